"""The array path: large leaf models of array equations compiled without a Python object per
scalar give the DAE of the scalar pipeline, or go the scalar way."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica import Component, Parameter, StateSelect, Variable, der, exp, time
from bgmodelica.array_path import ArrayCompiledModel, compile_arrays, why_not
from bgmodelica.compiler import _compile
from bgmodelica.errors import UnbalancedModelError, UnitError
from library.examples import RCLadder, RCLadderVector

TIGHT = {"rtol": 1e-10, "atol": 1e-12}


# -- the same DAE as the scalar pipeline -------------------------------------------------------

def _same_dae(a, b) -> None:
    assert a.names == b.names and a.state_names == b.state_names
    assert a.algebraic_names == b.algebraic_names == []
    assert [q.name for q in a.parameters] == [q.name for q in b.parameters]
    assert np.array_equal(a.x_start, b.x_start) and a.fixed == b.fixed
    assert np.array_equal(a.p_default, b.p_default)
    assert a.differentiated == b.differentiated
    rng = np.random.default_rng(3)
    x, p = rng.random(a.x.numel()) + 0.5, rng.random(a.p.numel()) + 0.5
    fa = ca.Function("a", [a.x, a.p, a.t], [a.ode, a.observed])
    fb = ca.Function("b", [b.x, b.p, b.t], [b.ode, b.observed])
    for u, v in zip(fa(x, p, 0.37), fb(x, p, 0.37), strict=True):
        assert np.allclose(np.asarray(u), np.asarray(v), rtol=1e-14, atol=0.0)


@pytest.mark.parametrize("n", [1, 2, 5, 64])
def test_the_ladder_gives_the_scalar_pipelines_dae(n):
    fast = compile_arrays(RCLadderVector(n), minimum=0)
    assert isinstance(fast, ArrayCompiledModel)
    _same_dae(fast.dae, _compile(RCLadderVector(n), None).dae)


class DecayDeclarations(Component):
    """The declarations of :class:`Decays` (equations are inherited: the variants below
    start from here)."""

    x = Variable(shape="n", unit="m", description="state")
    y = Variable(shape="n", unit="m", description="twice the state")
    s = Variable(unit="m", description="first plus last")
    rate = Parameter(shape="n", value=1.0, unit="1/s")
    u = Parameter(1.0, unit="m/s")

    def __init__(self, n: int = 4, **modifiers):
        self.n = n
        k = np.linspace(0.5, 3.0, n)
        super().__init__(**{"rate": k, "x": np.linspace(1.0, 2.0, n), **modifiers})


class Decays(DecayDeclarations):
    """``der(x[k]) = -k_k*x[k] + u(t)``, ``y = 2*x`` observed, ``s = x[1] + x[n]``: each
    ``x[k](t) = x0_k e^{-k_k t} + (1 - e^{-k_k t})/k_k`` for ``u = 1``."""

    def equations(self):
        yield der(self.x) == -self.rate * self.x + self.u
        yield self.y == 2.0 * self.x
        yield self.s == self.x[0] + self.x[-1]


def test_a_model_taken_by_compile_matches_the_analytic_solution():
    n = 1000
    model = Decays(n)
    assert why_not(model) is None
    compiled = bg.compile(model)
    assert isinstance(compiled, ArrayCompiledModel)
    res = bg.simulate(compiled, stop_time=2.0, interval=0.1, **TIGHT,
                      outputs=["x[1]", f"x[{n}]", "y[500]", "s"])
    k, x0 = np.linspace(0.5, 3.0, n), np.linspace(1.0, 2.0, n)

    def exact(j):
        return x0[j] * np.exp(-k[j] * res.time) + (1 - np.exp(-k[j] * res.time)) / k[j]

    assert np.max(np.abs(res["x[1]"] - exact(0))) < 1e-8
    assert np.max(np.abs(res[f"x[{n}]"] - exact(n - 1))) < 1e-8
    assert np.max(np.abs(res["y[500]"] - 2 * exact(499))) < 1e-8
    assert np.max(np.abs(res["s"] - exact(0) - exact(n - 1))) < 1e-8
    assert res.units["x[1]"] == "m" and res.meta["solver"] == "cvodes"
    _same_dae(compiled.dae, _compile(Decays(n), None).dae)


def test_the_scalar_structures_are_made_on_first_use():
    compiled = bg.compile(RCLadderVector(1200))
    assert isinstance(compiled, ArrayCompiledModel)
    assert "flat" not in compiled.__dict__ and "scalar_structures" not in compiled.timings
    bg.simulate(compiled, stop_time=0.01)                # simulation does not need them
    assert "flat" not in compiled.__dict__
    before = compiled.dae
    summary = compiled.summary()                          # read off the array path
    assert summary["equations"] == 2400 and len(summary["states"]) == 1200
    assert "flat" not in compiled.__dict__
    assert len(compiled.flat.variables) == 3600           # made when read
    assert compiled.timings["scalar_structures"] > 0
    assert compiled.dae is not before and compiled.dae.names == before.names
    assert len(compiled.flat.variables) == 3600


def test_parameters_and_results_work_as_for_any_model():
    compiled = bg.compile(RCLadderVector(1100))
    res = bg.simulate(compiled, stop_time=0.05, interval=0.01, params={"V": 2.0, "R[1]": 0.5},
                      outputs=["v[1]", "i[1]"], **TIGHT)
    ref = bg.simulate(_compile(RCLadderVector(1100), None), stop_time=0.05, interval=0.01,
                      params={"V": 2.0, "R[1]": 0.5}, outputs=["v[1]", "i[1]"], **TIGHT)
    for name in ("v[1]", "i[1]"):
        assert np.max(np.abs(res[name] - ref[name])) < 1e-12
    assert res.parameters["R[1]"] == 0.5 and res.units["i[1]"] == "A"


def test_a_compiled_model_pickles_with_its_scalar_structures():
    from bgmodelica.studies.payload import pickle_compiled, unpickle_compiled

    back = unpickle_compiled(pickle_compiled(bg.compile(RCLadderVector(1000))))
    assert back.source is None and len(back.flat.variables) == 3000
    res = bg.simulate(back, stop_time=0.01, outputs=["v[1]"])
    assert np.isfinite(res["v[1]"]).all()


# -- what goes the scalar way ------------------------------------------------------------------

class Recurrence(Component):
    """``y[1] = u``, ``y[k+1] = y[k] + x[k+1]``, ``der(x) = -x``: a running sum (each
    ``y[k]`` depends on the one before in the same block)."""

    x = Variable(shape="n", start=1.0, fixed=True)
    y = Variable(shape="n")
    u = Parameter(1.0)

    def __init__(self, n: int = 4, **modifiers):
        self.n = n
        super().__init__(**modifiers)

    def equations(self):
        yield der(self.x) == -self.x
        yield self.y[0] == self.u
        yield self.y[1:] == self.y[:-1] + self.x[1:]


class Loop(Component):
    """``a + b = 2 x``, ``a - b = 0`` element by element (a 2x2 algebraic loop per element),
    ``der(x) = -a``: ``a = b = x``."""

    x = Variable(shape="n", start=1.0, fixed=True)
    a = Variable(shape="n")
    b = Variable(shape="n")

    def __init__(self, n: int = 4, **modifiers):
        self.n = n
        super().__init__(**modifiers)

    def equations(self):
        yield self.a + self.b == 2.0 * self.x
        yield self.a - self.b == 0.0 * self.x
        yield der(self.x) == -self.a


def test_a_recurrence_goes_the_scalar_way_and_is_right():
    model = Recurrence(1000)
    assert "own block" in why_not(model)
    res = bg.simulate(model, stop_time=1.0, interval=0.5, **TIGHT, outputs=["y[1000]"])
    assert res["y[1000]"][-1] == pytest.approx(1.0 + 999 * np.exp(-1.0), rel=1e-8)


def test_an_algebraic_loop_goes_the_scalar_way_and_is_right():
    model = Loop(1000)
    assert "loop" in why_not(model)
    res = bg.simulate(model, stop_time=1.0, interval=0.5, **TIGHT, outputs=["x[7]"])
    assert abs(res["x[7]"][-1] - np.exp(-1.0)) < 1e-8


class Unbalanced(DecayDeclarations):
    """:class:`Decays` without the equation of ``s``."""

    def equations(self):
        yield der(self.x) == -self.rate * self.x + self.u
        yield self.y == 2.0 * self.x


def test_an_unbalanced_model_gets_the_scalar_pipelines_error():
    assert "equations for" in why_not(Unbalanced(1000))
    with pytest.raises(UnbalancedModelError, match="2000 equations for 2001 unknowns"):
        bg.compile(Unbalanced(1000))


class WrongUnits(DecayDeclarations):
    def equations(self):
        yield der(self.x) == -self.rate * self.x + self.u
        yield self.y == self.rate                             # 1/s where m is declared
        yield self.s == self.x[0] + self.x[-1]


def test_units_are_checked_on_the_array_path():
    with pytest.raises(UnitError, match="top level"):
        bg.compile(WrongUnits(1000))
    assert isinstance(bg.compile(WrongUnits(1000), units="off"), ArrayCompiledModel)


def test_other_models_say_why_they_go_the_scalar_way():
    assert why_not(RCLadder(3)) == "small"
    assert why_not(Decays(10)) == "small"
    assert why_not(Decays(10), minimum=0) is None
    assert "state selection" in why_not(
        Decays(10, x={"state_select": StateSelect.ALWAYS, "start": 1.0}), minimum=0)


class Mixed(Component):
    """Scalar equations of array elements beside array equations:
    ``der(x) = -x/tau``, ``z = x[1] * exp(-time/tau)``."""

    x = Variable(shape=3, start=[1.0, 2.0, 3.0], fixed=True)
    z = Variable()
    tau = Parameter(1.0, unit="s")

    def equations(self):
        yield der(self.x) == -self.x / self.tau
        yield self.z == self.x[0] * exp(-time / self.tau)


def test_scalar_equations_of_elements_and_time():
    compiled = compile_arrays(Mixed(), minimum=0)
    _same_dae(compiled.dae, _compile(Mixed(), None).dae)
    res = bg.simulate(compiled, stop_time=1.0, interval=0.5, **TIGHT)
    assert abs(res["z"][-1] - np.exp(-2.0)) < 1e-8


class TwoUnits(Component):
    """``x[1]`` in m, ``x[2]`` in s (per-element modifiers), ``y`` all in m: ``y == x`` holds
    for the first element only."""

    x = Variable(shape=2, unit="m")
    y = Variable(shape=2, unit="m")
    tau = Parameter(1.0, unit="s")
    gain = Parameter(3.0, unit="1")

    def equations(self):
        yield der(self.x) == -self.x / self.tau
        yield self.y == self.gain * self.x


def test_an_array_of_several_units_is_checked_element_by_element():
    model = TwoUnits(x=[{"unit": "m", "start": 1.0}, {"unit": "s", "start": 2.0}])
    with pytest.raises(UnitError, match="y"):
        compile_arrays(model, minimum=0)
    with pytest.raises(UnitError):
        bg.compile(TwoUnits(x=[{"unit": "m", "start": 1.0}, {"unit": "s", "start": 2.0}]))
    assert isinstance(compile_arrays(TwoUnits(), minimum=0), ArrayCompiledModel)


def test_values_with_units_need_no_scalar_structures():
    compiled = bg.compile(RCLadderVector(1000))
    res = bg.simulate(compiled, stop_time=0.01, params={"V": "2000 mV"}, outputs=["v[1]"])
    assert res.parameters["V"] == pytest.approx(2.0)
    assert "flat" not in compiled.__dict__


class NumpyValues(Component):
    """``der(x) = -a*x`` with ``a`` from a numpy array default (numpy scalars as values)."""

    x = Variable(shape=3, start=1.0, fixed=True)
    a = Parameter(shape=3, value=np.array([1.0, 2.0, 3.0]))

    def equations(self):
        yield der(self.x) == -self.a * self.x


def test_numpy_values_take_the_array_path():
    assert why_not(NumpyValues(), minimum=0) is None
    res = bg.simulate(compile_arrays(NumpyValues(), minimum=0), stop_time=1.0, **TIGHT)
    assert res["x[3]"][-1] == pytest.approx(np.exp(-3.0), rel=1e-8)


def test_fmu_export_and_linearization_of_a_model_from_the_array_path(tmp_path):
    from fmpy import simulate_fmu

    from bgmodelica.fmi.from_model import export_model

    compiled = compile_arrays(Decays(4), minimum=0)
    fmu = export_model(compiled, tmp_path, fmi_version=2, fmu_type="cs")
    assert "flat" in compiled.__dict__           # export completed the scalar structures
    out = simulate_fmu(str(fmu), stop_time=1.0, output=["x[4]"], output_interval=0.5)
    k, x0 = 3.0, 2.0
    exact = x0 * np.exp(-k) + (1 - np.exp(-k)) / k
    assert abs(out["x[4]"][-1] - exact) < 1e-4
    sys = bg.linearize(compile_arrays(Decays(4), minimum=0))
    assert sorted(np.linalg.eigvals(sys.A).real) == pytest.approx(
        sorted(-np.linspace(0.5, 3.0, 4)), rel=1e-9)


def test_a_symbol_of_another_component_gets_the_scalar_pipelines_error():
    from bgmodelica.errors import EquationError

    other = Decays(1000)

    class Alien(DecayDeclarations):
        def equations(self):
            yield der(self.x) == -self.rate * other.x + self.u
            yield self.y == 2.0 * self.x
            yield self.s == self.x[0] + self.x[-1]

    model = Alien(1000)
    assert "KeyError" in why_not(model)
    with pytest.raises(EquationError, match="not part of the model"):
        bg.compile(Alien(1000))


def test_a_heat_rod_of_1000_nodes_takes_the_array_path_and_decays_exactly():
    from library.examples.thermal import HeatRod, rod_mode

    n = 1000
    assert why_not(HeatRod(n)) is None
    res = bg.simulate(HeatRod(n), stop_time=5.0, interval=2.5, rtol=1e-9, atol=1e-9,
                      outputs=["T[1]", "T[500]", f"T[{n}]"])
    assert isinstance(res.meta["timings"], dict) and "lowering" in res.meta["timings"]
    exact = rod_mode(n, 5.0)
    for k in (1, 500, n):
        assert abs(res[f"T[{k}]"][-1] - exact[k - 1]) < 1e-6
    assert abs(res["T[500]"][-1] - res["T[500]"][0]) > 3.0        # it did decay
    _same_dae(compile_arrays(HeatRod(5), minimum=0).dae, _compile(HeatRod(5), None).dae)


def test_a_component_changed_after_compile_is_refused_when_completing():
    from bgmodelica.errors import ModelError

    model = RCLadderVector(1000)
    compiled = bg.compile(model)
    model.modify(V=5.0)
    with pytest.raises(ModelError, match="modified after compile"):
        compiled.flat  # noqa: B018


def test_the_array_path_can_be_turned_off():
    compiled = bg.compile(RCLadderVector(1000), array_path=False)
    assert not isinstance(compiled, ArrayCompiledModel) and "flatten" in compiled.timings
    _same_dae(bg.compile(RCLadderVector(1000)).dae, compiled.dae)


class Aliased(Component):
    """:class:`Decays`-like with aliases: ``w = x`` (an array alias, ``w`` fixed at the
    start), ``m = -x[1]`` (a scalar one) and ``q[1:n] = y[1:n]`` beside ``y = 2*x``."""

    x = Variable(shape="n")
    w = Variable(shape="n")
    y = Variable(shape="n")
    q = Variable(shape="n")
    m = Variable()
    k = Parameter(shape="n", value=1.0)

    def __init__(self, n: int = 4, **modifiers):
        self.n = n
        super().__init__(**{"k": np.linspace(0.5, 2.0, n),
                            "w": np.linspace(1.0, 3.0, n), **modifiers})

    def equations(self):
        yield der(self.x) == -self.k * self.x
        yield self.w == self.x
        yield self.m == -self.x[0]
        yield self.y == 2.0 * self.x
        yield self.q == self.y


@pytest.mark.parametrize("n", [2, 7])
def test_aliases_are_eliminated_as_the_scalar_pipeline_does(n):
    fast = compile_arrays(Aliased(n), minimum=0)
    assert isinstance(fast, ArrayCompiledModel)
    slow = _compile(Aliased(n), None)
    assert fast.dae.aliases == slow.dae.aliases and fast.dae.aliases
    _same_dae(fast.dae, slow.dae)
    res = bg.simulate(fast, stop_time=1.0, interval=0.5, **TIGHT)
    k, x0 = np.linspace(0.5, 2.0, n), np.linspace(1.0, 3.0, n)
    assert res["w[2]"][-1] == pytest.approx(x0[1] * np.exp(-k[1]), rel=1e-8)
    assert res["m"][-1] == pytest.approx(-x0[0] * np.exp(-k[0]), rel=1e-8)
    assert res["q[1]"][-1] == pytest.approx(2 * x0[0] * np.exp(-k[0]), rel=1e-8)


class LoopedAliases(Component):
    """``a = b``, ``b = c``, ``c = a``: a cycle of alias links (one is an ordinary
    equation then), with ``der(a) = -a``."""

    a = Variable(shape=3, start=1.0, fixed=True)
    b = Variable(shape=3)
    c = Variable(shape=3)

    def equations(self):
        yield der(self.a) == -self.a
        yield self.a == self.b
        yield self.b == self.c
        yield self.c == self.a


def test_alias_cycles_and_conflicts_go_the_scalar_way():
    assert "cycle" in why_not(LoopedAliases(), minimum=0)
    conflicting = Aliased(3, x={"start": 5.0, "fixed": True})
    assert "conflicting" in why_not(conflicting, minimum=0)


class Measured(Component):
    """``der(x) = -k*x`` with the outputs ``y = 3*x`` (an array) and ``total = x[1] + x[n]``
    and the alias output ``copy = x``."""

    x = Variable(shape="n", start=1.0, fixed=True)
    y = bg.Output(shape="n")
    copy = bg.Output(shape="n")
    total = bg.Output()
    k = Parameter(2.0)

    def __init__(self, n: int = 3, **modifiers):
        self.n = n
        super().__init__(**modifiers)

    def equations(self):
        yield der(self.x) == -self.k * self.x
        yield self.y == 3.0 * self.x
        yield self.copy == self.x
        yield self.total == self.x[0] + self.x[-1]


def test_outputs_take_the_array_path_and_export(tmp_path):
    from fmpy import read_model_description

    from bgmodelica.fmi.from_model import export_model

    fast = compile_arrays(Measured(3), minimum=0)
    assert isinstance(fast, ArrayCompiledModel)
    slow = _compile(Measured(3), None)
    assert fast.dae.aliases == slow.dae.aliases
    _same_dae(fast.dae, slow.dae)
    res = bg.simulate(fast, stop_time=1.0, interval=0.5, **TIGHT)
    assert res["total"][-1] == pytest.approx(2 * np.exp(-2.0), rel=1e-8)
    assert res["copy[3]"][-1] == pytest.approx(np.exp(-2.0), rel=1e-8)
    fmu = export_model(fast, tmp_path)
    outputs = {v.name for v in read_model_description(str(fmu)).modelVariables
               if v.causality == "output"}
    assert {"y[1]", "y[3]", "total"} <= outputs


class Driven(Component):
    """``der(x) = -k*x + u + g`` with a scalar input ``u`` and an array input ``g``."""

    x = Variable(shape="n", start=0.0, fixed=True)
    u = bg.Input(start=1.0)
    g = bg.Input(shape="n", start=0.5)
    k = Parameter(2.0)

    def __init__(self, n: int = 3, **modifiers):
        self.n = n
        super().__init__(**modifiers)

    def equations(self):
        yield der(self.x) == -self.k * self.x + self.u + self.g


def test_inputs_take_the_array_path_held_or_as_tables():
    fast = compile_arrays(Driven(3), minimum=0)
    assert isinstance(fast, ArrayCompiledModel)
    slow = _compile(Driven(3), None)
    assert [u.name for u in fast.dae.inputs] == [u.name for u in slow.dae.inputs] \
        == ["u", "g[1]", "g[2]", "g[3]"]
    _same_dae(fast.dae, slow.dae)
    res = bg.simulate(fast, stop_time=1.0, interval=0.5, **TIGHT)        # held at start
    assert res["x[2]"][-1] == pytest.approx(1.5 / 2.0 * (1 - np.exp(-2.0)), rel=1e-8)
    table = {"u": ([0.0, 1.0], [0.0, 2.0])}                              # u = 2 t
    res = bg.simulate(fast, stop_time=1.0, interval=0.5, inputs=table, **TIGHT)
    ref = bg.simulate(slow, stop_time=1.0, interval=0.5, inputs=table, **TIGHT)
    assert np.max(np.abs(res["x[1]"] - ref["x[1]"])) < 1e-10
    assert "flat" not in fast.__dict__


@pytest.mark.parametrize("make", [lambda: RCLadderVector(3), lambda: Aliased(3),
                                  lambda: Driven(3), lambda: Measured(3), lambda: Mixed()])
def test_the_summary_equals_the_scalar_pipelines_without_building_it(make):
    fast = compile_arrays(make(), minimum=0)
    mine = fast.summary()
    assert "flat" not in fast.__dict__
    theirs = _compile(make(), None).summary()
    for summary in (mine, theirs):
        summary.pop("compile_seconds")
    assert mine == theirs


class PartlyAliases(Component):
    """Equations of one shape ``a == b``, some between two variables (aliases), one with a
    parameter (kept): ``x[k] == w[k]``, ``y == k``, and an array ``z == [x[1], g]`` half
    alias; ``der(x) = -x``."""

    x = Variable(shape=3, start=[1.0, 2.0, 3.0], fixed=True)
    w = Variable(shape=3)
    y = Variable()
    z = Variable(shape=2)
    k = Parameter(4.0)
    g = Parameter(-1.0)

    def equations(self):
        yield der(self.x) == -self.x
        yield self.w[0] == self.x[0]
        yield self.y == self.k
        yield self.w[1] == self.x[1]
        yield self.w[2] == self.x[2]
        yield self.z[0] == self.x[0]
        yield self.z[1] == self.g


def test_equations_partly_of_aliases_keep_their_other_rows():
    compiled = compile_arrays(PartlyAliases(), minimum=0)
    assert compiled is not None
    _same_dae(compiled.dae, _compile(PartlyAliases(), None).dae)
    assert {"w[1]", "w[2]", "w[3]", "z[1]"} <= set(compiled.dae.aliases)
    res = bg.simulate(compiled, stop_time=1.0, interval=0.5, outputs=["y", "z[2]", "w[3]"],
                      **TIGHT)
    assert res.final("y") == 4.0 and res.final("z[2]") == -1.0
    assert abs(res.final("w[3]") - 3.0 * np.exp(-1.0)) < 1e-8
