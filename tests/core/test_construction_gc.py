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
    _collect_all()                 # the garbage of earlier tests (some needs two passes)
    gc.disable()
    try:
        flat = flatten(model)
        found = gc.collect()
    finally:
        gc.enable()
    assert len(flat.equations) == 4000
    assert found < 500


def _collect_all() -> None:
    """Collect until a pass finds nothing (a finalizer may free more for the next pass)."""
    for _ in range(10):
        if not gc.collect():
            return


@pytest.mark.parametrize("sections", [1500, 3000])
def test_models_built_and_dropped_in_a_loop_are_collected(sections):
    """A model tree is cyclic (symbols and their owners): the collector must still see the
    objects of dropped models. Of fifteen ladders built and dropped, a few stay
    alive until the next full collection. A large model's objects go straight to the oldest
    generation (sparing the young collections a scan of them), which hides them from the
    count that triggers full collections: without the count kept by
    :mod:`bgmodelica.structure.collector`, all fifteen were still alive."""
    from library.electrical import Resistor

    _collect_all()
    for _ in range(15):
        model = RCLadder(sections)
        del model
    alive = sum(1 for o in gc.get_objects() if type(o) is Resistor)
    assert alive <= 8 * sections


def test_a_large_model_goes_straight_to_the_oldest_generation():
    """The objects of a large model are not left for a young collection to scan."""
    _collect_all()
    model = RCLadder(4000)                       # some 200,000 objects
    assert gc.get_count()[0] < 1000
    assert any(o is model for o in gc.get_objects(generation=2))
