"""Planar multibody components: conventions and simple mechanisms with known solutions."""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

from bgmodelica import Component, compile, connect, simulate
from library.planar import (
    AbsoluteAngleSensor,
    AbsolutePositionSensor,
    Body,
    Fixed,
    FixedTranslation,
    RelativeAngleSensor,
    RelativeSpeedSensor,
    Revolute,
    World,
)
from library.rotational import ConstantTorque

TIGHT = {"rtol": 1e-12, "atol": 1e-14, "dynamic": False}


class Pendulum(Component):
    """World -> revolute -> body whose centre of mass is offset (rcx, rcy) from the joint."""

    def __init__(self, rcx=0.5, rcy=0.0, rod=False, **kw):
        super().__init__(**kw)
        self.world = World(g=9.81)
        self.joint = Revolute(q=0.4, w=0.0)
        if rod:            # the offset as a rigid rod, the body's frame at its centre of mass
            self.rod = FixedTranslation(rx=rcx, ry=rcy)
            self.body = Body(m=2.0, I=0.05, g=self.world.g)
        else:
            self.body = Body(m=2.0, I=0.05, rcx=rcx, rcy=rcy, g=self.world.g)
        self.angle = RelativeAngleSensor()
        self.speed = RelativeSpeedSensor()
        self.absolute = AbsoluteAngleSensor()
        self.position = AbsolutePositionSensor()

    def equations(self):
        yield connect(self.world.frame_b, self.joint.frame_a)
        if hasattr(self, "rod"):
            yield connect(self.joint.frame_b, self.rod.frame_a)
            yield connect(self.rod.frame_b, self.body.frame_a)
            yield connect(self.rod.frame_b, self.position.frame_a)
        else:
            yield connect(self.joint.frame_b, self.body.frame_a)
            yield connect(self.joint.frame_b, self.position.frame_a)
        for sensor in (self.angle, self.speed):
            yield connect(self.world.frame_b, sensor.frame_a)
            yield connect(self.joint.frame_b, sensor.frame_b)
        yield connect(self.joint.frame_b, self.absolute.frame_a)


def _pendulum_reference(rcx, rcy, t):
    m, inertia, g = 2.0, 0.05, 9.81
    r2 = rcx**2 + rcy**2
    off = np.arctan2(rcy, rcx)

    def f(_t, y):       # (I + m r^2) q'' = -m g r cos(q + off)
        return [y[1], -m * g * np.sqrt(r2) * np.cos(y[0] + off) / (inertia + m * r2)]

    sol = solve_ivp(f, (t[0], t[-1]), [0.4, 0.0], method="DOP853", t_eval=t, rtol=1e-13,
                    atol=1e-13)
    return sol.y


def test_pendulum_index_reduction_and_states():
    """A body hinged to the world is an index-3 DAE; the joint angle/speed become states."""
    s = compile(Pendulum()).summary()
    assert s["balanced"] and s["structural_index"] == 3
    assert s["states"] == ["joint.q", "joint.w"]
    assert s["algebraic_variables"] == []


def test_pendulum_matches_ode_and_sensors():
    res = simulate(Pendulum(rcx=0.5, rcy=0.2), stop_time=3.0, interval=0.01, **TIGHT)
    q, w = _pendulum_reference(0.5, 0.2, res.time)
    assert np.max(np.abs(res["joint.q"] - q)) < 1e-9
    assert np.max(np.abs(res["joint.w"] - w)) < 1e-8
    np.testing.assert_allclose(res["angle.phi_rel"], res["joint.q"], atol=1e-14)
    np.testing.assert_allclose(res["speed.w_rel"], res["joint.w"], atol=1e-12)
    np.testing.assert_allclose(res["absolute.phi"], res["joint.q"], atol=1e-14)
    np.testing.assert_allclose(res["absolute.w"], res["joint.w"], atol=1e-12)
    # the body's centre of mass sits at R(q) (rcx, rcy); the joint frame at the origin
    c, s = np.cos(res["joint.q"]), np.sin(res["joint.q"])
    np.testing.assert_allclose(res["body.x"], 0.5 * c - 0.2 * s, atol=1e-12)
    np.testing.assert_allclose(res["body.y"], 0.5 * s + 0.2 * c, atol=1e-12)
    np.testing.assert_allclose(res["position.x"], 0.0, atol=1e-14)
    # reaction at the hinge: world force on the body balances gravity + centripetal force
    fy = -res["world.frame_b.fy"]            # force the world pushes into the joint
    np.testing.assert_allclose(fy, 2.0 * (res["body.ay"] + 9.81), atol=1e-9)


def test_body_offset_equals_rod_plus_body():
    """Body(rcx, rcy) behaves as FixedTranslation(rx, ry) + Body with the COM at its frame."""
    a = simulate(Pendulum(rcx=0.3, rcy=-0.1), stop_time=2.0, interval=0.02, **TIGHT)
    b = simulate(Pendulum(rcx=0.3, rcy=-0.1, rod=True), stop_time=2.0, interval=0.02, **TIGHT)
    assert np.max(np.abs(a["joint.q"] - b["joint.q"])) < 1e-10
    np.testing.assert_allclose(b["position.x"], b["body.x"], atol=1e-14)


class Spinner(Component):
    """A body rotating about its centre of mass, driven by a constant torque, no gravity."""

    fixed = Fixed(x0=1.0, y0=-2.0, phi0=0.3)
    joint = Revolute(q=0.0, w=0.5)
    body = Body(m=3.0, I=0.2, g=0.0)
    drive = ConstantTorque(tau_constant=0.1)

    def equations(self):
        yield connect(self.fixed.frame_b, self.joint.frame_a)
        yield connect(self.joint.frame_b, self.body.frame_a)
        yield connect(self.drive.flange, self.joint.flange)


def test_revolute_drive_convention():
    """A positive flange torque accelerates frame_b positively: w = w0 + tau/I t; the
    reaction -tau acts on frame_a's side (the torque into the Fixed component)."""
    res = simulate(Spinner(), stop_time=2.0, interval=0.1, **TIGHT)
    t = res.time
    np.testing.assert_allclose(res["joint.w"], 0.5 + 0.5 * t, atol=1e-9)
    np.testing.assert_allclose(res["joint.q"], 0.5 * t + 0.25 * t**2, atol=1e-9)
    np.testing.assert_allclose(res["body.phi"], 0.3 + res["joint.q"], atol=1e-12)
    np.testing.assert_allclose(res["body.x"], 1.0, atol=1e-12)
    np.testing.assert_allclose(res["fixed.frame_b.tau"], -0.1, atol=1e-12)
    np.testing.assert_allclose(res["joint.tau"], 0.1, atol=1e-12)
