"""Element laws, bond directions, nonlinear laws, sources, detectors, nesting (word bond
graphs) and adapters to rotational flanges and electrical pins."""

from __future__ import annotations

import numpy as np
import pytest

import bgmodelica as bm
from bgmodelica.bondgraph import (
    GY,
    J0,
    J1,
    TF,
    BondGraph,
    C,
    De,
    Df,
    I,
    R,
    Se,
    Sf,
    analyze,
    graph_of,
    orientation,
)
from library.bondgraph import FlangeAdapter, PinAdapter
from library.electrical import Ground, Resistor
from library.rotational import Inertia


class RC(BondGraph):
    """Se -> 1 {R} -> 0 {C, De}: the capacitor charges to E with time constant R*C."""

    def __init__(self, **kw):
        super().__init__(**kw)
        self.add("U", Se(E=2.0))
        self.add("a", J1())
        self.add("res", R(R=10.0))
        self.add("b", J0())
        self.add("cap", C(C=0.01))
        self.add("V", De())
        self.bond(self.U, self.a)
        self.bond(self.a, self.res)
        self.bond(self.a, self.b)
        self.bond(self.b, self.cap)
        self.bond(self.b, self.V)


def test_bond_direction_maps_onto_connector_flows():
    m = RC()
    assert orientation(m.U.port) == -1 and orientation(m.res.port) == 1
    res = bm.simulate(m, stop_time=0.1, rtol=1e-9, atol=1e-12)
    assert res["cap.q"][-1] == pytest.approx(0.02 * (1 - np.exp(-1.0)), rel=1e-6)
    # port flow is positive into the element: the source sees -f, the capacitor +f
    assert np.allclose(res["U.port.f"], -res["res.port.f"], atol=1e-12)
    assert np.allclose(res["res.port.f"], res["cap.port.f"], atol=1e-12)
    assert np.allclose(res["V.y"], res["cap.q"] / 0.01, atol=1e-9)


def test_reversed_half_arrow_on_a_one_junction_flips_the_effort_sign():
    # Sf -> 1 <- R : both half-arrows point into the junction, so the common flow runs along
    # both bonds and the efforts sum to zero: e_Sf + e_R = 0 with e_R = R*f (the R, drawn
    # with its half-arrow outwards, delivers power, as the drawing says)
    bg = BondGraph(name="flip")
    bg.add("F", Sf(F=3.0))
    bg.add("j", J1())
    bg.add("res", R(R=2.0))
    bg.bond(bg.F, bg.j)
    bg.bond(bg.res, bg.j)
    res = bm.simulate(bg, stop_time=0.1)
    assert res["j.f"][-1] == pytest.approx(3.0)
    assert res["res.port.e"][-1] == pytest.approx(6.0)
    assert res["F.port.e"][-1] == pytest.approx(-6.0)
    assert res["res.port.f"][-1] == pytest.approx(-3.0)      # port flow: into the element


def test_nonlinear_laws_signal_source_and_gyrator():
    class Plant(BondGraph):
        u = bm.Input()

        def __init__(self, **kw):
            super().__init__(**kw)
            self.add("S", Se(signal=True))
            self.add("a", J1())
            self.add("res", R(law=lambda e, f: e == f + 0.5 * f**3))
            self.add("gy", GY(r=2.0))
            self.add("b", J1())
            self.add("mass", I(law=lambda f, p: p == 4.0 * f))
            self.add("spring", C(law=lambda e, q, m: e == q / 0.5, q=0.1))
            self.add("w", Df())
            self.connect(self.u, self.S.u)
            self.bond(self.S, self.a)
            self.bond(self.a, self.res)
            self.bond(self.a, self.gy)
            self.bond(self.gy, self.b)
            self.bond(self.b, self.mass)
            self.bond(self.b, self.spring)
            self.bond(self.b, self.w)

    cm = bm.compile(Plant())
    assert [u.name for u in cm.dae.inputs] == ["u"]
    res = bm.simulate(cm, stop_time=1.0, params={"u": 1.0}, rtol=1e-9)
    assert np.allclose(res["gy.p1.e"], 2.0 * res["b.f"], atol=1e-9)     # e1 = r f2
    assert np.allclose(res["res.port.e"], res["a.f"] + 0.5 * res["a.f"] ** 3, atol=1e-9)
    assert res["spring.q"][0] == pytest.approx(0.1)
    rep = analyze(Plant())
    assert sorted(rep.integral) == ["mass", "spring"]


class Shaft(BondGraph):
    """A word-bond-graph subsystem: 1-junction with an inertia, port ``end`` exposed."""

    def __init__(self, **kw):
        super().__init__(**kw)
        self.add("w", J1())
        self.add("J", I(I=2.0))
        self.bond(self.w, self.J)
        self.expose("end", self.w)


def test_nested_subsystem_and_transformer():
    top = BondGraph(name="top")
    top.add("T", Se(E=1.0))
    top.add("a", J1())
    top.add("tf", TF(m=0.5))
    top.add("load", Shaft())
    top.bond(top.T, top.a)
    top.bond(top.a, top.tf)
    top.bond(top.tf, "load.end")
    g = graph_of(top)
    assert {(b.tail, b.head) for b in g.bonds} >= {("tf", "load.w"), ("load.w", "load.J")}
    res = bm.simulate(top, stop_time=1.0, rtol=1e-9, atol=1e-12)
    # f2 = m f1, e1 = m e2: torque 1 at the input gives 2 at the load, inertia 2 -> accel 1,
    # load speed 1*t; input speed 2*t
    assert res["load.w.f"][-1] == pytest.approx(1.0, rel=1e-6)
    assert res["a.f"][-1] == pytest.approx(2.0, rel=1e-6)
    rep = analyze(top)
    assert rep.integral == ["load.J"]


def test_open_port_is_zero_flow():
    g = graph_of(Shaft(name="s"))
    virtual = [n for n in g.nodes.values() if n.zero]
    assert [n.name for n in virtual] == ["end"] and virtual[0].kind == "Sf"


def test_flange_adapter_drives_a_rotational_inertia():
    class Mixed(bm.Component):
        def __init__(self, **kw):
            super().__init__(**kw)
            self.bg = BondGraph()
            self.bg.add("T", Se(E=3.0))
            self.bg.add("j", J1())
            self.bg.add("fl", FlangeAdapter())
            self.bg.bond(self.bg.T, self.bg.j)
            self.bg.bond(self.bg.j, self.bg.fl)
            self.load = Inertia(J=1.5)
            self.connect(self.bg.fl.flange, self.load.flange_a)

    res = bm.simulate(Mixed(), stop_time=1.0, rtol=1e-9, atol=1e-12)
    assert res["load.w"][-1] == pytest.approx(3.0 / 1.5, rel=1e-6)
    assert np.allclose(res["bg.j.f"], res["load.w"], atol=1e-9)
    assert analyze(Mixed().bg).graph.nodes["fl"].kind == "X"


def test_pin_adapter_feeds_a_resistor():
    class Mixed(bm.Component):
        def __init__(self, **kw):
            super().__init__(**kw)
            self.bg = BondGraph()
            self.bg.add("U", Se(E=5.0))
            self.bg.add("pins", PinAdapter())
            self.bg.bond(self.bg.U, self.bg.pins)
            self.r = Resistor(R=2.0)
            self.gnd = Ground()
            self.connect(self.bg.pins.p, self.r.p)
            self.connect(self.r.n, self.bg.pins.n)
            self.connect(self.r.n, self.gnd.p)

    res = bm.simulate(Mixed(), stop_time=0.1)
    assert res["r.i"][-1] == pytest.approx(2.5)
    assert res["bg.U.port.f"][-1] == pytest.approx(-2.5)    # 2.5 A out of the source's bond


@pytest.mark.parametrize("value", ["2*sin(time)", lambda m: 2 * bm.sin(bm.time)])
def test_time_expression_source(value):
    bg = BondGraph(name="t")
    bg.add("F", Sf(value=value))
    bg.add("j", J1())
    bg.add("res", R(R=3.0))
    bg.bond(bg.F, bg.j)
    bg.bond(bg.j, bg.res)
    # sin(time) takes the sine of seconds: the unit check rejects it unless switched off
    with pytest.raises(bm.errors.UnitError, match=r"sin\(\) needs a dimensionless argument"):
        bm.compile(bg)
    res = bm.simulate(bg, stop_time=1.0, interval=0.1, units="off")
    assert np.allclose(res["res.port.e"], 6.0 * np.sin(res.time), atol=1e-9)
