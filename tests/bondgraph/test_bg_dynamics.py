"""The compiled bond-graph arm equals the Lagrange model of paper Eq. (8)/(11); a free swing
conserves energy; the DC motor and the full manipulator simulate."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

import bgmodelica as bm
from library.bondgraph import DCMotorDrive, TwoLinkArm, TwoLinkManipulator

PARAMS = ("m1", "m2", "l1", "lc1", "lc2", "I1", "I2", "g")


def lagrange(P, q, qd):
    """M(q), C(q, q'), G(q) of paper Eq. (8), written independently of the bond graph:
    q1 from the x axis, q2 relative to link 1, gravity along -y."""
    m1, m2, l1, lc1, lc2, I1, I2, g = (P[k] for k in PARAMS)
    c1, c2, s2, c12 = np.cos(q[0]), np.cos(q[1]), np.sin(q[1]), np.cos(q[0] + q[1])
    M11 = I1 + I2 + m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2)
    M12 = I2 + m2 * (lc2**2 + l1 * lc2 * c2)
    M22 = I2 + m2 * lc2**2
    M = np.array([[M11, M12], [M12, M22]])
    h = m2 * l1 * lc2 * s2
    C = np.array([[-h * qd[1], -h * (qd[0] + qd[1])], [h * qd[0], 0.0]])
    G = np.array([(m1 * lc1 + m2 * l1) * g * c1 + m2 * lc2 * g * c12, m2 * lc2 * g * c12])
    return M, C, G


def energy(P, q1, q2, w1, w2):
    m1, m2, l1, lc1, lc2, I1, I2, g = (P[k] for k in PARAMS)
    c2 = np.cos(q2)
    M11 = I1 + I2 + m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2)
    M12 = I2 + m2 * (lc2**2 + l1 * lc2 * c2)
    M22 = I2 + m2 * lc2**2
    kinetic = 0.5 * (M11 * w1**2 + 2 * M12 * w1 * w2 + M22 * w2**2)
    potential = m1 * g * lc1 * np.sin(q1) + m2 * g * (l1 * np.sin(q1) + lc2 * np.sin(q1 + q2))
    return kinetic, potential


@pytest.fixture(scope="module")
def arm():
    return bm.compile(TwoLinkArm())


def test_arm_equations_of_motion_equal_lagrange(arm):
    dae = arm.dae
    assert [u.name for u in dae.inputs] == ["tau1", "tau2"]
    aliases = arm.flat.aliases

    def obs(name):
        if name in dae.observed_index:
            return dae.observed[dae.observed_index[name]]
        rep, sign = aliases[name]
        return sign * obs(rep)

    # states (x) for given joint angles and speeds, then the accelerations the model computes
    target = ca.SX.sym("target", 4)
    residual = ca.vertcat(obs("q1"), obs("q2"), obs("w1.f"), obs("w2.f")) - target
    unknown = ca.vertcat(dae.x, dae.z)
    g = ca.Function("g", [unknown, ca.vertcat(target, dae.p, dae.t)],
                    [ca.vertcat(residual, dae.alg)])
    solve = ca.rootfinder("states", "newton", g, {"abstol": 1e-14})
    acc = ca.Function("acc", [unknown, dae.p, dae.t],
                      [ca.vertcat(obs("der(w1.f)"), obs("der(w2.f)"))])
    names = [p.name for p in dae.parameters]
    rng = np.random.default_rng(2014)
    worst = 0.0
    for _ in range(100):
        P = {"m1": rng.uniform(0.5, 3), "m2": rng.uniform(0.5, 3), "l1": rng.uniform(0.3, 2),
             "l2": 1.0, "I1": rng.uniform(0.01, 1), "I2": rng.uniform(0.01, 1), "g": 9.81}
        P["lc1"] = rng.uniform(0.1, 1) * P["l1"]
        P["lc2"] = rng.uniform(0.1, 1)
        q = rng.uniform(-np.pi, np.pi, 2)
        qd = rng.uniform(-3, 3, 2)
        tau = rng.uniform(-20, 20, 2)
        p = np.array([P[n] for n in names] + list(tau))
        sol = solve(np.zeros(unknown.numel()), np.concatenate([q, qd, p, [0.0]]))
        qdd = np.asarray(acc(sol, p, 0.0)).ravel()
        M, C, G = lagrange(P, q, qd)
        worst = max(worst, float(np.max(np.abs(M @ qdd + C @ qd + G - tau))))
    assert worst < 1e-10, worst


def test_free_swing_conserves_energy():
    q0 = (0.3, 0.8)
    res = bm.simulate(TwoLinkArm(q1=q0[0], q2=q0[1]), stop_time=3.0, interval=0.01,
                      rtol=1e-12, atol=1e-12)
    P = dict(res.parameters)
    assert abs(res["q1"][0] - q0[0]) < 1e-12 and abs(res["q2"][0] - q0[1]) < 1e-12
    kin, pot = energy(P, res["q1"], res["q2"], res["w1.f"], res["w2.f"])
    total = kin + pot
    assert np.max(kin) > 5.0                          # it really swings
    drift = np.max(np.abs(total - total[0])) / abs(total[0])
    assert drift < 1e-8, drift


def test_dc_motor_steady_state():
    res = bm.simulate(DCMotorDrive(), stop_time=2.0, params={"motor.U": 12.0},
                      rtol=1e-9, atol=1e-10)
    R, k1, b, k2 = 1.0, 0.5, 1e-4, 20.0
    wm = k1 * 12.0 / (R * b + k1**2)                   # no load: U = R i + k1 wm, k1 i = b wm
    assert res["motor.wm.f"][-1] == pytest.approx(wm, rel=1e-6)
    assert res["wa.f"][-1] == pytest.approx(wm / k2, rel=1e-6)     # motor = k2 x joint
    assert res["qa"][-1] > 0


def test_manipulator_simulates_and_gear_convention_holds():
    m = TwoLinkManipulator()
    res = bm.simulate(m, stop_time=0.5, params={"motor1.U": 6.0, "motor2.U": -3.0},
                      rtol=1e-8, atol=1e-10)
    k2 = res.parameters["motor1.k2"]
    assert np.allclose(res["motor1.wm.f"], k2 * res["w1.f"], atol=1e-8)
    # joint torque = k2 x motor torque on the gear
    assert np.allclose(res["motor1.gear.p1.e"], k2 * res["motor1.gear.p2.e"], atol=1e-8)
    assert np.all(np.isfinite(res["q1"])) and np.all(np.isfinite(res["q2"]))
    summary = bm.compile(m).summary()
    assert set(summary["states"]) == {"Iz1.p", "Iz2.p", "Dq1.y", "Dq2.y", "motor1.ind.p",
                                      "motor2.ind.p"}
