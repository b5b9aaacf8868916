"""Initial equations (Modelica ``initial equation``), steady-state initialization and the
errors that name the over- or under-determined conditions."""

from __future__ import annotations

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica import Component, Input, Output, Parameter, Variable, der
from bgmodelica.errors import EquationError, InitializationError


class TankBase(Component):
    """A dh/dt = q_in - k h."""

    A = Parameter(2.0, unit="m2")
    k = Parameter(0.5, unit="m2/s")
    q_in = Input(unit="m3/s")
    h = Variable(unit="m", start=1.0)
    y = Output(unit="m")

    def equations(self):
        yield self.A * der(self.h) == self.q_in - self.k * self.h
        yield self.y == self.h


class Tank(TankBase):
    """Starts in equilibrium by an initial equation."""

    def initial_equations(self):
        yield der(self.h) == 0


class TankLevel(TankBase):
    """Starts at a given level (initial equations are inherited like equations, so this
    extends the base without them)."""

    h0 = Parameter(0.25, unit="m")

    def initial_equations(self):
        yield self.y == self.h0             # through an output (an algebraic variable)


class TwoConditions(Tank):
    def initial_equations(self):
        yield self.h == 3.0                  # conflicts with the inherited der(h) == 0


class Lag(Component):
    """x' = (u - x)/tau, y = 2 x: the algebraic y given at the start."""

    tau = Parameter(0.5, unit="s")
    x = Variable(unit="m", start=9.0)
    y = Variable(unit="m")

    def equations(self):
        yield der(self.x) == (1.0 - self.x) / self.tau
        yield self.y == 2 * self.x

    def initial_equations(self):
        yield self.y == 4.0


class Drift(Component):
    """x' = u: no steady state unless u = 0."""

    u = Input(unit="m/s")
    x = Variable(unit="m", start=0.0, fixed=True)

    def equations(self):
        yield der(self.x) == self.u


def test_initial_equation_der_zero_starts_in_equilibrium():
    res = bg.simulate(Tank(), stop_time=2.0, interval=0.5, params={"q_in": 1.0})
    assert np.allclose(res["h"], 2.0, rtol=0, atol=1e-12)      # q_in / k
    assert res.meta["init_notes"] == []


def test_initial_equation_on_an_algebraic_variable():
    res = bg.simulate(Lag(), stop_time=1.0, interval=0.5)
    assert abs(res["y"][0] - 4.0) < 1e-12 and abs(res["x"][0] - 2.0) < 1e-12
    res = bg.simulate(TankLevel(), stop_time=1.0, params={"q_in": 0.0, "h0": 0.5})
    assert abs(res["h"][0] - 0.5) < 1e-12


def test_conflicting_initial_equations_are_named():
    with pytest.raises(InitializationError) as err:
        bg.simulate(TwoConditions(name="tank"), stop_time=1.0, params={"q_in": 1.0})
    msg = str(err.value)
    assert "over-determined" in msg
    assert "initial equation h == 3" in msg and "initial equation der(h) == 0" in msg
    assert "for h" in msg


def test_initial_equation_conflicting_with_a_fixed_start_value():
    class Fixed(Tank):
        h = Variable(unit="m", start=1.0, fixed=True)

    with pytest.raises(InitializationError) as err:
        bg.simulate(Fixed(), stop_time=1.0, params={"q_in": 1.0})
    msg = str(err.value)
    assert "initial equation der(h) == 0" in msg and "h (fixed start value)" in msg


def test_underdetermined_initial_conditions_are_named():
    class Free(Component):
        tau = Parameter(1.0, unit="s")
        x = Variable(unit="m", start=0.3)
        v = Variable(unit="m/s", start=0.0, fixed=True)

        def equations(self):
            yield der(self.x) == self.v
            yield der(self.v) == -self.v / self.tau

    res = bg.simulate(Free(), stop_time=0.1)
    assert any("no fixed start value or initial equation for state(s) x" in n
               for n in res.meta["init_notes"])


def test_derivative_only_in_an_initial_equation_is_refused():
    class Bad(Component):
        tau = Parameter(1.0, unit="s")
        x = Variable(unit="m", start=1.0, fixed=True)
        y = Variable(unit="m")

        def equations(self):
            yield der(self.x) == -self.x / self.tau
            yield self.y == self.x

        def initial_equations(self):
            yield der(self.y) == 0

    with pytest.raises(EquationError, match="not part of the model"):
        bg.compile(Bad())


def test_steady_state_that_does_not_exist_structurally():
    with pytest.raises(InitializationError) as err:
        bg.steady_state(Drift(), {"u": 1.0})
    msg = str(err.value)
    assert "no steady state" in msg and "der(x) = 0" in msg
    assert "der(x)-u" in msg.replace(" ", "")       # the equation that defines der(x)
    assert "x is not determined" in msg


def test_steady_state_that_does_not_exist_numerically():
    class Runaway(Component):
        c = Parameter(1.0, unit="m/s")
        L = Parameter(1.0, unit="m")
        x = Variable(unit="m", start=0.5)

        def equations(self):
            yield der(self.x) == self.c * (1.0 + (self.x / self.L) ** 2)

    with pytest.raises(InitializationError) as err:
        bg.steady_state(Runaway())
    msg = str(err.value)
    assert "no steady state found" in msg and "der(x) = 0" in msg


def test_moving_state_excluded_from_the_steady_state():
    from library.examples.control import DCMotorIO

    with pytest.raises(InitializationError, match="exclude=\\['rotor.phi'\\]"):
        bg.steady_state(DCMotorIO(), {"V": 1.0})
    op = bg.steady_state(DCMotorIO(), {"V": 1.0}, exclude=["rotor.phi"])
    R, k, b = 1.0, 0.1, 0.001
    assert abs(op["w"] - k / (R * b + k**2)) < 1e-12         # w = k V / (R b + k^2)
    assert abs(op["rotor.phi"]) == 0.0


def test_simulate_from_the_steady_state():
    res = bg.simulate(Tank(), stop_time=1.0, interval=0.5, params={"q_in": 3.0},
                      init="steady-state")
    assert np.allclose(res["h"], 6.0, rtol=0, atol=1e-12)
    from bgmodelica.errors import ParameterError

    with pytest.raises(ParameterError, match="init must be"):
        bg.simulate(Tank(), stop_time=1.0, init="rest")


def test_initial_equation_units_are_checked():
    from bgmodelica.errors import UnitError

    class WrongUnits(TankBase):
        def initial_equations(self):
            yield self.h == self.k               # m against m2/s

    with pytest.raises(UnitError, match="initial equation h == k"):
        bg.compile(WrongUnits())
