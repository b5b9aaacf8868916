"""Coulomb friction with stiction and hard stops (hybrid: events, pre(), when/reinit) against
closed-form solutions."""

from __future__ import annotations

import numpy as np
import pytest
from library_testing import TIGHT

import bgmodelica as bg
from bgmodelica import Component, connect
from library.blocks import Ramp, Step
from library.rotational import BearingFriction, ConstantTorque, Inertia
from library.translational import (
    ConstantForce,
    Fixed,
    Force,
    Mass,
    MassWithFriction,
    MassWithStop,
    MassWithStopAndFriction,
    Spring,
    SupportFriction,
)


class Push(Component):
    """A constant force on a block resting on a surface (m = 2 kg, F_c = 3 N, F_s = 4 N)."""

    push = ConstantForce(f_constant=5.0)
    block = MassWithFriction(m=2.0, F_c=3.0, F_s=4.0, s=0.0, v=0.0)

    def equations(self):
        yield connect(self.push.flange, self.block.flange_a)


@pytest.mark.parametrize("force", [5.0, -6.5])
def test_push_above_breakaway_slides(force):
    """|F| > F_s: x(t) = sign(F) (|F| - F_c) t^2 / (2 m), friction -F_c against the motion."""
    result = bg.simulate(Push(), stop_time=2.0, interval=0.05,
                         params={"push.f_constant": force}, **TIGHT)
    t = result.time
    direction = np.sign(force)
    expected = direction * (abs(force) - 3.0) * t**2 / (2 * 2.0)
    assert np.max(np.abs(result["block.s"] - expected)) < 1e-10
    assert np.max(np.abs(result["block.v"] - 2 * expected / np.maximum(t, 1e-300))[t > 0]) \
        < 1e-10
    assert np.all(result["block.f"] == direction * 3.0)
    assert result["block.mode"][-1] == direction
    assert not np.any(result["block.locked"][t > 0.01])


@pytest.mark.parametrize("force", [3.5, -3.999, 0.0])
def test_push_below_breakaway_stays_stuck(force):
    """|F| <= F_s: the block never moves and friction balances the force (f = sa = F)."""
    result = bg.simulate(Push(), stop_time=2.0, interval=0.05,
                         params={"push.f_constant": force}, **TIGHT)
    assert np.all(result["block.s"] == 0.0)
    assert np.all(result["block.v"] == 0.0)
    assert np.all(result["block.locked"] == 1.0)
    assert np.all(result["block.mode"] == 0.0)
    assert np.max(np.abs(result["block.f"] - force)) < 1e-12
    assert result.meta["n_events"] == 0


def test_ramp_force_breakaway_time():
    """F = k t on a block at rest: stuck until k t_b = F_s (a state event on sa > f0_max),
    then m v' = k t - F_c: v = (k (t^2 - t_b^2)/2 - F_c (t - t_b)) / m."""

    class RampPush(Component):
        ramp = Ramp(height=20.0, duration=10.0)       # k = 2 N/s
        drive = Force()
        block = MassWithFriction(m=2.0, F_c=3.0, F_s=4.0, s=0.0, v=0.0)

        def equations(self):
            yield connect(self.ramp.y, self.drive.f)
            yield connect(self.drive.flange, self.block.flange_a)

    result = bg.simulate(RampPush(), stop_time=4.0, interval=0.01, **TIGHT)
    t, k, t_b = result.time, 2.0, 2.0
    tau = np.maximum(t - t_b, 0.0)
    v = (k * tau * (tau + 2 * t_b) / 2 - 3.0 * tau) / 2.0
    s = (k * (tau**3 / 6 + t_b * tau**2 / 2) - 3.0 * tau**2 / 2) / 2.0
    assert np.max(np.abs(result["block.v"] - v)) < 1e-9
    assert np.max(np.abs(result["block.s"] - s)) < 1e-9
    # (the relation sa > f0 of the hysteresis also crosses, at k t = F_c: an event without
    # a mode change)
    assert np.min(np.abs(np.array(result.meta["event_times"]) - t_b)) < 1e-9
    stuck = t < t_b - 1e-9
    assert np.all(result["block.locked"][stuck] == 1.0)
    assert np.max(np.abs(result["block.f"][stuck] - k * t[stuck])) < 1e-9


def test_spring_mass_with_coulomb_friction_decay():
    """Mass on a spring (c = 100 N/m, m = 1 kg, w = 10 rad/s), F_c = 1 N, F_s = 2.5 N,
    released at x = 0.1 m: each half period pi/w the amplitude drops by 2 F_c/c = 0.02 m
    about the shifted centre +-F_c/c (extremes 0.1, -0.08, 0.06, -0.04, 0.02); at 0.02 m
    the spring force 2 N < F_s and the mass stays stuck from t = 4 pi/w on."""

    class Decay(Component):
        fixed = Fixed(s0=-1.0)
        spring = Spring(c=100.0, s_rel0=1.0)
        friction = SupportFriction(F_c=1.0, F_s=2.5)
        body = Mass(m=1.0, s=0.1, v=0.0)

        def equations(self):
            yield connect(self.fixed.flange, self.spring.flange_a)
            yield connect(self.spring.flange_b, self.body.flange_a)
            yield connect(self.body.flange_b, self.friction.flange_a)

    result = bg.simulate(Decay(), stop_time=2.0, interval=1e-3, **TIGHT)
    t, w = result.time, 10.0
    extremes = [0.1, -0.08, 0.06, -0.04, 0.02]
    # half period of each row (a row at an event, found 1e-10 s early, starts the next one)
    half = np.minimum(np.floor(t * w / np.pi + 1e-6), 4).astype(int)
    start = np.array(extremes)[half]
    centre = np.sign(start) * 1.0 / 100.0          # friction F_c against the return motion
    phase = np.where(half < 4, w * t - half * np.pi, 0.0)
    expected = centre + (start - centre) * np.cos(phase)
    expected[half >= 4] = 0.02
    err = np.abs(result["body.s"] - expected)
    assert np.max(err) < 1e-8
    ends = [te for te in result.meta["event_times"] if te > 0.05]
    # velocity zeros at k pi / w end each half period; the last one sticks
    for k in range(1, 5):
        assert min(abs(np.array(ends) - k * np.pi / w)) < 1e-9
    after = t > 4 * np.pi / w + 1e-6
    assert np.all(result["friction.locked"][after] == 1.0)
    assert np.max(np.abs(result["body.v"][after])) < 1e-9
    assert np.max(np.abs(result["friction.f"][after] - (-2.0))) < 1e-6


def test_friction_element_equals_mass_with_friction():
    class Separate(Component):
        push = ConstantForce(f_constant=5.0)
        body = Mass(m=2.0, s=0.0, v=0.0)
        friction = SupportFriction(F_c=3.0, F_s=4.0, F_prop=0.5)

        def equations(self):
            yield connect(self.push.flange, self.body.flange_a)
            yield connect(self.body.flange_b, self.friction.flange_a)

    a = bg.simulate(Separate(), stop_time=2.0, interval=0.05, **TIGHT)
    b = bg.simulate(Push(), stop_time=2.0, interval=0.05, params={"block.F_prop": 0.5},
                    **TIGHT)
    # m v' = F - F_c - F_prop v: v = (F - F_c)/F_prop (1 - exp(-F_prop t/m))
    v = (5.0 - 3.0) / 0.5 * (1 - np.exp(-0.5 * a.time / 2.0))
    assert np.max(np.abs(a["body.v"] - v)) < 1e-9
    assert np.max(np.abs(np.interp(a.time, b.time, b["block.v"]) - v)) < 1e-9


class Stops(Component):
    """Mass (m = 1 kg, L = 0.2 m) between stops smin = 0, smax = 1 (centre in [0.1, 0.9]),
    from rest at s = 0.5, pushed by +2 N, then by -2 N from t = 2 s."""

    force = Step(height=-4.0, offset=2.0, start_time=2.0)
    drive = Force()
    body = MassWithStop(m=1.0, L=0.2, smin=0.0, smax=1.0, s=0.5, v=0.0)

    def equations(self):
        yield connect(self.force.y, self.drive.f)
        yield connect(self.drive.flange, self.body.flange_a)


def test_mass_against_end_stops():
    """s = 0.5 + t^2 until the stop at 0.9 (t1 = sqrt(0.4)), held there while pushed, then
    s = 0.9 - (t - 2)^2 until the stop at 0.1 (t2 = 2 + sqrt(0.8)), held there."""
    result = bg.simulate(Stops(), stop_time=4.0, interval=0.01, **TIGHT)
    t, s = result.time, result["body.s"]
    t1, t2 = np.sqrt(0.4), 2 + np.sqrt(0.8)
    expected = np.where(t < t1, 0.5 + t**2,
                        np.where(t < 2.0, 0.9, np.maximum(0.9 - (t - 2)**2, 0.1)))
    assert np.max(np.abs(s - expected)) < 1e-9
    assert np.all(s >= 0.1 - 1e-12) and np.all(s <= 0.9 + 1e-12)
    assert np.all(result["body.flange_a.s"] >= -1e-12)
    assert np.all(result["body.flange_b.s"] <= 1.0 + 1e-12)
    at_max = (t > t1 + 1e-9) & (t < 2.0)
    at_min = t > t2 + 1e-9
    assert np.all(result["body.v"][at_max | at_min] == 0.0)
    assert np.all(result["body.stopped"][at_max] == 1)
    assert np.all(result["body.stopped"][at_min] == -1)
    assert np.all(result["body.locked"][at_max | at_min] == 1)
    times = np.array(result.meta["event_times"])
    for te in (t1, 2.0, t2):
        assert np.min(np.abs(times - te)) < 1e-9


def test_impact_with_friction_stays_within_stops():
    """Released at 1 m/s towards the stop with F_c = F_s = 0.5 N (decelerating at 0.5 m/s2):
    reaches smax - L/2 = 0.9 after t1 = 2 - sqrt(4 - 1.6) with speed 1 - 0.5 t1, stops."""

    class Slide(Component):
        body = MassWithStopAndFriction(m=1.0, L=0.2, smin=0.0, smax=1.0, F_c=0.5, F_s=0.5,
                                       s=0.5, v=1.0)

    result = bg.simulate(Slide(), stop_time=3.0, interval=0.01, **TIGHT)
    t = result.time
    t1 = 2 - np.sqrt(4 - 1.6)
    expected = np.where(t < t1, 0.5 + t - 0.25 * t**2, 0.9)
    assert np.max(np.abs(result["body.s"] - expected)) < 1e-9
    assert np.max(result["body.s"]) <= 0.9 + 1e-12
    assert np.all(result["body.v"][t > t1 + 1e-9] == 0.0)


def test_flywheel_spin_down_under_coulomb_torque():
    """J = 0.5 kg.m2 at w0 = 10 rad/s, tau_c = 2 N.m: w = w0 - tau_c t / J, stops at
    t = J w0 / tau_c = 2.5 s (phi = 12.5 rad) and stays stuck (tau_s = 2.5 N.m)."""

    class SpinDown(Component):
        flywheel = Inertia(J=0.5, phi=0.0, w=10.0)
        bearing = BearingFriction(tau_c=2.0, tau_s=2.5)

        def equations(self):
            yield connect(self.flywheel.flange_b, self.bearing.flange_a)

    result = bg.simulate(SpinDown(), stop_time=4.0, interval=0.01, **TIGHT)
    t = result.time
    t_stop = 0.5 * 10.0 / 2.0
    tt = np.minimum(t, t_stop)
    assert np.max(np.abs(result["flywheel.w"] - (10.0 - 4.0 * tt))) < 1e-9
    assert np.max(np.abs(result["flywheel.phi"] - (10.0 * tt - 2.0 * tt**2))) < 1e-9
    stop_events = [te for te in result.meta["event_times"] if te > 1.0]
    assert abs(stop_events[0] - t_stop) < 1e-9
    after = t > t_stop + 1e-9
    assert np.all(result["bearing.locked"][after] == 1.0)
    assert np.all(result["bearing.mode"][after] == 0.0)
    assert np.max(np.abs(result["bearing.tau"][after])) < 1e-9


def test_bearing_breakaway_torque():
    """A constant torque from rest: below tau_s nothing turns; above it w = (tau - tau_c) t/J."""

    class Drive(Component):
        motor = ConstantTorque(tau_constant=3.0)
        flywheel = Inertia(J=0.5, phi=0.0, w=0.0)
        bearing = BearingFriction(tau_c=2.0, tau_s=2.5)

        def equations(self):
            yield connect(self.motor.flange, self.flywheel.flange_a)
            yield connect(self.flywheel.flange_b, self.bearing.flange_a)

    moving = bg.simulate(Drive(), stop_time=1.0, interval=0.01, **TIGHT)
    assert np.max(np.abs(moving["flywheel.w"] - (3.0 - 2.0) * moving.time / 0.5)) < 1e-10
    held = bg.simulate(Drive(), stop_time=1.0, interval=0.01,
                       params={"motor.tau_constant": -2.4}, **TIGHT)
    assert np.all(held["flywheel.w"] == 0.0)
    assert np.max(np.abs(held["bearing.tau"] - (-2.4))) < 1e-12
