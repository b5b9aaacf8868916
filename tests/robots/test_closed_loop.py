"""Closed loops of the paper's robot: PID on the motor voltages (Fig. 13-15) and computed
torque (Fig. 12), plus the main job."""

from __future__ import annotations

import json

import casadi as ca
import numpy as np
import pytest

from bgmodelica import compile, simulate
from library.robots.baseline import N_STATES, robot_rhs
from library.robots.robot import RobotComputedTorque, RobotPID

#: Documented bound on the PID tracking error after 1 s with the default parameters
#: (measured: 0.0247 rad on joint 1, 0.0283 rad on joint 2).
PID_BOUND = 0.03


@pytest.fixture(scope="module")
def pid_robot():
    return compile(RobotPID())


def test_pid_structure(pid_robot):
    s = pid_robot.summary()
    assert s["balanced"] and s["structural_index"] == 3
    assert s["algebraic_variables"] == []
    assert {"arm.joint1.q", "arm.joint1.w", "arm.joint2.q", "arm.joint2.w",
            "motor1.inductor.i", "motor2.inductor.i"} <= set(s["states"])
    assert pid_robot.compile_time < 1.0


def test_pid_parameter_names(pid_robot):
    """The paper's names at the top level, per-motor parameters under motor1./motor2."""
    names = {p.name for p in pid_robot.dae.parameters}
    expected = {"m1", "m2", "l1", "l2", "lc1", "lc2", "I1", "I2", "g", "Kp1", "Ki1", "Kd1",
                "Kp2", "Ki2", "Kd2", "A1", "f1", "A2", "f2", "Vmax"}
    expected |= {f"motor{j}.{n}" for j in (1, 2) for n in ("R", "L", "k1", "Jm", "b", "k2")}
    assert expected <= names
    modified = compile(RobotPID(q1=0.2, **{"motor1.R": 2.0, "pid2.Nd": 5.0}))
    p = {q.name: q.decl.value for q in modified.dae.parameters}
    assert p["motor1.R"] == 2.0 and p["motor2.R"] == 1.0
    res = simulate(modified, stop_time=0.1, interval=0.05, dynamic=False)
    assert res["arm.q1"][0] == pytest.approx(0.2)


def test_pid_tracking(pid_robot):
    res = simulate(pid_robot, stop_time=10.0, interval=0.01, dynamic=False)
    after = res.time >= 1.0
    for j in (1, 2):
        err = res[f"ref{j}.q"] - res[f"arm.q{j}"]
        np.testing.assert_allclose(res[f"e{j}"], err, atol=1e-14)
        assert np.max(np.abs(err[after])) < PID_BOUND
        assert np.max(np.abs(res[f"motor{j}.u"])) <= 24.0 + 1e-9
    np.testing.assert_allclose(res["ref1.q"], np.sin(2 * np.pi * 0.25 * res.time), atol=1e-14)


@pytest.mark.parametrize("params", [{}, {"m2": 2.5, "l1": 0.45, "Kp2": 300.0, "Kd1": 8.0,
                                     "A2": 1.1, "Vmax": 15.0}])
def test_pid_robot_matches_handwritten_ode(pid_robot, params):
    """The component robot (multibody arm, component motors, LimPID blocks) = the
    hand-written Lagrange + motor + PID ODE, integrated separately by CVODES."""
    grid = np.linspace(0.0, 3.0, 301)
    res = simulate(pid_robot, stop_time=3.0, interval=0.01, params=params, rtol=1e-11,
                   atol=1e-13, dynamic=False)
    x, t = ca.SX.sym("x", N_STATES), ca.SX.sym("t")
    F = ca.integrator("ref", "cvodes", {"x": x, "t": t, "ode": robot_rhs(ca, params)(t, x)},
                      0.0, list(grid[1:]), {"abstol": 1e-13, "reltol": 1e-11,
                                            "max_num_steps": 10**6})
    ref = np.hstack([np.zeros((N_STATES, 1)), np.asarray(F(x0=np.zeros(N_STATES))["xf"])])
    for k, name in enumerate(["arm.q1", "arm.q2", "arm.w1", "arm.w2", "motor1.i", "motor2.i"]):
        scale = max(1.0, np.max(np.abs(ref[k])))
        assert np.max(np.abs(res[name] - ref[k])) < 1e-7 * scale, name


def test_pid_saturation(pid_robot):
    """With a 12 V supply the voltages clip at +-12 V and tracking degrades (but runs)."""
    res = simulate(pid_robot, stop_time=4.0, interval=0.01, params={"Vmax": 12.0},
                   dynamic=False)
    u = np.concatenate([res["motor1.u"], res["motor2.u"]])
    assert np.max(np.abs(u)) <= 12.0 + 1e-9
    assert np.mean(np.abs(u) > 12.0 - 1e-6) > 0.05          # saturated part of the time
    assert np.max(np.abs(res["e2"][res.time >= 1.0])) > PID_BOUND


@pytest.mark.parametrize("mode", ["feedforward", "inverse_dynamics"])
def test_computed_torque_perfect_model(mode):
    """M, C, G from the compiled arm, perfect parameters: error < 1e-4 rad after 2 s."""
    compiled = compile(RobotComputedTorque(mode=mode))
    res = simulate(compiled, stop_time=6.0, interval=0.01, rtol=1e-9, atol=1e-11,
                   dynamic=False)
    after = res.time >= 2.0
    for j in (1, 2):
        assert np.max(np.abs(res[f"e{j}"][after])) < 1e-4
    # an imperfect model (link 2 30 % heavier than the controller believes) tracks worse
    bad = simulate(RobotComputedTorque(mode=mode, **{"model.m2": 2.0 / 1.3}), stop_time=6.0,
                   interval=0.01, rtol=1e-9, atol=1e-11, dynamic=False)
    assert max(np.max(np.abs(bad[f"e{j}"][after])) for j in (1, 2)) > 1e-3


def test_main_job(tmp_path):
    from library.robots.main_job import run

    summary = run(tmp_path)
    err = summary["max_abs_tracking_error_after_1s_rad"]
    assert err["q1"] < PID_BOUND and err["q2"] < PID_BOUND
    for name in ("robot.csv", "fig14_joint1.png", "fig15_joint2.png", "tracking_error.png",
                 "motors.png", "summary.json"):
        assert (tmp_path / name).stat().st_size > 0
    assert json.loads((tmp_path / "summary.json").read_text())["states"] == summary["states"]
    header = (tmp_path / "robot.csv").read_text().splitlines()[0].split(",")
    assert header[:3] == ["time", "ref1.q", "arm.q1"]
