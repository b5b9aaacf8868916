"""The geared DC motor in component form (paper Eq. 5-7) against its ODE, and against the
bond-graph motor of library.bondgraph.paper when that module is available."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from bgmodelica import Component, compile, connect, simulate
from library.blocks import Sine
from library.robots.motor import DCMotor
from library.robots.params import MOTOR
from library.rotational import Inertia

J_LOAD = 0.4
TIGHT = {"rtol": 1e-12, "atol": 1e-14, "dynamic": False}


class MotorOnLoad(Component):
    """Sine voltage (6 + 12 sin(2 pi t) V) -> DCMotor -> joint-side inertia J_LOAD."""

    source = Sine(amplitude=12.0, f=1.0, offset=6.0)
    motor = DCMotor()
    load = Inertia(J=J_LOAD, phi=0.0, w=0.0)

    def equations(self):
        yield connect(self.source.y, self.motor.u)
        yield connect(self.motor.flange, self.load.flange_a)


def motor_ode(p):
    """L i' = u - R i - k1 k2 w,  (J + Jm k2^2) w' = k1 k2 i - b k2^2 w  (w: joint speed)."""
    R, L, k1, Jm, b, k2 = (p[n] for n in ("R", "L", "k1", "Jm", "b", "k2"))

    def f(t, y):
        i, w = y
        u = 6.0 + 12.0 * np.sin(2 * np.pi * t)
        return [(u - R * i - k1 * k2 * w) / L,
                (k1 * k2 * i - b * k2**2 * w) / (J_LOAD + Jm * k2**2)]

    return f


def test_motor_structure():
    """The gear ties the rotor to the joint: the load (joint side) keeps the states."""
    s = compile(MotorOnLoad()).summary()
    assert s["balanced"]
    assert sorted(s["states"]) == ["load.phi", "load.w", "motor.inductor.i"]


@pytest.mark.parametrize("params", [{}, {"motor.R": 2.0, "motor.k2": 80.0, "motor.b": 1e-3}])
def test_motor_matches_ode(params):
    res = simulate(MotorOnLoad(), stop_time=0.5, interval=0.001, params=params, **TIGHT)
    p = dict(MOTOR, **{k.split(".")[-1]: v for k, v in params.items()})
    ref = solve_ivp(motor_ode(p), (0, 0.5), [0.0, 0.0], method="Radau", t_eval=res.time,
                    rtol=1e-12, atol=1e-14)
    assert ref.success
    assert np.max(np.abs(res["motor.i"] - ref.y[0])) < 1e-8
    assert np.max(np.abs(res["load.w"] - ref.y[1])) < 1e-8
    # conventions: rotor speed = k2 x joint speed; joint torque = k2 x motor-side torque
    np.testing.assert_allclose(res["motor.w_m"], p["k2"] * res["load.w"], atol=1e-10)
    np.testing.assert_allclose(res["motor.gear.flange_b.tau"],
                               -p["k2"] * res["motor.gear.flange_a.tau"], atol=1e-9)
