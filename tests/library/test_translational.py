"""Translational components against closed-form solutions (Modelica sign conventions)."""

from __future__ import annotations

import numpy as np
from library_testing import TIGHT, rel_error

import bgmodelica as bg
from bgmodelica import Component, Input, connect
from library.translational import (
    AccSensor,
    ConstantForce,
    Damper,
    Fixed,
    Force,
    ForceSensor,
    Mass,
    PositionSensor,
    Rod,
    SpeedSensor,
    Spring,
    SpringDamper,
)


def damped_oscillator(t, x0, v0, m, c, d):
    """Free response x(t) of m x'' + d x' + c x = 0 (underdamped)."""
    wn = np.sqrt(c / m)
    zeta = d / (2 * np.sqrt(c * m))
    wd = wn * np.sqrt(1 - zeta**2)
    decay = np.exp(-zeta * wn * t)
    x = decay * (x0 * np.cos(wd * t) + (v0 + zeta * wn * x0) / wd * np.sin(wd * t))
    v = decay * (v0 * np.cos(wd * t)
                 - (zeta * wn * v0 + wn**2 * x0) / wd * np.sin(wd * t))
    return x, v


class Oscillator(Component):
    """Housing at s0 = 0.3 m -> spring (unstretched 0.5 m) and damper in parallel -> mass of
    length 0.2 m. Equilibrium centre: 0.3 + 0.5 + 0.1 = 0.9 m; released at s = 1.0 m with
    v = -0.2 m/s."""

    fixed = Fixed(s0=0.3)
    spring = Spring(c=20.0, s_rel0=0.5)
    damper = Damper(d=1.0)
    body = Mass(m=0.5, L=0.2, s=1.0, v=-0.2)
    position = PositionSensor()
    speed = SpeedSensor()
    acc = AccSensor()

    def equations(self):
        yield connect(self.fixed.flange, self.spring.flange_a)
        yield connect(self.fixed.flange, self.damper.flange_a)
        yield connect(self.spring.flange_b, self.body.flange_a)
        yield connect(self.damper.flange_b, self.body.flange_a)
        yield connect(self.position.flange, self.body.flange_b)
        yield connect(self.speed.flange, self.body.flange_b)
        yield connect(self.acc.flange, self.body.flange_b)


def test_mass_spring_damper_free_response():
    result = bg.simulate(Oscillator(), stop_time=3.0, interval=1e-3, **TIGHT)
    t = result.time
    x, v = damped_oscillator(t, 0.1, -0.2, m=0.5, c=20.0, d=1.0)
    assert rel_error(result["body.s"], 0.9 + x) < 1e-8
    assert rel_error(result["body.v"], v) < 1e-7
    # sensors at flange_b = s + L/2
    assert rel_error(result["position.s"], 1.0 + x) < 1e-8
    assert rel_error(result["speed.v"], v) < 1e-7
    # m a = -c x - d v
    assert rel_error(result["acc.a"], (-20.0 * x - 1.0 * v) / 0.5) < 1e-7
    # MSL signs: s_rel = body.flange_a.s - s0 = 0.5 + x, f = c (s_rel - s_rel0) (tension > 0)
    assert rel_error(result["spring.s_rel"], 0.5 + x) < 1e-8
    assert rel_error(result["spring.f"], 20.0 * x) < 1e-7
    assert rel_error(result["damper.f"], 1.0 * v) < 1e-7
    assert rel_error(result["damper.flange_a.f"], -1.0 * v) < 1e-7


def test_spring_damper_equals_parallel_pair():
    class Combined(Component):
        fixed = Fixed(s0=0.3)
        sd = SpringDamper(c=20.0, d=1.0, s_rel0=0.5)
        body = Mass(m=0.5, L=0.2, s=1.0, v=-0.2)

        def equations(self):
            yield connect(self.fixed.flange, self.sd.flange_a)
            yield connect(self.sd.flange_b, self.body.flange_a)

    result = bg.simulate(Combined(), stop_time=3.0, interval=1e-3, **TIGHT)
    x, v = damped_oscillator(result.time, 0.1, -0.2, m=0.5, c=20.0, d=1.0)
    assert rel_error(result["body.s"], 0.9 + x) < 1e-8
    assert rel_error(result["sd.f"], 20.0 * x + 1.0 * v) < 1e-7
    assert rel_error(result["sd.v_rel"], v) < 1e-7


def test_constant_force_on_mass_and_force_sensor():
    """push (F = 3 N) -> sensor -> mass (2 kg) -> rod (0.5 m) -> mass (1 kg):
    a = F/3, the sensor reads F, the rod carries F/3 * 1 kg."""

    class Push(Component):
        push = ConstantForce(f_constant=3.0)
        sensor = ForceSensor()
        body1 = Mass(m=2.0, L=0.1, s=0.25, v=0.5)
        rod = Rod(L=0.5)
        rod_sensor = ForceSensor()
        body2 = Mass(m=1.0, L=0.3)

        def equations(self):
            yield connect(self.push.flange, self.sensor.flange_a)
            yield connect(self.sensor.flange_b, self.body1.flange_a)
            yield connect(self.body1.flange_b, self.rod.flange_a)
            yield connect(self.rod.flange_b, self.rod_sensor.flange_a)
            yield connect(self.rod_sensor.flange_b, self.body2.flange_a)

    result = bg.simulate(Push(), stop_time=2.0, interval=1e-2, **TIGHT)
    t = result.time
    s1 = 0.25 + 0.5 * t + 3.0 / 3.0 * t**2 / 2
    assert rel_error(result["body1.s"], s1) < 1e-9
    assert rel_error(result["body2.s"], s1 + 0.05 + 0.5 + 0.15) < 1e-9
    assert rel_error(result["body2.v"], 0.5 + t) < 1e-9
    assert rel_error(result["sensor.f"], 3.0 * np.ones_like(t)) < 1e-9
    assert rel_error(result["rod_sensor.f"], 1.0 * np.ones_like(t)) < 1e-9
    assert rel_error(result["push.flange.s"], s1 - 0.05) < 1e-9


def test_force_signal_sign_and_fixed_offset():
    """A positive force signal against a spring to an offset housing: static deflection
    F/c, approached through the damped response from rest at the unstretched position."""

    class Pull(Component):
        f = Input(unit="N", description="Pulling force (model input)")
        drive = Force()
        fixed = Fixed(s0=-1.5)
        sensor = ForceSensor()
        spring = SpringDamper(c=50.0, d=2.0, s_rel0=1.0)
        body = Mass(m=1.0, L=0.0, s=-0.5, v=0.0)

        def equations(self):
            yield connect(self.f, self.drive.f)
            yield connect(self.fixed.flange, self.sensor.flange_a)
            yield connect(self.sensor.flange_b, self.spring.flange_a)
            yield connect(self.spring.flange_b, self.body.flange_a)
            yield connect(self.drive.flange, self.body.flange_b)

    result = bg.simulate(Pull(), stop_time=2.0, interval=1e-3, params={"f": 4.0}, **TIGHT)
    t = result.time
    x, _ = damped_oscillator(t, -4.0 / 50.0, 0.0, m=1.0, c=50.0, d=2.0)
    expected = -0.5 + 4.0 / 50.0 + x
    assert rel_error(result["body.s"], expected) < 1e-8
    assert rel_error(result["fixed.flange.s"], -1.5 * np.ones_like(t)) < 1e-12
    # the housing pulls the spring back: the sensor (housing -> spring) reads -spring.f
    assert rel_error(result["sensor.f"], -result["spring.f"]) < 1e-12
    assert abs(result["spring.f"][-1] - 4.0) < 0.1
