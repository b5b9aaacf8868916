"""Hybrid semantics (relations, when/elsewhen, pre/edge/change, sample, tables, inputs, if-
equations, no_event, event rows) and clear errors for bad hybrid input."""

from __future__ import annotations

import math

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica import (
    Boolean,
    Component,
    Discrete,
    Input,
    Integer,
    Parameter,
    Variable,
    change,
    der,
    edge,
    eq,
    if_else,
    if_equation,
    initial,
    no_event,
    pre,
    reinit,
    sample,
    time,
    time_table,
    when,
)
from bgmodelica.errors import EquationError, ModelError
from bgmodelica.events import EventError

TIGHT = dict(rtol=1e-10, atol=1e-12)


class Counter(Component):
    """n counts the samples; y integrates 1 while n is even."""

    Ts = Parameter(0.1, unit="s")
    n = Integer(start=0)
    ticked = Boolean(start=False)
    y = Variable(start=0.0, fixed=True)

    def equations(self):
        yield when(sample(0.05, self.Ts), self.n == pre(self.n) + 1)
        yield self.ticked == change(self.n)
        yield der(self.y) == if_else(eq(self.n - 2 * bg.core.expr.Op("floor", (self.n / 2,)),
                                        0), 1.0, 0.0)


def test_sample_counter_and_event_rows():
    res = bg.simulate(Counter(), stop_time=1.0, interval=0.25, **TIGHT)
    ev = res.meta["event_times"]
    assert ev == pytest.approx([0.05 + 0.1 * k for k in range(10)], abs=1e-15)
    assert res["n"][-1] == 10
    # two rows at each event: left limit then right limit
    t = res.time
    k = int(np.nonzero(t == ev[0])[0][0])
    assert t[k + 1] == t[k] and res["n"][k] == 0 and res["n"][k + 1] == 1
    # y grows while n is even: [0, .05], [.15, .25], ...: 0.05 + 4*0.1 + 0.05 = 0.5
    assert res["y"][-1] == pytest.approx(0.05 + 4 * 0.1 + 0.05, abs=1e-9)


class Thermostat(Component):
    """Relay with hysteresis on a first-order room: heat on below 19, off above 21."""

    T = Variable(start=20.0, fixed=True)
    heating = Boolean(start=True)

    def equations(self):
        yield der(self.T) == if_else(self.heating, 2.0, 0.0) - 0.1 * (self.T - 10.0)
        yield when(self.T > 21.0, self.heating == False).elsewhen(  # noqa: E712
            self.T < 19.0, self.heating == True)  # noqa: E712


def test_hysteresis_switching_times_analytic():
    res = bg.simulate(Thermostat(), stop_time=30.0, interval=0.5, **TIGHT)
    # heating: T' = 2 - 0.1 (T - 10) -> T_inf = 30; from 20 to 21: t = 10 ln(10/9)
    t1 = 10 * math.log(10 / 9)
    # cooling from 21 to 19: T_inf = 10: t = 10 ln(11/9)
    t2 = t1 + 10 * math.log(11 / 9)
    t3 = t2 + 10 * math.log(11 / 9)     # heating from 19 to 21: (30-19)/(30-21)
    # each switch is followed at once by the relation that fired falling back (an event at
    # which no when-clause fires): keep the first event of each cluster
    ev = [t for k, t in enumerate(res.meta["event_times"])
          if k == 0 or t - res.meta["event_times"][k - 1] > 1e-9]
    assert ev[:3] == pytest.approx([t1, t2, t3], abs=1e-7)
    on = res["heating"]
    assert on[np.searchsorted(res.time, 2.0)] == 0.0 and on[np.searchsorted(res.time, 4.0)] == 1


class EdgeAndInitial(Component):
    x = Variable(start=0.0, fixed=True)
    up = Boolean(start=False)
    rising = Integer(start=0)
    init_seen = Discrete(start=0.0)

    def equations(self):
        yield der(self.x) == 1.0
        yield self.up == (self.x > 0.5)
        yield when(edge(self.up), self.rising == pre(self.rising) + 1)
        yield when(initial(), self.init_seen == 42.0)


def test_edge_and_initial():
    res = bg.simulate(EdgeAndInitial(), stop_time=1.0, interval=0.1, **TIGHT)
    assert res["init_seen"][0] == 42.0
    assert res["rising"][-1] == 1
    assert res.meta["event_times"] == pytest.approx([0.5], abs=1e-10)


class TableSource(Component):
    y = Variable()
    z = Variable(start=0.0, fixed=True)

    def equations(self):
        yield self.y == time_table([0, 1, 1, 2], [0, 1, 3, 3], extrapolation="periodic")
        yield der(self.z) == self.y


def test_time_table_jump_and_periodic():
    res = bg.simulate(TableSource(), stop_time=4.0, interval=0.25, **TIGHT)
    t, y = res.time, res["y"]
    k = np.nonzero(t == 1.0)[0]
    assert len(k) == 2 and y[k[0]] == pytest.approx(1.0) and y[k[1]] == pytest.approx(3.0)
    assert y[np.nonzero(t == 2.5)[0][0]] == pytest.approx(0.5)     # periodic: 0.5 -> 0.5
    # integral over one period: 0.5 + 3 = 3.5, two periods: 7
    assert res["z"][-1] == pytest.approx(7.0, abs=1e-9)


class IfEq(Component):
    x = Variable(start=-1.0, fixed=True)
    a = Variable()

    def equations(self):
        yield der(self.x) == self.a
        yield if_equation(self.x < 0, [self.a == 2.0], [self.a == -self.x])


def test_if_equation_switches_at_crossing():
    res = bg.simulate(IfEq(), stop_time=2.0, interval=0.1, **TIGHT)
    # x = -1 + 2t until t = 0.5, then x' = -x from 0: stays 0
    assert res.meta["event_times"] == pytest.approx([0.5], abs=1e-10)
    assert abs(res["x"][-1]) < 1e-9


class NoEventAbs(Component):
    x = Variable(start=0.0, fixed=True)

    def equations(self):
        yield der(self.x) == no_event(if_else(time < 0.5, 1.0, -1.0))


def test_no_event_creates_no_event():
    c = bg.compile(NoEventAbs())
    assert c.dae.hybrid is None
    res = bg.simulate(c, stop_time=1.0, interval=0.5, rtol=1e-8)
    assert "n_events" not in res.meta
    assert abs(res["x"][-1]) < 1e-4


class Inputs(Component):
    u = Input(unit="V")
    x = Variable(start=0.0, fixed=True)

    def equations(self):
        yield der(self.x) == self.u


def test_inputs_from_mapping_with_jump():
    res = bg.simulate(Inputs(), stop_time=3.0, interval=0.5,
                      inputs={"u": ([0, 1, 1, 2], [0, 1, -1, -1])}, **TIGHT)
    # integral: 0.5 (ramp) - 1 (second) - 1 (held last value)
    assert res["x"][-1] == pytest.approx(-1.5, abs=1e-9)
    with pytest.raises(ModelError, match="not inputs of the model"):
        bg.simulate(Inputs(), stop_time=1.0, inputs={"w": ([0, 1], [0, 1])})


def test_check_lists_events(capsys):
    from bgmodelica.cli import main

    assert main(["check", "library.examples.hybrid:PWMMotor"]) == 0
    out = capsys.readouterr().out
    assert "time event" in out and "sample(0, 5e-05)" in out and "period_start" in out


# -- bad input -----------------------------------------------------------------------------------

class ReinitAlgebraic(Component):
    x = Variable(start=0.0, fixed=True)
    y = Variable()

    def equations(self):
        yield der(self.x) == 1.0
        yield self.y == 2 * self.x
        yield when(self.x > 0.5, reinit(self.y, 0.0))


def test_reinit_of_non_state_is_an_error():
    with pytest.raises(EquationError, match=r"reinit\(y.*not a state"):
        bg.simulate(ReinitAlgebraic(), stop_time=1.0)


def test_when_condition_must_be_boolean():
    class Bad(Component):
        x = Variable(start=0.0, fixed=True)
        d = Discrete()

        def equations(self):
            yield der(self.x) == 1.0
            yield when(self.x, self.d == 1.0)

    with pytest.raises(EquationError, match="not a Boolean expression"):
        bg.compile(Bad())


def test_when_assigns_continuous_variable_is_an_error():
    class Bad(Component):
        x = Variable(start=0.0, fixed=True)

        def equations(self):
            yield der(self.x) == 1.0
            yield when(self.x > 1, self.x == 0.0)

    with pytest.raises(EquationError, match="must assign a discrete variable"):
        bg.compile(Bad())


def test_discrete_algebraic_loop_is_an_error():
    class Loop(Component):
        x = Variable(start=0.0, fixed=True)
        b1 = Boolean()
        b2 = Boolean()

        def equations(self):
            yield der(self.x) == if_else(self.b1, 1.0, 0.0)
            yield self.b1 == ~self.b2
            yield self.b2 == (self.b1 | (self.x > 1))

    with pytest.raises(EquationError, match="algebraic loop through the discrete"):
        bg.compile(Loop())


def test_event_iteration_that_does_not_converge_names_the_variable():
    class Flip(Component):
        x = Variable(start=0.0, fixed=True)
        b = Boolean()

        def equations(self):
            yield der(self.x) == 1.0
            yield self.b == ~pre(self.b)

    with pytest.raises(EventError, match="did not converge.*b keep changing"):
        bg.simulate(Flip(), stop_time=1.0)


def test_chattering_is_detected():
    class Chatter(Component):
        """Ideal Coulomb friction without a stuck mode: v chatters around 0."""

        v = Variable(start=1.0, fixed=True)

        def equations(self):
            yield der(self.v) == -if_else(self.v > 0, 1.0, -1.0)

    with pytest.raises(EventError, match="chattering.*0 < v"):
        bg.simulate(Chatter(), stop_time=2.0)


def test_unbalanced_if_equation_is_an_error():
    class Bad(Component):
        x = Variable(start=0.0, fixed=True)
        a = Variable()

        def equations(self):
            yield der(self.x) == self.a
            yield if_equation(self.x < 1, [self.a == 1.0], [])

    with pytest.raises(EquationError, match="same number of equations"):
        bg.compile(Bad())


def test_fmu_export_of_models_with_events():
    # models with events export (tests/fmi/test_hybrid_fmus.py), a reinit of a variable that
    # index reduction demoted included (tests/fmi/test_state_set_fmus.py)
    from bgmodelica.fmi.from_model import fmu_spec
    from library.examples.hybrid import BouncingBall, PendulumWall

    spec = fmu_spec(BouncingBall())
    assert spec.hybrid is not None and spec.hybrid.nz == 1
    spec = fmu_spec(PendulumWall(), static_states=True)
    assert spec.hybrid is not None and spec.hybrid.nz >= 1


class Terminal(Component):
    x = Variable(start=0.0, fixed=True)
    final = Discrete(start=0.0)

    def equations(self):
        yield der(self.x) == 1.0
        yield when(bg.terminal(), self.final == self.x)


def test_terminal_fires_once_at_the_stop_time():
    res = bg.simulate(Terminal(), stop_time=2.0, interval=0.5, **TIGHT)
    assert res.time[-1] == res.time[-2] == 2.0
    assert res["final"][-2] == 0.0 and res["final"][-1] == pytest.approx(2.0)
    assert res.meta["n_events"] == 1


def test_cli_input_csv(tmp_path, capsys):
    from bgmodelica.cli import main

    data = tmp_path / "u.csv"
    data.write_text("time,u\n0,0\n1,1\n1,-1\n2,-1\n")
    out = tmp_path / "out.csv"
    model = f"{__file__}:Inputs"
    assert main(["simulate", model, "--stop-time", "3", "--interval", "0.5", "--input",
                 str(data), "-o", str(out), "--rtol", "1e-10", "--atol", "1e-12"]) == 0
    rows = [line.split(",") for line in out.read_text().splitlines()]
    assert rows[0][:2] == ["time", "u"] or "x" in rows[0]
    col = rows[0].index("x")
    assert float(rows[-1][col]) == pytest.approx(-1.5, abs=1e-8)
    assert "events: 2" in capsys.readouterr().out
