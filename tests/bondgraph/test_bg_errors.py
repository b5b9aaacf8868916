"""Bad input gives typed errors (subclasses of ModelError) that name the element."""

from __future__ import annotations

import pytest

import bgmodelica as bm
from bgmodelica.bondgraph import (
    J0,
    J1,
    MTF,
    TF,
    BondError,
    BondGraph,
    C,
    CausalConflictError,
    Graph,
    I,
    JunctionError,
    ModulusError,
    R,
    Se,
    analyze,
)
from bgmodelica.errors import InitializationError, ModelError


def test_errors_are_model_errors():
    for cls in (BondError, JunctionError, ModulusError, CausalConflictError):
        assert issubclass(cls, ModelError)


def test_bond_to_a_missing_port():
    bg = BondGraph(name="bg")
    bg.add("tf", TF(m=2.0))
    bg.add("j", J1())
    with pytest.raises(BondError, match="tf has no port or element 'p3'") as err:
        bg.bond("tf.p3", bg.j)
    assert err.value.element == "tf.p3"
    with pytest.raises(BondError, match="no element 'nothere'"):
        bg.bond("nothere", bg.j)


def test_bond_to_an_element_outside_the_graph_or_twice():
    bg = BondGraph(name="bg")
    bg.add("j", J0())
    with pytest.raises(BondError, match="not part of bond graph bg"):
        bg.bond(R(name="stray"), bg.j)
    bg.add("r", R())
    bg.bond(bg.j, bg.r)
    with pytest.raises(BondError, match="every port .* already bonded") as err:
        bg.bond(bg.j, bg.r)
    assert err.value.element == "r"


def test_junction_with_one_bond():
    bg = BondGraph(name="bg")
    bg.add("U", Se(E=1.0))
    bg.add("j", J1())
    bg.bond(bg.U, bg.j)
    with pytest.raises(JunctionError, match="1-junction j has 1 bond") as err:
        bm.compile(bg)
    assert err.value.element == "j"
    with pytest.raises(JunctionError):
        analyze(bg)


def test_modulus_with_an_unknown_variable():
    class Arm(BondGraph):
        l1 = bm.Parameter(1.0)
        q1 = bm.Variable()

        def __init__(self, modulus, **kw):
            super().__init__(**kw)
            self.add("T", Se(E=1.0))
            self.add("w", J1())
            self.add("r", MTF(m=modulus))
            self.add("v", J1())
            self.add("m", I(I=1.0))
            self.bond(self.T, self.w)
            self.bond(self.w, self.r)
            self.bond(self.r, self.v)
            self.bond(self.v, self.m)

        def equations(self):
            yield bm.der(self.q1) == self.w.f

    with pytest.raises(ModulusError, match=r"MTF r: the modulus 'l1\*cos\(q3\)' uses an "
                                           r"unknown name") as err:
        bm.compile(Arm("l1*cos(q3)"))
    assert err.value.element == "r"
    with pytest.raises(ModulusError, match="MTF r: the modulus function refers to an unknown"):
        analyze(Arm(lambda m: m.l1 * bm.cos(m.q3)))
    bm.compile(Arm("l1*cos(q1)"))             # the good one compiles
    bm.compile(Arm(lambda m: m.l1 * bm.cos(m.q1)))


def test_unresolvable_causal_conflict():
    bg = BondGraph(name="bg")
    bg.add("E1", Se(E=1.0))
    bg.add("E2", Se(E=2.0))
    bg.add("j", J0())
    bg.add("c", C(C=1.0))
    bg.bond(bg.E1, bg.j)
    bg.bond(bg.E2, bg.j)
    bg.bond(bg.j, bg.c)
    with pytest.raises(CausalConflictError, match="E2 cannot impose its effort: 0:j j") as err:
        bm.compile(bg)
    assert err.value.element == "E2"
    report = analyze(bg)                      # reported, not raised
    assert [c.element for c in report.conflicts] == ["E2"]
    assert "causal conflicts: E2" in report.to_text()


def test_transformer_with_both_bonds_in():
    bg = BondGraph(name="bg")
    bg.add("a", J1())
    bg.add("b", J1())
    bg.add("tf", TF(m=2.0))
    bg.add("U", Se(E=1.0))
    bg.add("r", R())
    bg.bond(bg.U, bg.a)
    bg.bond(bg.b, bg.r)
    bg.bond(bg.a, "tf.p1")
    bg.bond(bg.b, "tf.p2")
    with pytest.raises(BondError, match="TF:tf element tf: both bonds point into it"):
        analyze(bg)


def test_bad_law_and_graph_kind():
    bg = BondGraph(name="bg")
    bg.add("U", Se(E=1.0))
    bg.add("r", R(law=lambda e, f: e + f))
    bg.bond(bg.U, bg.r)
    with pytest.raises(ModulusError, match="R r: the constitutive law must return an equation"):
        bm.compile(bg)
    with pytest.raises(BondError, match="unknown bond-graph element kind"):
        Graph().add("x", "Q")


def test_modulus_that_is_not_finite_is_refused():
    # e1 = m e2 with m = l1/0 = inf: the solved form e2 = e1/m gave all-zero flows, silently
    class Arm(BondGraph):
        l1 = bm.Parameter(0.5)

        def __init__(self, modulus, **kw):
            super().__init__(**kw)
            self.add("T", Se(E=1.0))
            self.add("w", J1())
            self.add("r", MTF(m=modulus))
            self.add("v", J1())
            self.add("m", I(I=1.0))
            self.bond(self.T, self.w)
            self.bond(self.w, self.r)
            self.bond(self.r, self.v)
            self.bond(self.v, self.m)

    with pytest.raises(InitializationError, match=r"\[r \(MTF\)\] is NaN .*constant inf"):
        bm.simulate(Arm("l1/0"), stop_time=1.0)
    res = bm.simulate(Arm("l1"), stop_time=1.0)      # e2 = E/l1 = 2: p of the mass = 2 t
    assert abs(res["m.p"][-1] - 2.0) < 1e-6
