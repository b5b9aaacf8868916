"""The multibody arm (library.planar) against the paper's Lagrange dynamics (Eq. 8/11)."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from bgmodelica import compile, simulate
from library.robots import lagrange
from library.robots.arm import ARM_PARAMETERS, ArmWithTorques, TwoLinkArm
from library.robots.params import ARM
from library.robots.robot import arm_dynamics_functions

P_ARM = np.array([ARM[n] for n in ARM_PARAMETERS])


@pytest.fixture(scope="module")
def arm_with_torques():
    return compile(ArmWithTorques())


def _random_points(n=100, seed=1):
    rng = np.random.default_rng(seed)
    return (rng.uniform(-np.pi, np.pi, (n, 2)), rng.uniform(-6, 6, (n, 2)),
            rng.uniform(-20, 20, (n, 2)), rng.uniform(-40, 40, (n, 2)))


def test_structure(arm_with_torques):
    """Index 3 (Cartesian frames tied by joints) reduced to an ODE in the joint coordinates."""
    s = arm_with_torques.summary()
    assert s["balanced"] and s["structural_index"] == 3
    assert s["states"] == ["arm.joint1.q", "arm.joint1.w", "arm.joint2.q", "arm.joint2.w"]
    assert s["algebraic_variables"] == []
    assert s["inputs"] == ["tau1", "tau2"]


def test_accelerations_match_lagrange(arm_with_torques):
    """q'' of the compiled DAE = M^-1 (tau - C q' - G) at 100 random (q, q', tau)."""
    dae = arm_with_torques.dae
    assert not ca.depends_on(dae.ode, dae.t)
    f = ca.Function("f", [dae.x, dae.p], [dae.ode])
    qs, ws, _, taus = _random_points()
    worst = 0.0
    for q, w, tau in zip(qs, ws, taus, strict=True):
        xdot = np.asarray(f([q[0], w[0], q[1], w[1]],
                            dae.p_vector({"tau1": tau[0], "tau2": tau[1]}))).ravel()
        np.testing.assert_allclose(xdot[[0, 2]], w, rtol=0, atol=1e-14)
        acc = lagrange.forward_dynamics(q, w, tau)
        worst = max(worst, float(np.max(np.abs(xdot[[1, 3]] - acc))))
    assert worst < 1e-10, worst


def test_torques_match_lagrange():
    """Inverse dynamics extracted from the compiled arm = M q'' + C q' + G at 100 points,
    and M, C, G separately (parameters varied too)."""
    fns = arm_dynamics_functions()
    qs, ws, accs, _ = _random_points(seed=2)
    rng = np.random.default_rng(3)
    worst = 0.0
    for k, (q, w, a) in enumerate(zip(qs, ws, accs, strict=True)):
        p = P_ARM * (rng.uniform(0.5, 2.0, P_ARM.size) if k % 2 else 1.0)
        pd = dict(zip(ARM_PARAMETERS, p, strict=True))
        tau = np.asarray(fns["inverse"](q, w, a, p)).ravel()
        worst = max(worst, float(np.max(np.abs(tau - lagrange.inverse_dynamics(q, w, a, pd)))))
        np.testing.assert_allclose(np.asarray(fns["M"](q, p)), lagrange.mass_matrix(q, pd),
                                   rtol=0, atol=1e-12)
        np.testing.assert_allclose(np.asarray(fns["C"](q, w, p)),
                                   lagrange.coriolis_matrix(q, w, pd), rtol=0, atol=1e-11)
        np.testing.assert_allclose(np.asarray(fns["G"](q, p)).ravel(),
                                   lagrange.gravity_vector(q, pd), rtol=0, atol=1e-11)
    assert worst < 1e-10, worst


@pytest.mark.parametrize("start, params", [
    ((0.3, -0.5, 0.0, 0.0), {}),
    ((-1.2, 2.0, 1.5, -3.0), {"m2": 1.2, "l1": 0.6, "lc2": 0.3, "I1": 0.08, "g": 9.0}),
])
def test_free_swing_matches_scipy(start, params):
    """5 s free swing (no friction, no drive) vs scipy DOP853 on the Lagrange ODE: angles
    within 1e-8 rad, speeds within 1e-8 of their peak (IDAS at rtol 1e-12, atol 1e-14)."""
    q1, q2, w1, w2 = start
    compiled = compile(TwoLinkArm(q1=q1, q2=q2, w1=w1, w2=w2))
    res = simulate(compiled, stop_time=5.0, interval=0.01, params=params, rtol=1e-12,
                   atol=1e-14, dynamic=False, solver="idas", outputs=["joint1.q", "joint2.q",
                                                       "joint1.w", "joint2.w"])
    p = dict(ARM, **params)
    ref = solve_ivp(lagrange.lagrange_rhs(p), (0, 5), list(start), method="DOP853",
                    t_eval=res.time, rtol=1e-13, atol=1e-13)
    assert ref.success
    got = np.column_stack([res["joint1.q"], res["joint2.q"], res["joint1.w"],
                           res["joint2.w"]])
    dev = np.max(np.abs(got - ref.y.T), axis=0)
    assert np.all(dev[:2] < 1e-8), dev                                    # angles [rad]
    assert np.all(dev[2:] < 1e-8 * np.max(np.abs(ref.y[2:]), axis=1)), dev  # speeds, relative
    # energy is conserved (no friction) -- a check independent of scipy
    kin = [0.5 * np.array([a, b]) @ lagrange.mass_matrix([x, y], p) @ np.array([a, b])
           for x, y, a, b in got]
    pot = (p["m1"] * p["lc1"] * np.sin(got[:, 0]) + p["m2"] * (
        p["l1"] * np.sin(got[:, 0]) + p["lc2"] * np.sin(got[:, 0] + got[:, 1]))) * p["g"]
    energy = np.asarray(kin) + pot
    assert np.max(np.abs(energy - energy[0])) < 1e-7
