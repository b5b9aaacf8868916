"""The paper's robot with its motors (RobotOpenLoop) at an arm pose held by constant voltages:
steady state, eigenvalues and frequency response against an independent linearization
(complex-step derivatives of the closed-form Lagrange model of library/robots/lagrange.py
plus the motor equations), numeric ranks beside the structural ones of the bond graph."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica.analysis import controllability, linearization, observability
from library.robots.lagrange import coriolis_matrix, gravity_vector, mass_matrix
from library.robots.params import MOTOR

POSE = np.array([-1.0, 0.6])          # q1 from the x axis, q2 relative [rad]


def _complex_lib():
    """A ``lib`` for lagrange.py's formulas that keeps complex numbers (complex step)."""
    return SimpleNamespace(cos=np.cos, sin=np.sin,
                           horzcat=lambda *a: np.array(a, dtype=complex),
                           vertcat=lambda *a: np.array(a, dtype=complex))


def _rhs(x: np.ndarray, u: np.ndarray) -> np.ndarray:
    """The robot with its geared motors, written by hand: x = (q1, w1, q2, w2, i1, i2).

    Motor k: L di/dt = U - R i - k1 k2 w; joint torque k2 (k1 i - b k2 w - Jm k2 w').
    Arm: M(q) q'' + C(q, w) w + G(q) = tau  =>  (M + k2^2 Jm) q'' = k2 k1 i - k2^2 b w - C w - G.
    """
    lib = _complex_lib()
    R, L, k1, Jm, b, k2 = (MOTOR[n] for n in ("R", "L", "k1", "Jm", "b", "k2"))
    q = np.array([x[0], x[2]])
    w = np.array([x[1], x[3]])
    i = np.array([x[4], x[5]])
    M = mass_matrix(q, lib=lib).reshape(2, 2) + k2**2 * Jm * np.eye(2)
    C = coriolis_matrix(q, w, lib=lib).reshape(2, 2)
    G = gravity_vector(q, lib=lib).reshape(2)
    acc = np.linalg.solve(M, k2 * k1 * i - k2**2 * b * w - C @ w - G)
    di = (u - R * i - k1 * k2 * w) / L
    return np.array([w[0], acc[0], w[1], acc[1], di[0], di[1]])


def _reference():
    R, k1, k2 = MOTOR["R"], MOTOR["k1"], MOTOR["k2"]
    U = R * gravity_vector(POSE) / (k1 * k2)       # at rest: k2 k1 U/R = G(q)
    x0 = np.array([POSE[0], 0.0, POSE[1], 0.0, U[0] / R, U[1] / R])
    h = 1e-30
    A = np.column_stack([_rhs(x0 + 1j * h * e, U).imag / h for e in np.eye(6)])
    B = np.column_stack([_rhs(x0, U + 1j * h * e).imag / h for e in np.eye(2)])
    C = np.zeros((2, 6))
    C[0, 0] = C[1, 2] = 1.0
    assert np.max(np.abs(_rhs(x0, U).real)) < 1e-12   # it is an equilibrium
    return U, A, B, C


@pytest.fixture(scope="module")
def robot():
    from library.robots import RobotOpenLoop

    U, A, B, C = _reference()
    compiled = bg.compile(RobotOpenLoop())
    # start values only as guesses, 0.2 rad away from the pose
    lin = linearization(compiled, {"U1": U[0], "U2": U[1], "arm.q1": POSE[0] + 0.2,
                                   "arm.q2": POSE[1] - 0.2}, steady_state=True)
    return lin, (A, B, C)


def _order(names):
    want = ["arm.joint1.q", "arm.joint1.w", "arm.joint2.q", "arm.joint2.w",
            "motor1.inductor.i", "motor2.inductor.i"]
    return [names.index(n) for n in want]


def test_pose_held_by_constant_voltages(robot):
    lin, _ = robot
    pt = lin.point
    assert pt.kind == "steady state"
    assert abs(pt["q1"] - POSE[0]) < 1e-9 and abs(pt["q2"] - POSE[1]) < 1e-9
    assert abs(pt["arm.q1"] - POSE[0]) < 1e-9
    assert pt.residual < 1e-10


def test_eigenvalues_against_independent_linearization(robot):
    lin, (A, B, C) = robot
    perm = _order(lin.states)
    assert lin.inputs == ["U1", "U2"] and lin.outputs == ["q1", "q2"]
    Ap = lin.A[np.ix_(perm, perm)]
    assert np.allclose(Ap, A, rtol=1e-8, atol=1e-8 * np.abs(A).max())
    ev = np.sort_complex(np.linalg.eigvals(A))
    got = np.sort_complex(lin.eigenvalues)
    rel = np.max(np.abs(got - ev) / np.abs(ev))
    assert rel < 1e-6, rel


def test_frequency_response_against_independent_linearization(robot):
    lin, (A, B, C) = robot
    omega = np.concatenate([[0.0], np.logspace(-3, 3, 61)])      # 0 .. 1000 rad/s
    G = lin.frequency_response(omega)
    worst = 0.0
    for k, w in enumerate(omega):
        ref = C @ np.linalg.solve(1j * w * np.eye(6) - A, B)
        worst = max(worst, np.max(np.abs(G[k] - ref) / np.abs(ref)))
    assert worst < 1e-6, worst


def test_numeric_ranks_beside_structural(robot):
    lin, _ = robot
    ctrb = controllability(lin.A, lin.B)
    obsv = observability(lin.A, lin.C)
    assert (ctrb.rank, ctrb.n, obsv.rank, obsv.n) == (6, 6, 6, 6)
    # powers of A fail here: [B AB ... A^5 B] spans 10^13 in scale
    import control

    assert np.linalg.cond(control.ctrb(lin.A, lin.B)) > 1e12
    # the structural result of the paper's bond graph with the same motors and detectors
    from bgmodelica.analysis.compare import compare_bond_graph
    from library.bondgraph.paper import TwoLinkManipulator

    m = TwoLinkManipulator()
    cmp = compare_bond_graph(m, bg.compile(m))
    s, n = cmp.structural["controllability"], cmp.numeric["controllability"]
    assert s.ok and (s.rank, s.n) == (4, 4) and (n.rank, n.n) == (6, 6)
    s, n = cmp.structural["observability"], cmp.numeric["observability"]
    assert s.ok and (s.rank, s.n) == (4, 4) and (n.rank, n.n) == (6, 6)
    assert cmp.inputs == {"motor1.src": "motor1.U", "motor2.src": "motor2.U"}
    assert "4 states" in cmp.to_text()


def test_pid_tuned_on_the_linear_model_drives_the_nonlinear_robot(robot):
    import control

    from library.robots.linear_control import POSE as POSE_LC
    from library.robots.linear_control import RobotJointPID, tune_pid

    lin, _ = robot
    pid = tune_pid(lin)
    assert np.all(pid["closed_loop_poles"].real < 0)
    assert pid["phase_margin1"] > 45 and pid["phase_margin2"] > 45
    params = {f"pid{k[-1]}.{k[:-1]}": pid[k] for k in
              ("Kp1", "Ki1", "Kd1", "Tf1", "Kp2", "Ki2", "Kd2", "Tf2")}
    params.update({"dq1": 0.05, "dq2": -0.05, "arm.q1": POSE_LC[0] + 0.1,
                   "arm.q2": POSE_LC[1] - 0.1})
    res = bg.simulate(RobotJointPID(), stop_time=0.4, interval=0.002, params=params,
                      init="steady-state", rtol=1e-9, atol=1e-11)
    assert abs(res["arm.q1"][0] - POSE_LC[0]) < 1e-9     # starts held at the pose
    T = res.time
    r = np.vstack([0.05 * (1 - np.exp(-T / 0.05)), -0.05 * (1 - np.exp(-T / 0.05))])
    y_lin = np.asarray(control.forced_response(pid["closed_loop"], T, r).outputs)
    y_nl = np.vstack([res["arm.q1"] - POSE_LC[0], res["arm.q2"] - POSE_LC[1]])
    assert np.max(np.abs(y_nl - y_lin)) < 1e-3 * 0.05 * 10
