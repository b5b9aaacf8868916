"""Model construction runs with the cyclic garbage collector paused, and restores it."""

from __future__ import annotations

import gc

import pytest

from bgmodelica import Component, Parameter
from library.examples.circuits import RCLadder


class Probe(Component):
    """Records whether the collector ran during its constructor; fails on request."""

    k = Parameter(1.0)

    def __init__(self, fail: bool = False, **modifiers):
        super().__init__(**modifiers)
        self.collector_was_enabled = gc.isenabled()
        if fail:
            raise ValueError("bad section")


def test_collector_paused_while_building_and_restored():
    assert gc.isenabled()
    probe = Probe()
    assert probe.collector_was_enabled is False
    assert gc.isenabled()
    assert len(RCLadder(50)._children) == 2 + 2 * 50
    assert gc.isenabled()


def test_collector_restored_after_a_failing_constructor():
    with pytest.raises(ValueError, match="bad section"):
        Probe(fail=True)
    assert gc.isenabled()


def test_a_paused_collector_stays_paused():
    gc.disable()
    try:
        Probe()
        assert not gc.isenabled()
    finally:
        gc.enable()


def test_flattening_an_array_model_leaves_no_cycles_behind():
    """The flattener and its per-symbol entries are freed by reference counting: before, a
    recursive closure of the array lowering kept them in a cycle (about 5 objects per array
    element for the cyclic collector to find)."""
    from bgmodelica.core.flatten import flatten
    from library.examples.circuits import RCLadderVector

    model = RCLadderVector(2000)
    gc.collect()
    gc.disable()
    try:
        flat = flatten(model)
        found = gc.collect()
    finally:
        gc.enable()
    assert len(flat.equations) == 4000
    assert found < 500


def _young() -> int:
    return len(gc.get_objects(generation=0)) + len(gc.get_objects(generation=1))


def test_a_large_model_skips_the_young_generations():
    """After building and after compiling a large model the young generations hold nothing
    of it: the first collections afterwards do not scan its objects. A small model is left
    to the collector as usual (see graph.PROMOTE_FROM)."""
    import bgmodelica as bg

    gc.collect()
    model = RCLadder(1500)
    assert _young() < 1000
    compiled = bg.compile(model)
    assert gc.isenabled()
    assert _young() < 1000 < len(compiled.flat.variables)
    gc.collect()
    small = bg.compile(RCLadder(20))
    assert _young() > len(small.flat.variables)
