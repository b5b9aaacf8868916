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
