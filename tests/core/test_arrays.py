"""Array variables, parameters, equations and arrays of components, against analytic
solutions and against the same models written one scalar at a time."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from scipy.linalg import expm

import bgmodelica as bg
from bgmodelica import Component, Parameter, Variable, array_of, der
from bgmodelica.core.arrays import compact_names, element_names
from bgmodelica.errors import ConnectError, DeclarationError, EquationError
from library.electrical import Capacitor, Ground, Resistor
from library.examples import RCLadder, RCLadderArrays, RCLadderVector

TIGHT = {"rtol": 1e-10, "atol": 1e-12}


class Decay(Component):
    """der(x[k]) = -a[k]*x[k], x[k](0) = x0[k]: x[k](t) = x0[k]*exp(-a[k]*t)."""

    x = Variable(shape=3, start=[1.0, 2.0, 3.0], fixed=True)
    a = Parameter(shape=3, value=[0.5, 1.0, 2.0], unit="1/s")

    def equations(self):
        yield der(self.x) == -self.a * self.x


class Linear2(Component):
    """der(x) = A x with a 2x2 parameter matrix: x(t) = expm(A t) x0."""

    x = Variable(shape=2, start=[1.0, 0.0], fixed=True)
    A = Parameter(shape=(2, 2), value=[[0.0, 1.0], [-4.0, -0.4]], unit="1/s")

    def equations(self):
        yield der(self.x) == self.A @ self.x


def test_vector_decay_matches_exponentials():
    res = bg.simulate(Decay(), stop_time=2.0, interval=0.1, **TIGHT)
    for k, (x0, a) in enumerate(zip([1.0, 2.0, 3.0], [0.5, 1.0, 2.0], strict=True)):
        assert np.max(np.abs(res[f"x[{k + 1}]"] - x0 * np.exp(-a * res.time))) < 1e-8


def test_parameter_array_override_by_element_name():
    res = bg.simulate(Decay(), stop_time=1.0, interval=0.5, params={"a[2]": 3.0}, **TIGHT)
    assert res["x[2]"][-1] == pytest.approx(2.0 * np.exp(-3.0), rel=1e-8)
    assert res["x[1]"][-1] == pytest.approx(np.exp(-0.5), rel=1e-8)


def test_array_modifier_at_construction():
    res = bg.simulate(Decay(x=[4.0, 5.0, 6.0], a=2.0), stop_time=1.0, interval=0.5, **TIGHT)
    assert res["x[3]"][-1] == pytest.approx(6.0 * np.exp(-2.0), rel=1e-8)


def test_matrix_parameter_and_matmul_match_expm():
    res = bg.simulate(Linear2(), stop_time=3.0, interval=0.5, **TIGHT)
    A = np.array([[0.0, 1.0], [-4.0, -0.4]])
    for t, x1, x2 in zip(res.time, res["x[1]"], res["x[2]"], strict=True):
        ref = expm(A * t) @ np.array([1.0, 0.0])
        assert abs(x1 - ref[0]) < 1e-8 and abs(x2 - ref[1]) < 1e-8
    assert "A[1,2]" in res.parameters


@pytest.mark.parametrize("n", [1, 2, 9])
def test_three_ladder_forms_agree_exactly(n):
    runs = [bg.simulate(M(n), stop_time=0.5, interval=0.05, **TIGHT)
            for M in (RCLadder, RCLadderArrays, RCLadderVector)]
    ref = runs[0][f"C{n}.v"]
    assert np.max(np.abs(runs[1][f"C[{n}].v"] - ref)) < 1e-12
    assert np.max(np.abs(runs[2][f"v[{n}]"] - ref)) < 1e-12
    assert np.max(np.abs(runs[2]["i[1]"] - runs[0]["R1.i"])) < 1e-9


def test_single_section_ladder_is_the_analytic_rc():
    """n = 1: C v' = (sin(20 pi t) - v)/R with R = C = 1, v(0) = 1."""
    res = bg.simulate(RCLadderVector(1), stop_time=1.0, interval=0.01, **TIGHT)
    w = 20 * np.pi
    t = res.time
    forced = (np.sin(w * t) - w * np.cos(w * t)) / (1 + w**2)
    exact = forced + (1.0 + w / (1 + w**2)) * np.exp(-t)
    assert np.max(np.abs(res["v[1]"] - exact)) < 1e-8


def test_element_names_and_compact_names():
    assert element_names("x", (3,)) == ["x[1]", "x[2]", "x[3]"]
    assert element_names("A", (2, 2)) == ["A[1,1]", "A[1,2]", "A[2,1]", "A[2,2]"]
    names = ["v[1]", "v[2]", "v[3]", "w", "C[1].v", "C[2].v", "C[4].v", "der(x[1])"]
    assert compact_names(names) == ["v[1:3]", "w", "C[1:2].v", "C[4].v", "der(x[1])"]
    # components numbered in a row (a ladder's sections): three or more collapse
    names = ["C1.v", "C2.v", "C3.v", "C5.v", "R7.i", "R8.i", "x1", "mass1.s", "mass2.s",
             "der(C1.v)"]
    assert compact_names(names) == ["C1.v .. C3.v", "C5.v", "R7.i", "R8.i", "x1",
                                    "mass1.s", "mass2.s", "der(C1.v)"]


def test_check_lists_long_name_lists_briefly():
    from bgmodelica.cli import _listed

    assert _listed([f"C{k}.v" for k in range(1, 10001)]) == "C1.v .. C10000.v"
    mixed = [f"m{k}.{x}" for k in range(1, 101) for x in ("s", "v")]    # no runs
    text = _listed(mixed)
    assert text.startswith("m1.s, m1.v, m2.s") and text.endswith("(160 more; --json lists all)")
    assert _listed([]) == "-"


def test_array_of_components_connect_broadcast_and_mismatch():
    class Chain(Component):
        def __init__(self):
            super().__init__()
            self.g = Ground()
            self.R = array_of(Resistor, 3, R=[1.0, 2.0, 3.0])
            self.C = array_of(Capacitor, 3, C=1.0, v=[1.0, 2.0, 3.0])
            self.connect(self.R.n, self.C.p)
            self.connect(self.C.n, self.g.p)
            self.connect(self.R.p, self.g.p)

    m = Chain()
    assert [c.name for c in m.R] == ["R[1]", "R[2]", "R[3]"]
    res = bg.simulate(m, stop_time=1.0, interval=0.5, **TIGHT)
    for k in (1, 2, 3):      # each C[k] discharges through R[k]: tau = R[k]*1 F
        assert res[f"C[{k}].v"][-1] == pytest.approx(k * np.exp(-1.0 / k), rel=1e-8)
    with pytest.raises(ConnectError, match="3 and 2 connectors"):
        m.connect(m.R.p, m.C.n[:2])


def test_shape_from_missing_attribute_is_named():
    class Bad(Component):
        x = Variable(shape="m")

    with pytest.raises(DeclarationError, match="Bad.x: shape 'm' names no integer"):
        Bad()
    with pytest.raises(DeclarationError, match="shape 0"):
        type("Zero", (Component,), {"x": Variable(shape=0)})()


def test_mismatched_array_equation_names_the_component():
    class Mismatch(Component):
        x = Variable(shape=3)

        def equations(self):
            yield der(self.x[:2]) == self.x

    with pytest.raises(EquationError, match=r"Mismatch.*\(2,\) and \(3,\)"):
        bg.compile(Mismatch())


def test_check_prints_arrays_compactly():
    out = subprocess.run([sys.executable, "-m", "bgmodelica.cli", "check",
                          "library.examples:RCLadderVector", "--arg", "n=40"],
                         capture_output=True, text=True, check=True).stdout
    assert "states (40): v[1:40]" in out
    assert "100 equations" not in out and "80 equations" in out


class Bus(bg.Connector):
    """Three wires: potentials and currents as arrays."""

    v = bg.Potential(shape=3, unit="V")
    i = bg.Flow(shape=3, unit="A")


class BusRC(Component):
    """Per wire: a capacitor C from the bus to ground (bus currents flow into it)."""

    p = Bus()
    C = Parameter(shape=3, value=[1.0, 2.0, 4.0], unit="F")

    def equations(self):
        yield self.C * der(self.p.v) == self.p.i


class BusLoad(Component):
    """Per wire: a resistor R from the bus to ground."""

    p = Bus()
    R = Parameter(1.0, unit="Ohm")

    def equations(self):
        yield self.p.v == self.R * self.p.i


class ThreePhaseDecay(Component):
    """Each capacitor discharges through its resistor: v[k](t) = v0[k] exp(-t/(R C[k]))."""

    caps = BusRC()
    load = BusLoad()

    def equations(self):
        yield bg.connect(self.caps.p, self.load.p)


def test_connector_with_array_variables_connects_elementwise():
    m = ThreePhaseDecay(**{"caps.p.v": [1.0, 2.0, 3.0]})       # array start values
    res = bg.simulate(m, stop_time=2.0, interval=0.5, **TIGHT)
    for k, (v0, c) in enumerate(zip([1.0, 2.0, 3.0], [1.0, 2.0, 4.0], strict=True)):
        exact = v0 * np.exp(-res.time / c)
        assert np.max(np.abs(res[f"caps.p.v[{k + 1}]"] - exact)) < 1e-8


def test_declare_adds_an_instance_array_and_refuses_a_second_one():
    class Chain(Component):
        def __init__(self, n):
            super().__init__()
            self.declare("x", Variable(shape=n, start=[float(k + 1) for k in range(n)],
                                       fixed=True))
            self.declare("a", Parameter(2.0, unit="1/s"))

        def equations(self):
            yield der(self.x) == -self.a * self.x

    m = Chain(4)
    with pytest.raises(bg.errors.DuplicateNameError, match="'x' is already declared"):
        m.declare("x", Variable())
    res = bg.simulate(m, stop_time=1.0, interval=0.5, **TIGHT)
    assert res["x[4]"][-1] == pytest.approx(4.0 * np.exp(-2.0), rel=1e-8)


@pytest.mark.parametrize("n", [2, 9])
def test_ladder_forms_agree_with_the_compiled_graph_searches(n, monkeypatch):
    """Large systems are matched and BLT-ordered by scipy's compiled searches; forcing them
    on small ladders gives the same solutions as the Python algorithms."""
    from bgmodelica.structure import compiled

    ref = bg.simulate(RCLadder(n), stop_time=0.5, interval=0.05, **TIGHT)
    monkeypatch.setattr(compiled, "LARGE", 1)
    for M, name in ((RCLadder, f"C{n}.v"), (RCLadderArrays, f"C[{n}].v"),
                    (RCLadderVector, f"v[{n}]")):
        res = bg.simulate(M(n), stop_time=0.5, interval=0.05, **TIGHT)
        assert np.max(np.abs(res[name] - ref[f"C{n}.v"])) < 1e-10


def test_per_element_declarations_equal_dataclass_replace():
    """Array elements get their declarations through ``Declaration.evolve`` (no __init__
    per element): the same objects ``dataclasses.replace`` would build."""
    from dataclasses import replace

    base = Variable(unit="V", start=0.0, nominal=2.0)
    copy = base.evolve(start=3.0, fixed=True)
    assert copy == replace(base, start=3.0, fixed=True) and hash(copy) == hash(
        replace(base, start=3.0, fixed=True))
    assert base.start == 0.0 and not base.fixed and type(copy) is Variable
    p = Parameter(1.0, unit="Ohm")
    assert p.with_start(2.5) == replace(p, value=2.5)
    m = RCLadderVector(3)
    assert [m._symbols[f"R[{k}]"].decl.value for k in (1, 2, 3)] == [1.0, 0.5, 1.0 / 3]
    assert [m._symbols[f"v[{k}]"].decl.start for k in (1, 2, 3)] == [1.0, 2.0, 3.0]


def test_element_declarations_follow_with_start():
    """Array elements get what ``with_start`` gives each scalar: start and fixed for a
    variable, value for a parameter, the named fields for a dict; other fields unchanged."""
    from dataclasses import replace

    from bgmodelica import Component, Parameter, Variable

    class Holder(Component):
        x = Variable(shape=3, unit="m", nominal=[1.0, 2.0, 3.0])
        p = Parameter(shape=3, value=0.5, min=0.0)

    plain = Holder()
    assert all(plain._symbols[f"x[{k}]"].decl == replace(
        Holder.x, shape=(), nominal=float(k)) for k in (1, 2, 3))
    assert plain._symbols["p[1]"].decl is plain._symbols["p[3]"].decl   # one shared copy
    given = Holder(x=np.array([4.0, 5.0, 6.0]), p=[1.0, 2.0, 3.0])
    for k in (1, 2, 3):
        assert given._symbols[f"x[{k}]"].decl == replace(
            Holder.x, shape=(), nominal=float(k), start=3.0 + k, fixed=True)
        assert given._symbols[f"p[{k}]"].decl == replace(Holder.p, shape=(), value=float(k))
    as_dict = Holder(x={"start": 7.0, "fixed": False})
    assert as_dict._symbols["x[2]"].decl == replace(Holder.x, shape=(), nominal=2.0, start=7.0)
