"""The array path for hierarchical models (components holding components): the scalar
pipeline's DAE, groups of identical leaves written once across their parents, and the RC
ladder built from sections giving the flat ladder's results."""

from __future__ import annotations

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica import Component, Variable, array_of, connect
from bgmodelica.array_path import ArrayCompiledModel, compile_arrays, why_not
from bgmodelica.compiler import _compile
from library.electrical import Capacitor, Ground, Pin, Resistor, SineVoltage
from library.examples.circuits import RC, RCLadder, RCLadderSections, Section

from .test_array_path_components import _same_dae


def _fast_and_slow(make):
    fast = compile_arrays(make(), minimum=0)
    assert isinstance(fast, ArrayCompiledModel), why_not(make(), minimum=0)
    return fast, _compile(make(), None)


class Nested(Component):
    """An :class:`RC` circuit (which has subcomponents) beside a resistor across a
    ground."""

    def __init__(self, **modifiers):
        super().__init__(**modifiers)
        self.rc = RC()
        self.extra = Resistor()
        self.ground = Ground()
        self.connect(self.extra.p, self.ground.p)
        self.connect(self.extra.n, self.ground.p)


class Probed(Section):
    """A :class:`Section` with a variable and an equation of its own (its capacitor's
    voltage doubled)."""

    twice = Variable(unit="V")

    def equations(self):
        yield from super().equations()
        yield self.twice == 2 * self.C.v


class Rung(Component):
    """Two levels down: a :class:`Probed` section and an array of two resistors in
    parallel with its resistor."""

    p = Pin()
    n = Pin()
    ground = Pin()

    def __init__(self, k: int = 1, **modifiers):
        super().__init__(**modifiers)
        self.inner = Probed(**{"R.R": 1.0 + k, "C.C": 0.5 / k, "C.v": 0.1 * k})
        self.shunt = array_of(Resistor, 2, R=[2.0 + k, 3.0])

    def equations(self):
        yield connect(self.p, self.inner.p)
        yield connect(self.inner.n, self.n)
        yield connect(self.inner.ground, self.ground)
        for r in (self.shunt[0], self.shunt[1]):
            yield connect(self.p, r.p)
            yield connect(r.n, self.n)


class Ladder(Component):
    """A sine source and ground feeding ``n`` rungs of class ``rung``."""

    def __init__(self, n: int = 3, rung: type = Rung, **modifiers):
        super().__init__(**modifiers)
        self.source = SineVoltage(V=1.0, f=2.0)
        self.ground = Ground()
        self.connect(self.source.n, self.ground.p)
        node = self.source.p
        for k in range(1, n + 1):
            part = self.add(f"rung{k}", rung(k))
            self.connect(node, part.p)
            self.connect(part.ground, self.ground.p)
            node = part.n


@pytest.mark.parametrize("make", [
    Nested, lambda: RCLadderSections(3), lambda: RCLadderSections(70),
    lambda: Ladder(2), lambda: Ladder(70)],
    ids=["rc-beside-resistor", "sections-3", "sections-70", "rungs-2", "rungs-70"])
def test_hierarchies_give_the_scalar_pipelines_dae(make):
    fast, slow = _fast_and_slow(make)
    _same_dae(fast.dae, slow.dae)


def test_identical_leaves_are_written_once_across_their_parents():
    from bgmodelica.array_path.components import _tree
    from bgmodelica.core.flatten_vectorized import group_connections, tree_groups

    tree = _tree(RCLadderSections(70), 0)
    groups = tree_groups(tree.components, tree.parents)
    sizes = {type(items[0]).__name__: len(items) for _, items in groups}
    assert sizes == {"Resistor": 70, "Capacitor": 70}
    assert groups[0][0][:2] == ["section1.R", "section2.R"]
    sections = [c for _, c in tree.parents[1:]]
    pairs = group_connections(sections)          # the sections' connects, written once
    assert [(a._items[3]._name, b._items[3]._name) for a, b in pairs] \
        == [("p", "p"), ("n", "p"), ("n", "n"), ("n", "ground")]


def test_sections_ladder_takes_the_array_path_and_matches_the_flat_ladder():
    assert why_not(RCLadderSections(100)) is None         # from 1000 scalar equations on
    n = 50
    opts = {"stop_time": 0.3, "interval": 0.01, "rtol": 1e-10, "atol": 1e-10}
    flat = bg.simulate(_compile(RCLadder(n), None), **opts)           # the scalar pipeline
    sections = bg.simulate(compile_arrays(RCLadderSections(n), minimum=0), **opts)
    for k in range(1, n + 1):
        np.testing.assert_allclose(sections[f"section{k}.C.v"], flat[f"C{k}.v"],
                                   rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(sections[f"section{k}.R.i"], flat[f"R{k}.i"],
                                   rtol=1e-12, atol=1e-12)


class LateConnector(Component):
    """A component declaring a connector after its subcomponent (goes the scalar way)."""

    R = Resistor()
    p = Pin()
    n = Pin()

    def equations(self):
        yield connect(self.p, self.R.p)
        yield connect(self.R.n, self.n)


class WithLate(Component):
    def __init__(self, **modifiers):
        super().__init__(**modifiers)
        self.source = SineVoltage(V=1.0, f=2.0)
        self.part = LateConnector()
        self.c = Capacitor(C=1.0, v=0.0)
        self.ground = Ground()
        self.connect(self.source.p, self.part.p)
        self.connect(self.part.n, self.c.p)
        self.connect(self.c.n, self.ground.p)
        self.connect(self.source.n, self.ground.p)


def test_a_connector_after_a_subcomponent_goes_the_scalar_way():
    assert "after a subcomponent" in why_not(WithLate(), minimum=0)
    compiled = bg.compile(WithLate())
    assert not isinstance(compiled, ArrayCompiledModel)
    assert "c.v" in compiled.dae.state_names
