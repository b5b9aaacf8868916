"""The array path for models of leaf components joined by ``connect``: the scalar pipeline's
DAE (names, states, parameters and their owners, aliases, starts, ODE and observations), the
models that go the scalar way and why, and the scalar pipeline's errors."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica import Component, Parameter, StateSelect, Variable, der
from bgmodelica.array_path import ArrayCompiledModel, compile_arrays, why_not
from bgmodelica.compiler import _compile
from bgmodelica.errors import UnbalancedModelError, UnitError
from library import translational as tr
from library.blocks import Constant
from library.electrical import (
    Capacitor,
    ConstantVoltage,
    Ground,
    Inductor,
    OnePort,
    Resistor,
    SignalVoltage,
    SineVoltage,
)
from library.examples.circuits import RC, RCLadder, RCLadderArrays, SeriesRLC

TIGHT = {"rtol": 1e-10, "atol": 1e-10}


# -- helpers -----------------------------------------------------------------------------------

def _point(dae, seed: int = 7):
    rng = np.random.default_rng(seed)
    return rng.random(dae.x.numel()) + 0.5, rng.random(dae.p.numel()) + 0.5, 0.37


def _evaluate(dae, x, p, t):
    f = ca.Function("f", [dae.x, dae.p, dae.t], [dae.ode, dae.observed])
    ode, observed = f(x, p, t)
    return np.asarray(ode).ravel(), np.asarray(observed).ravel()


def _values(dae, seed: int = 7) -> dict[str, float]:
    """Every variable's value (aliases included) and every parameter's at a random state,
    parameters and time."""
    x, p, t = _point(dae, seed)
    _, observed = _evaluate(dae, x, p, t)
    out = dict(zip(dae.names, observed.tolist(), strict=True))
    out.update(zip([q.name for q in dae.parameters], p.tolist(), strict=True))
    for name, (target, sign) in dae.aliases.items():
        out[name] = sign * out[target]
    return out


def _close(u, v) -> None:
    u, v = np.asarray(u, dtype=float), np.asarray(v, dtype=float)
    scale = max(1.0, float(np.max(np.abs(v), initial=0.0)))
    np.testing.assert_allclose(u, v, rtol=1e-12, atol=1e-12 * scale)


def _same_dae(a, b) -> None:
    """``a`` (array path) is the DAE ``b`` of the scalar pipeline."""
    assert a.names == b.names
    assert a.state_names == b.state_names
    assert a.algebraic_names == b.algebraic_names
    assert a.observed_index == b.observed_index
    assert [(q.name, q.component) for q in a.parameters] \
        == [(q.name, q.component) for q in b.parameters]
    assert [q.decl.unit for q in a.parameters] == [q.decl.unit for q in b.parameters]
    assert [u.name for u in a.inputs] == [u.name for u in b.inputs]
    assert a.aliases == b.aliases
    assert np.array_equal(a.x_start, b.x_start)
    assert a.fixed == b.fixed
    assert np.array_equal(a.p_default, b.p_default)
    assert a.differentiated == b.differentiated
    for seed in (3, 11):
        point = _point(a, seed)
        for u, v in zip(_evaluate(a, *point), _evaluate(b, *point), strict=True):
            _close(u, v)


def _fast_and_slow(make):
    """The model compiled by the array path (which must take it) and by the scalar one."""
    fast = compile_arrays(make(), minimum=0)
    assert isinstance(fast, ArrayCompiledModel), why_not(make(), minimum=0)
    return fast, _compile(make(), None)


# -- models ------------------------------------------------------------------------------------

class RLCChain(Component):
    """A sine source feeding ``n`` sections: ``Rk`` and ``Lk`` in series, then ``Ck`` to
    ground (the inductor currents are states; the sets between ``Rk`` and ``Lk`` have two
    members)."""

    def __init__(self, n: int = 3, **modifiers):
        super().__init__(**modifiers)
        self.source = SineVoltage(V=1.0, f=2.0)
        self.ground = Ground()
        self.connect(self.source.n, self.ground.p)
        node = self.source.p
        for k in range(1, n + 1):
            r = self.add(f"R{k}", Resistor(R=1.0 + k))
            ind = self.add(f"L{k}", Inductor(L=0.1 * k, i=0.01 * k))
            c = self.add(f"C{k}", Capacitor(C=1e-2 / k, v=0.5 * k))
            self.connect(node, r.p)
            self.connect(r.n, ind.p)
            self.connect(ind.n, c.p)
            self.connect(c.n, self.ground.p)
            node = ind.n


class SlidingMass(tr.PartialTwoFlanges):
    """:class:`library.translational.Mass` without its state selection (default: the
    array path takes it): ``m*der(v) = flange_a.f + flange_b.f``, ``v = der(s)``."""

    m = Parameter(1.0, unit="kg")
    s = Variable(unit="m")
    v = Variable(unit="m/s")

    def equations(self):
        yield self.flange_a.s == self.s
        yield self.flange_b.s == self.s
        yield self.v == der(self.s)
        yield self.m * der(self.v) == self.flange_a.f + self.flange_b.f


class MassChain(Component):
    """A wall, then ``n`` masses: the first on a spring, each next one joined by a spring
    in parallel with a Maxwell element (spring and damper in series, their joint massless);
    a constant force pulls the last mass."""

    def __init__(self, n: int = 3, **modifiers):
        super().__init__(**modifiers)
        self.wall = tr.Fixed(s0=0.0)
        self.pull = tr.ConstantForce(f_constant=2.0)
        node = self.wall.flange
        for k in range(1, n + 1):
            mass = self.add(f"mass{k}", SlidingMass(m=1.0 + 0.1 * k, s=float(k), v=0.0))
            spring = self.add(f"spring{k}", tr.Spring(c=10.0 * k, s_rel0=1.0))
            self.connect(node, spring.flange_a)
            self.connect(spring.flange_b, mass.flange_a)
            if k > 1:
                inner = self.add(f"inner{k}", tr.Spring(c=5.0, s_rel0=0.5))
                damper = self.add(f"damper{k}", tr.Damper(d=0.3 * k, s_rel=0.5))
                self.connect(node, inner.flange_a)
                self.connect(inner.flange_b, damper.flange_a)
                self.connect(damper.flange_b, mass.flange_a)
            node = mass.flange_b
        self.connect(node, self.pull.flange)


class LibraryMassChain(Component):
    """Springs and :class:`library.translational.Mass` (whose ``s`` and ``v`` prefer to be
    states)."""

    def __init__(self, n: int = 3, **modifiers):
        super().__init__(**modifiers)
        self.wall = tr.Fixed()
        node = self.wall.flange
        for k in range(1, n + 1):
            spring = self.add(f"spring{k}", tr.Spring(c=10.0 * k))
            mass = self.add(f"mass{k}", tr.Mass(m=1.0, s=0.1 * k, v=0.0))
            self.connect(node, spring.flange_a)
            self.connect(spring.flange_b, mass.flange_a)
            node = mass.flange_b


class AlwaysMass(SlidingMass):
    """:class:`SlidingMass` whose velocity must be a state (``StateSelect.ALWAYS``, which
    the scalar pipeline checks against the structure)."""

    v = Variable(unit="m/s", state_select=StateSelect.ALWAYS)


class AlwaysMassChain(Component):
    """Springs and :class:`AlwaysMass` masses from a wall."""

    def __init__(self, n: int = 3, **modifiers):
        super().__init__(**modifiers)
        self.wall = tr.Fixed()
        node = self.wall.flange
        for k in range(1, n + 1):
            spring = self.add(f"spring{k}", tr.Spring(c=10.0 * k))
            mass = self.add(f"mass{k}", AlwaysMass(m=1.0, s=0.1 * k, v=0.0))
            self.connect(node, spring.flange_a)
            self.connect(spring.flange_b, mass.flange_a)
            node = mass.flange_b


class ProbedLadder(RCLadder):
    """:class:`RCLadder` with a resistor ``probe`` hanging from node 1, its pin ``n``
    connected to nothing (so ``probe.n.i = 0``, hence ``probe.i = 0``)."""

    def __init__(self, n: int = 3, **modifiers):
        super().__init__(n, **modifiers)
        self.add("probe", Resistor(R=3.0))
        self.connect(self.R1.n, self.probe.p)


class ParallelRC(Component):
    """``n`` branches ``Rk`` -> ``Ck`` in parallel on one constant source ``V``: each
    ``Ck.v = V*(1 - exp(-t/(Rk*Ck)))`` from ``Ck.v(0) = 0``."""

    def __init__(self, n: int = 3, V: float = 2.0, **modifiers):
        super().__init__(**modifiers)
        self.source = ConstantVoltage(V=V)
        self.ground = Ground()
        self.connect(self.source.n, self.ground.p)
        for k in range(1, n + 1):
            r = self.add(f"R{k}", Resistor(R=_branch_r(k, n)))
            c = self.add(f"C{k}", Capacitor(C=_branch_c(k, n), v=0.0))
            self.connect(self.source.p, r.p)
            self.connect(r.n, c.p)
            self.connect(c.n, self.ground.p)


def _branch_r(k: int, n: int) -> float:
    return 1.0 + k / n


def _branch_c(k: int, n: int) -> float:
    return 0.25 + 0.5 * ((7 * k) % n) / n


# -- 1. the scalar pipeline's DAE ----------------------------------------------------------------

@pytest.mark.parametrize("n", [1, 2, 5, 70])
def test_a_ladder_of_components_gives_the_scalar_pipelines_dae(n):
    fast, slow = _fast_and_slow(lambda: RCLadder(n))
    _same_dae(fast.dae, slow.dae)
    assert fast.dae.state_names == [f"C{k}.v" for k in range(1, n + 1)]
    assert fast.dae.aliases                                     # connections make aliases
    owners = {q.name: q.component for q in fast.dae.parameters}
    assert owners["source.V"] == "source" and owners[f"R{n}.R"] == f"R{n}"


@pytest.mark.parametrize("n", [3, 70])
def test_a_ladder_of_arrays_of_components_gives_the_scalar_pipelines_dae(n):
    fast, slow = _fast_and_slow(lambda: RCLadderArrays(n))
    _same_dae(fast.dae, slow.dae)
    assert fast.dae.state_names == [f"C[{k}].v" for k in range(1, n + 1)]


@pytest.mark.parametrize("n", [2, 70])
def test_inductor_currents_as_states_give_the_scalar_pipelines_dae(n):
    fast, slow = _fast_and_slow(lambda: RLCChain(n))
    _same_dae(fast.dae, slow.dae)
    assert {"L1.i", "C1.v", f"L{n}.i"} <= set(fast.dae.state_names)
    # Rk, Lk in series: one current, the resistor's an alias of the inductor's state
    assert fast.dae.aliases["R1.i"] == ("L1.i", 1.0)


@pytest.mark.parametrize("n", [2, 70])
def test_a_mechanical_chain_gives_the_scalar_pipelines_dae(n):
    fast, slow = _fast_and_slow(lambda: MassChain(n))
    _same_dae(fast.dae, slow.dae)
    assert {"mass1.s", "mass1.v", f"mass{n}.v", f"damper{n}.s_rel"} \
        <= set(fast.dae.state_names)
    values = _values(fast.dae)
    # the last mass's flange_b and the force's flange form a set of two
    assert values[f"mass{n}.flange_b.f"] == values["pull.f_constant"] != 0.0
    assert values["wall.flange.s"] == values["spring1.flange_a.s"] == values["wall.s0"]


@pytest.mark.parametrize("n", [2, 70])
def test_masses_that_prefer_their_states_give_the_scalar_pipelines_dae(n):
    # library Mass: s and v declared StateSelect.PREFER, which ranks aliases only here
    fast, slow = _fast_and_slow(lambda: LibraryMassChain(n))
    _same_dae(fast.dae, slow.dae)
    assert {f"mass{n}.s", f"mass{n}.v"} <= set(fast.dae.state_names)


def test_an_unconnected_connector_carries_no_flow():
    fast, slow = _fast_and_slow(lambda: ProbedLadder(4))
    _same_dae(fast.dae, slow.dae)
    for seed in (3, 5):
        values = _values(fast.dae, seed)
        assert values["probe.n.i"] == 0.0 and values["probe.i"] == 0.0
        assert values["probe.p.i"] == 0.0
        assert values["probe.n.v"] == pytest.approx(values["R1.n.v"], rel=1e-12)
        assert values["probe.p.v"] == pytest.approx(values["C1.v"], rel=1e-12)


def test_flows_of_a_set_of_two_are_aliases():
    fast, slow = _fast_and_slow(SeriesRLC)
    _same_dae(fast.dae, slow.dae)
    values = _values(fast.dae)
    for a, b in (("source.p", "resistor.p"), ("resistor.n", "inductor.p"),
                 ("inductor.n", "capacitor.p")):
        # the set's flow row a.i + b.i = 0 was eliminated, not kept as an equation
        assert f"{a}.i" in fast.dae.aliases or f"{b}.i" in fast.dae.aliases
        assert f"{a}.i" in fast.dae.aliases or f"{a}.i" in fast.dae.names
        assert values[f"{a}.i"] == -values[f"{b}.i"] != 0.0
        assert values[f"{a}.v"] == values[f"{b}.v"]
    assert fast.dae.state_names == slow.dae.state_names == ["inductor.i", "capacitor.v"]


class RedundantLinks(RCLadder):
    """:class:`RCLadder` with a connection repeated, the same one reversed, and one closing a
    cycle in the graph of a connection set (``C2.n`` to ``source.n``, already joined
    through ``ground.p``)."""

    def __init__(self, n: int = 3, **modifiers):
        super().__init__(n, **modifiers)
        self.connect(self.R1.n, self.C1.p)
        self.connect(self.C1.p, self.R1.n)
        self.connect(self.C2.n, self.source.n)


@pytest.mark.parametrize("n", [3, 70])
def test_repeated_and_redundant_connections_give_the_scalar_pipelines_dae(n):
    fast, slow = _fast_and_slow(lambda: RedundantLinks(n))
    _same_dae(fast.dae, slow.dae)


class RCWithRL(Component):
    """An RC ladder whose every node also has a resistor ``Dk`` and an inductor ``Lk`` in
    series to ground: the resistors play two roles (``Rk`` gives its current from the
    voltages, ``Dk`` its voltage from the inductor's current). No algebraic loop."""

    def __init__(self, n: int = 3, **modifiers):
        super().__init__(**modifiers)
        self.source = SineVoltage(V=1.0, f=2.0)
        self.ground = Ground()
        self.connect(self.source.n, self.ground.p)
        node = self.source.p
        for k in range(1, n + 1):
            r = self.add(f"R{k}", Resistor(R=1.0 + 0.1 * k))
            c = self.add(f"C{k}", Capacitor(C=1.0, v=0.1 * k))
            d = self.add(f"D{k}", Resistor(R=2.0))
            ind = self.add(f"L{k}", Inductor(L=0.5, i=0.01 * k))
            self.connect(node, r.p)
            self.connect(r.n, c.p)
            self.connect(c.n, self.ground.p)
            self.connect(c.p, d.p)
            self.connect(d.n, ind.p)
            self.connect(ind.n, self.ground.p)
            node = c.p


def test_a_class_in_two_roles_gives_the_scalar_pipelines_dae():
    fast, slow = _fast_and_slow(lambda: RCWithRL(10))          # below the grouping
    _same_dae(fast.dae, slow.dae)
    assert not slow.summary()["algebraic_loops"]
    # 280 components, every class grouped: the resistors' block solves currents from
    # voltages (R) and voltages from currents (D), at two levels of the system
    assert why_not(RCWithRL(70), minimum=0) is None
    grouped = bg.compile(RCWithRL(70))
    assert isinstance(grouped, ArrayCompiledModel)
    _same_dae(grouped.dae, _compile(RCWithRL(70), None).dae)


# -- 2. an analytic solution ---------------------------------------------------------------------

def test_parallel_rc_branches_charge_as_the_analytic_solution():
    n, volts = 1000, 2.0
    model = ParallelRC(n, V=volts)
    assert why_not(model) is None
    compiled = bg.compile(model)
    assert isinstance(compiled, ArrayCompiledModel)
    picked = [1, 2, 500, 777, n]
    res = bg.simulate(compiled, stop_time=2.0, interval=0.25, **TIGHT,
                      outputs=[f"C{k}.v" for k in picked] + ["source.i", "R1.i"])
    assert res.time[-1] == pytest.approx(2.0)
    for k in picked:
        tau = _branch_r(k, n) * _branch_c(k, n)
        exact = volts * (1.0 - np.exp(-res.time / tau))
        assert np.max(np.abs(res[f"C{k}.v"] - exact)) < 1e-6
        assert res[f"C{k}.v"][-1] > 0.5                      # it did charge
    tau1 = _branch_r(1, n) * _branch_c(1, n)
    exact_i = volts / _branch_r(1, n) * np.exp(-res.time / tau1)
    assert np.max(np.abs(res["R1.i"] - exact_i)) < 1e-6
    assert np.all(res["source.i"] < 0.0)              # the source delivers every branch's
    assert "reduced" not in compiled.__dict__


# -- 3. what goes the scalar way, and why ----------------------------------------------------------

class OwnVariables(RCLadder):
    """:class:`RCLadder` with a variable of the top level: ``total = C1.v + C2.v``."""

    total = Variable(unit="V")

    def equations(self):
        yield self.total == self.C1.v + self.C2.v


class TopParameters(RCLadder):
    """:class:`RCLadder` with a parameter and a variable of the top level, and an equation
    of its own: ``total = gain*(C1.v + C2.v)``."""

    gain = Parameter(2.0)
    total = Variable(unit="V")

    def equations(self):
        yield self.total == self.gain * (self.C1.v + self.C2.v)


@pytest.mark.parametrize("make", [lambda: OwnVariables(3), lambda: TopParameters(70)],
                         ids=["own-variable", "own-parameter-70"])
def test_variables_and_equations_of_the_top_level_give_the_scalar_pipelines_dae(make):
    fast, slow = _fast_and_slow(make)
    _same_dae(fast.dae, slow.dae)
    assert "total" in fast.dae.names


def test_a_ladder_from_modelica_text_takes_the_array_path():
    from pathlib import Path

    mo = Path(__file__).resolve().parents[1] / "modelica" / "models" / "circuits.mo"
    model = bg.load_modelica(mo, "Circuits.RCLadder", n=1200)
    assert why_not(model) is None            # arrays of components, a parameter n
    compiled = bg.compile(model)
    assert isinstance(compiled, ArrayCompiledModel)
    _same_dae(compiled.dae, _compile(bg.load_modelica(mo, "Circuits.RCLadder", n=1200),
                                     None).dae)
    py = bg.simulate(bg.compile(RCLadder(1200)), stop_time=0.05, interval=0.05,
                     outputs=["C1200.v"], **TIGHT)
    mo_res = bg.simulate(compiled, stop_time=0.05, interval=0.05, outputs=["C[1200].v"],
                         **TIGHT)
    assert abs(py.final("C1200.v") - mo_res.final("C[1200].v")) < 1e-8


class StartsAtRest(Capacitor):
    """A capacitor starting from ``der(v) = 0`` (an initial equation)."""

    def initial_equations(self):
        yield der(self.v) == 0


class WithInitialEquations(Component):
    """A constant source charging ``StartsAtRest`` through a resistor."""

    def __init__(self, **modifiers):
        super().__init__(**modifiers)
        self.source = ConstantVoltage(V=1.0)
        self.resistor = Resistor(R=2.0)
        self.capacitor = StartsAtRest(C=0.5)
        self.ground = Ground()
        self.connect(self.source.p, self.resistor.p)
        self.connect(self.resistor.n, self.capacitor.p)
        self.connect(self.capacitor.n, self.ground.p)
        self.connect(self.source.n, self.ground.p)


class SignalDriven(Component):
    """A block's output drives a voltage source through a signal connection."""

    def __init__(self, **modifiers):
        super().__init__(**modifiers)
        self.setpoint = Constant(k=2.0)
        self.source = SignalVoltage()
        self.resistor = Resistor(R=2.0)
        self.capacitor = Capacitor(C=0.5, v=0.0)
        self.ground = Ground()
        self.connect(self.setpoint.y, self.source.u)
        self.connect(self.source.p, self.resistor.p)
        self.connect(self.resistor.n, self.capacitor.p)
        self.connect(self.capacitor.n, self.ground.p)
        self.connect(self.source.n, self.ground.p)


@pytest.mark.parametrize(("make", "reason"), [
    (WithInitialEquations, "a subcomponent has initial equations"),
    (SignalDriven, "the top level connects signals"),
    (lambda: AlwaysMassChain(3), "a variable has a state selection"),
], ids=["initial-equations", "signal-connection",
        "state-selection"])
def test_models_going_the_scalar_way_say_why_and_compile(make, reason):
    found = why_not(make(), minimum=0)
    assert found is not None and reason in found
    assert compile_arrays(make(), minimum=0) is None
    compiled = bg.compile(make())
    assert not isinstance(compiled, ArrayCompiledModel)
    slow = _compile(make(), None)
    assert compiled.dae.names == slow.dae.names
    assert compiled.dae.state_names == slow.dae.state_names


def test_a_large_nested_model_takes_the_array_path_and_simulates():
    class BigNested(RCLadder):
        def __init__(self):
            super().__init__(400)
            self.rc = RC()

    assert why_not(BigNested()) is None
    compiled = bg.compile(BigNested())
    assert isinstance(compiled, ArrayCompiledModel)
    res = bg.simulate(compiled, stop_time=1.0, interval=0.5, **TIGHT, outputs=["rc.capacitor.v"])
    assert res["rc.capacitor.v"][-1] == pytest.approx(10.0 * (1 - np.exp(-1.0)), rel=1e-7)


# -- 4. the scalar pipeline's errors -------------------------------------------------------------

class Lossless(OnePort):
    """A one-port missing its constitutive equation (one equation short)."""

    R = Parameter(1.0, unit="Ohm")


class BadUnits(OnePort):
    """A resistor writing ``v = R*R*i`` (Ohm2.A where V is declared)."""

    R = Parameter(1.0, unit="Ohm")

    def equations(self):
        yield self.v == self.R * self.R * self.i


class Sections(Component):
    """``n`` sections of a one-port class ``kind`` in series, each node with a capacitor to
    ground, fed by a sine source."""

    def __init__(self, kind, n: int, **modifiers):
        super().__init__(**modifiers)
        self.source = SineVoltage(V=1.0, f=10.0)
        self.ground = Ground()
        self.connect(self.source.n, self.ground.p)
        node = self.source.p
        for k in range(1, n + 1):
            part = self.add(f"R{k}", kind(R=1.0 / k))
            c = self.add(f"C{k}", Capacitor(C=1.0 / k, v=float(k)))
            self.connect(node, part.p)
            self.connect(part.n, c.p)
            self.connect(c.n, self.ground.p)
            node = part.n


class ParallelSources(RCLadder):
    """:class:`RCLadder` with a second (constant) source across the first: the two fix the
    same voltage and nothing fixes how they share the current (structurally singular)."""

    def __init__(self, n: int = 3, **modifiers):
        super().__init__(n, **modifiers)
        self.add("twin", ConstantVoltage(V=1.0))
        self.connect(self.source.p, self.twin.p)
        self.connect(self.source.n, self.twin.n)


def _error_of(call):
    with pytest.raises(Exception) as info:  # noqa: PT011 -- compared below
        call()
    return type(info.value), str(info.value)


@pytest.mark.parametrize(("make", "words"), [
    (lambda: Sections(Lossless, 300), "is unbalanced"),
    (lambda: ParallelSources(400), "structurally singular"),
], ids=["unbalanced", "singular"])
def test_an_ill_posed_model_gets_the_scalar_pipelines_error(make, words):
    reason = why_not(make())
    assert reason is not None and reason != "small"          # it was tried
    fast = _error_of(lambda: bg.compile(make()))
    slow = _error_of(lambda: bg.compile(make(), array_path=False))
    assert fast == slow
    assert fast[0] is UnbalancedModelError and words in fast[1]


def test_a_unit_error_in_a_class_used_100_times_is_the_scalar_pipelines():
    assert why_not(Sections(BadUnits, 100)) is None          # without the unit check
    assert compile_arrays(Sections(BadUnits, 100)) is None    # the unit check refuses it
    fast = _error_of(lambda: bg.compile(Sections(BadUnits, 100)))
    slow = _error_of(lambda: bg.compile(Sections(BadUnits, 100), array_path=False))
    assert fast == slow and fast[0] is UnitError
    assert isinstance(bg.compile(Sections(BadUnits, 100), units="off"), ArrayCompiledModel)


# -- 5. algebraic loops --------------------------------------------------------------------------

class DividerLadder(Component):
    """``n`` sections: from the previous capacitor node, ``Ak`` to a node ``k`` tied to
    ground by ``Bk`` and, through ``Dk``, to the capacitor ``Ck``: the voltage of node ``k``
    solves a linear loop of the three resistors' currents."""

    def __init__(self, n: int = 3, **modifiers):
        super().__init__(**modifiers)
        self.source = SineVoltage(V=1.0, f=1.0)
        self.ground = Ground()
        self.connect(self.source.n, self.ground.p)
        node = self.source.p
        for k in range(1, n + 1):
            a = self.add(f"A{k}", Resistor(R=1.0 + 0.01 * k))
            b = self.add(f"B{k}", Resistor(R=2.0))
            d = self.add(f"D{k}", Resistor(R=0.5))
            c = self.add(f"C{k}", Capacitor(C=0.1, v=0.01 * k))
            self.connect(node, a.p)
            self.connect(a.n, b.p)
            self.connect(b.n, self.ground.p)
            self.connect(a.n, d.p)
            self.connect(d.n, c.p)
            self.connect(c.n, self.ground.p)
            node = c.p


def test_an_algebraic_loop_of_components_goes_the_scalar_way_and_is_right():
    n = 200
    assert "algebraic loop" in why_not(DividerLadder(n))
    compiled = bg.compile(DividerLadder(n))
    assert not isinstance(compiled, ArrayCompiledModel)
    slow = bg.compile(DividerLadder(n), array_path=False)
    outputs = ["C1.v", f"C{n}.v", "B1.i", "A7.n.v"]
    res = bg.simulate(compiled, stop_time=0.5, interval=0.1, **TIGHT, outputs=outputs)
    ref = bg.simulate(slow, stop_time=0.5, interval=0.1, **TIGHT, outputs=outputs)
    for name in outputs:
        assert np.max(np.abs(res[name] - ref[name])) < 1e-12
    # node 1 is the divider of the source, ground and C1 (B1.i = A1.n.v / B1.R)
    assert res["B1.i"][-1] != 0.0


# -- 6. the scalar structures on demand ------------------------------------------------------------

def test_the_scalar_structures_of_a_ladder_are_made_on_first_use():
    compiled = bg.compile(RCLadder(1200))
    assert isinstance(compiled, ArrayCompiledModel)
    res = bg.simulate(compiled, stop_time=0.01, interval=0.005, outputs=["C1.v", "C1200.v"])
    assert np.isfinite(res["C1.v"]).all()
    assert "reduced" not in compiled.__dict__ and "flat" not in compiled.__dict__
    assert "scalar_structures" not in compiled.timings
    before = compiled.dae
    reduced = compiled.reduced
    assert reduced is compiled.__dict__["reduced"]
    assert compiled.timings["scalar_structures"] > 0
    assert compiled.dae is not before
    _same_dae(before, compiled.dae)


def test_summary_pickling_and_parameter_overrides_match_the_scalar_pipeline():
    from bgmodelica.studies.payload import pickle_compiled, unpickle_compiled

    compiled = bg.compile(RCLadder(1200))
    assert isinstance(compiled, ArrayCompiledModel)
    slow = bg.compile(RCLadder(1200), array_path=False)
    mine, theirs = compiled.summary(), slow.summary()
    assert {k: v for k, v in mine.items() if k != "compile_seconds"} == \
        {k: v for k, v in theirs.items() if k != "compile_seconds"}
    assert "reduced" not in compiled.__dict__             # read off the array path's result
    back = unpickle_compiled(pickle_compiled(compiled))
    runs = [bg.simulate(m, stop_time=0.05, interval=0.01, outputs=["C7.v", "R5.i"],
                        params={"R5.R": 2.0}, **TIGHT) for m in (compiled, back, slow)]
    for res in runs[1:]:
        assert np.max(np.abs(res["C7.v"] - runs[0]["C7.v"])) < 1e-12
        assert np.max(np.abs(res["R5.i"] - runs[0]["R5.i"])) < 1e-12
    assert runs[0].parameters["R5.R"] == 2.0 and runs[0].units["R5.i"] == "A"


def test_fmu_export_of_a_model_of_components_from_the_array_path(tmp_path):
    from fmpy import simulate_fmu

    from bgmodelica.fmi.from_model import export_model

    n, volts = 3, 2.0
    compiled = compile_arrays(ParallelRC(n, V=volts), minimum=0)
    assert compiled is not None
    fmu = export_model(compiled, tmp_path, fmi_version=2, fmu_type="cs")
    assert "flat" in compiled.__dict__           # export completed the scalar structures
    out = simulate_fmu(str(fmu), stop_time=1.0, output=["C2.v", "R2.i"], output_interval=0.5)
    tau = _branch_r(2, n) * _branch_c(2, n)
    assert abs(out["C2.v"][-1] - volts * (1 - np.exp(-1.0 / tau))) < 1e-4
    assert abs(out["R2.i"][-1] - volts / _branch_r(2, n) * np.exp(-1.0 / tau)) < 1e-4


class Decay(Component):
    """``der(x) = -k*x``, ``x(0) = 1``: no connectors."""

    x = Variable(start=1.0, fixed=True)
    k = Parameter(1.0)

    def equations(self):
        yield der(self.x) == -self.k * self.x


class Decays(Component):
    """``n`` independent :class:`Decay` components (``k = 1 + i/10``), no connections."""

    def __init__(self, n: int = 3, **modifiers):
        super().__init__(**modifiers)
        for i in range(n):
            self.add(f"d{i}", Decay(k=1.0 + i / 10))


@pytest.mark.parametrize("n", [3, 100])
def test_components_without_connectors_take_the_array_path(n):
    fast, slow = _fast_and_slow(lambda: Decays(n))
    _same_dae(fast.dae, slow.dae)
    res = bg.simulate(fast, stop_time=1.0, interval=0.5, outputs=[f"d{n - 1}.x"], **TIGHT)
    assert abs(res.final(f"d{n - 1}.x") - np.exp(-(1.0 + (n - 1) / 10))) < 1e-8
