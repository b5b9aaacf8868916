"""Component/multibody forms against the paper's bond-graph forms (library.bondgraph.paper):
the geared DC motor, the free two-link arm, and the PID robot with either arm."""

from __future__ import annotations

import numpy as np
import pytest

from bgmodelica import Component, compile, connect, simulate
from library.blocks import Constant
from library.robots.arm import TwoLinkArm, bond_graph_arm
from library.robots.motor import DCMotor
from library.robots.params import MOTOR
from library.rotational import ConstantTorque

paper = pytest.importorskip("library.bondgraph.paper")

TIGHT = {"rtol": 1e-12, "atol": 1e-14, "dynamic": False}
U, TAU_LOAD = 12.0, 2.0


class MotorAgainstLoad(Component):
    """Constant voltage U -> component DCMotor -> constant load torque opposing the joint."""

    source = Constant(k=U)
    motor = DCMotor()
    load = ConstantTorque(tau_constant=-TAU_LOAD)

    def equations(self):
        yield connect(self.source.y, self.motor.u)
        yield connect(self.motor.flange, self.load.flange)


def test_motor_matches_bond_graph_motor():
    """Currents and speeds of the component motor = bond-graph motor (Fig. 6-7) to 1e-8."""
    comp = simulate(MotorAgainstLoad(), stop_time=0.3, interval=0.001, **TIGHT)
    bg_params = {f"motor.{k}": v for k, v in MOTOR.items()}
    bg_params.update({"motor.U": U, "tau_load": TAU_LOAD})
    bg = simulate(paper.DCMotorDrive(), stop_time=0.3, interval=0.001, params=bg_params,
                  **TIGHT)
    assert np.max(np.abs(comp["motor.i"] - bg["motor.i.f"])) < 1e-8
    assert np.max(np.abs(comp["motor.w_m"] - bg["motor.wm.f"])) < 1e-8
    assert np.max(np.abs(comp["motor.w_m"] / MOTOR["k2"] - bg["wa.f"])) < 1e-8
    assert np.max(np.abs(comp["motor.i"])) > 1.0          # a non-trivial transient


@pytest.mark.parametrize("start", [(0.3, -0.5, 0.0, 0.0), (-1.0, 1.5, -2.0, 3.0)])
def test_free_arm_matches_bond_graph_arm(start):
    """5 s free swings of the multibody arm and of the bond-graph arm (Fig. 9/11); the
    chaotic double pendulum needs rtol 1e-13 for the two routes to agree to 1e-8."""
    q1, q2, w1, w2 = start
    out = {}
    for key, make in (("mb", TwoLinkArm), ("bg", bond_graph_arm)):
        res = simulate(compile(make(q1=q1, q2=q2, w1=w1, w2=w2)), stop_time=5.0,
                       interval=0.01, rtol=1e-13, atol=1e-15, dynamic=False, solver="idas")
        out[key] = np.column_stack([res[n] for n in ("q1", "q2", "w1", "w2")])
    dev = np.max(np.abs(out["mb"] - out["bg"]), axis=0)
    assert np.all(dev[:2] < 1e-8), dev
    assert np.all(dev[2:] < 1e-8 * np.max(np.abs(out["mb"][:, 2:]), axis=0)), dev


def test_pid_robot_with_bond_graph_arm():
    """RobotPID(arm="bondgraph") = RobotPID() (multibody arm) over 10 s."""
    from library.robots.robot import RobotPID

    res = {arm: simulate(compile(RobotPID(arm=arm)), stop_time=10.0, interval=0.01,
                         rtol=1e-10, atol=1e-12, dynamic=False)
           for arm in ("multibody", "bondgraph")}
    for name, tol in (("arm.q1", 1e-9), ("arm.q2", 1e-9), ("motor1.i", 1e-7),
                      ("motor2.i", 1e-7)):
        assert np.max(np.abs(res["multibody"][name] - res["bondgraph"][name])) < tol, name
