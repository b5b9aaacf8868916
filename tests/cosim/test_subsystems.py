"""The causal split of the robot (library.robots.subsystems) and the generic wrapper
(bgmodelica.cosim.wrap): same physics as the monolithic model, clear declaration errors."""

from __future__ import annotations

import numpy as np
import pytest

from bgmodelica import Component, compile, simulate
from bgmodelica.cosim.wrap import (
    FlowInput,
    FlowOutput,
    PotentialInput,
    PotentialOutput,
    expose,
)
from bgmodelica.errors import DeclarationError
from library.robots.params import MOTOR
from library.robots.robot import RobotPID
from library.robots.subsystems import (
    RobotFromSubsystems,
    arm_subsystem,
    controller_subsystem,
    drive_damping,
    motor_subsystem,
    reflected_inertia,
    robot_parameters,
)
from library.rotational import Damper, Fixed, Inertia

Q = ["arm.q1", "arm.q2", "arm.w1", "arm.w2", "motor1.i", "motor2.i"]


@pytest.fixture(scope="module")
def monolithic():
    return simulate(compile(RobotPID()), stop_time=1.5, interval=0.01, rtol=1e-10,
                    atol=1e-12, dynamic=False)


@pytest.mark.parametrize("coupling", ["lumped", "plain"])
def test_split_is_exact(monolithic, coupling):
    """The four subsystems connected back together are RobotPID (same states, same
    trajectories to the integrator tolerance): the split changes no physics."""
    res = simulate(compile(RobotFromSubsystems(coupling)), stop_time=1.5, interval=0.01,
                   rtol=1e-10, atol=1e-12, dynamic=False)
    for name in Q:
        scale = max(1.0, float(np.max(np.abs(monolithic[name]))))
        assert np.max(np.abs(res[name] - monolithic[name])) < 1e-7 * scale, name


def test_subsystem_interfaces():
    arm, motor, ctrl = (compile(f()) for f in (arm_subsystem, motor_subsystem,
                                                 controller_subsystem))
    assert [u.name for u in arm.dae.inputs] == ["tau1", "tau2"]
    assert sorted(arm.dae.state_names) == ["joint1.q", "joint1.w", "joint2.q", "joint2.w"]
    assert [u.name for u in motor.dae.inputs] == ["u", "w"]
    assert "inductor.i" in motor.dae.state_names
    assert sorted(u.name for u in ctrl.dae.inputs) == ["q1", "q2", "w1", "w2"]
    plain = compile(controller_subsystem("plain"))
    assert sorted(u.name for u in plain.dae.inputs) == ["q1", "q2"]
    with pytest.raises(ValueError, match="coupling"):
        controller_subsystem("stiff")


def test_motor_torque_law():
    """tau_shaft = k2 (k1 i - b k2 w); tau = tau_shaft + k2^2 (k1^2/R + b) w; at steady
    state i = (u - k1 k2 w)/R."""
    c = compile(motor_subsystem())
    u, w = 12.0, 1.5
    res = simulate(c, stop_time=0.05, interval=0.01, params={"u": u, "w": w})
    k1, k2, R, b = (MOTOR[n] for n in ("k1", "k2", "R", "b"))
    i = (u - k1 * k2 * w) / R
    assert res.final("i") == pytest.approx(i, rel=1e-6)
    assert res.final("tau_shaft") == pytest.approx(k2 * (k1 * i - b * k2 * w), rel=1e-6)
    assert res.final("tau") == pytest.approx(k1 * k2 * u / R, rel=1e-6)
    assert res.final("w_m") == pytest.approx(k2 * w)
    assert drive_damping() == pytest.approx(k2 ** 2 * (k1 ** 2 / R + b))


def test_arm_with_drive_inertia_and_damping():
    """A constant torque on joint 1 with gravity off: (M11 + Jd1) a1 = tau - d1 w1 at rest."""
    c = compile(arm_subsystem())
    res = simulate(c, stop_time=1e-3, interval=1e-4, params={"tau1": 10.0, "g": 0.0},
                   dynamic=False)
    from library.robots.lagrange import ARM_DEFAULTS as A

    m11 = (A["I1"] + A["m1"] * A["lc1"] ** 2 + A["I2"]
           + A["m2"] * (A["l1"] ** 2 + A["lc2"] ** 2 + 2 * A["l1"] * A["lc2"]))
    m12 = A["I2"] + A["m2"] * (A["lc2"] ** 2 + A["l1"] * A["lc2"])
    m22 = A["I2"] + A["m2"] * A["lc2"] ** 2
    jd = reflected_inertia()
    M = np.array([[m11 + jd, m12], [m12, m22 + jd]])
    a = np.linalg.solve(M, [10.0, 0.0])
    assert res["joint1.a"][0] == pytest.approx(a[0], rel=1e-9)
    assert res["joint2.a"][0] == pytest.approx(a[1], rel=1e-9)
    # the drive damping: steady speed of joint 1 under a torque, joint 2 held by its damper
    slow = simulate(c, stop_time=0.2, interval=0.1, params={"tau1": 10.0, "g": 0.0},
                    dynamic=False)
    assert slow.final("w1") == pytest.approx(10.0 / drive_damping(), rel=1e-2)


def test_robot_parameters():
    p = robot_parameters({"m2": 2.5, "motor2.Jm": 1e-4, "Kp1": 300.0})
    assert p["arm"]["m2"] == 2.5 and p["controller"]["Kp1"] == 300.0
    assert p["arm"]["Jd2"] == pytest.approx(MOTOR["k2"] ** 2 * 1e-4)
    assert p["arm"]["Jd1"] == pytest.approx(reflected_inertia())
    assert "Jm" not in p["motor1"] and p["motor1"]["R"] == MOTOR["R"]
    assert robot_parameters(coupling="plain")["arm"]["d1"] == 0.0
    with pytest.raises(KeyError, match="nope"):
        robot_parameters({"nope": 1.0})


class _Shaft(Component):
    """An inertia with a damper to the housing: the generic wrapper's test object."""

    def __init__(self, **kw):
        super().__init__(**kw)
        self.load = Inertia(J=2.0)
        self.damper = Damper(d=0.5)
        self.housing = Fixed()

    def equations(self):
        from bgmodelica import connect

        yield connect(self.damper.flange_a, self.housing.flange)
        yield connect(self.damper.flange_b, self.load.flange_a)


def test_expose_flow_in_motion_out():
    m = expose(_Shaft(), inputs={"tau": FlowInput("load.flange_b")},
               outputs={"phi": PotentialOutput("load.flange_b"),
                        "w": PotentialOutput("load.flange_b", order=1),
                        "w_inner": "load.w"})
    c = compile(m)
    assert [u.name for u in c.dae.inputs] == ["tau"]
    res = simulate(c, stop_time=20.0, interval=0.5, params={"tau": 1.0})
    # J w' = tau - d w: w = (tau/d) (1 - exp(-d t / J))
    np.testing.assert_allclose(res["w"], 2.0 * (1 - np.exp(-0.25 * res.time)), atol=1e-5)
    np.testing.assert_allclose(res["w"], res["w_inner"], atol=1e-12)
    assert res.final("phi") > 0


def test_expose_motion_in_flow_out():
    """A damper driven by a speed returns d*w (inertia-free side of a cut)."""
    class _Brake(Component):
        def __init__(self, **kw):
            super().__init__(**kw)
            self.damper = Damper(d=0.5)
            self.housing = Fixed()

        def equations(self):
            from bgmodelica import connect

            yield connect(self.damper.flange_a, self.housing.flange)

    m = expose(_Brake(), inputs={"w": PotentialInput("damper.flange_b", order=1)},
               outputs={"tau": FlowOutput("damper.flange_b")})
    res = simulate(compile(m), stop_time=1.0, interval=0.5, params={"w": 3.0})
    assert res.final("tau") == pytest.approx(-1.5)   # the brake pulls back on the driver


def test_expose_errors():
    with pytest.raises(DeclarationError, match="names nothing"):
        expose(_Shaft(), inputs={"tau": FlowInput("load.nope")})
    with pytest.raises(DeclarationError, match="needs a PotentialInput"):
        expose(_Shaft(), outputs={"tau": FlowOutput("load.flange_b")})
    with pytest.raises(DeclarationError, match="driven by two inputs"):
        expose(_Shaft(), inputs={"a": FlowInput("load.flange_b"),
                                 "b": PotentialInput("load.flange_b")})
    with pytest.raises(DeclarationError, match="not a connector"):
        expose(_Shaft(), inputs={"a": FlowInput("load")})
    with pytest.raises(DeclarationError, match="already has"):
        expose(_Shaft(), outputs={"load": "load.w"})
    with pytest.raises(DeclarationError, match="not an Input"):
        expose(_Shaft(), inputs={"x": "load.w"})
