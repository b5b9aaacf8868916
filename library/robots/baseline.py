"""Hand-written reference ODE of the PID robot (independent of the component models): the
paper's Lagrange arm (Eq. 8/11) driven by the geared DC motors (Eq. 5-7) under the same
LimPID law as :class:`~library.robots.robot.RobotPID`. Used by the tests and by
``benchmarks/robot_speed.py`` (CasADi + CVODES and scipy baselines).

State ``x = [q1, q2, w1, w2, i1, i2, xi1, xd1, xi2, xd2]`` (joint angles and speeds, armature
currents, PID integral and derivative-filter states). Motor + arm:

    (M(q) + Jm k2^2 I) q'' = k1 k2 i - b k2^2 q' - C(q, q') q' - G(q)
    L i' = u - R i - k1 k2 q'

PID (LimPID with wd = 0, wp = 1): ``y_un = Kp (e + xi + Nd (-q - xd))``, ``u = clip(y_un)``,
``xi' = (e + (u - y_un)/(Kp Ni)) Ki/Kp``, ``xd' = Nd Kp/Kd (-q - xd)``.
"""

from __future__ import annotations

from collections.abc import Mapping

import casadi as ca
import numpy as np

from . import lagrange
from .params import ARM, MOTOR, PID, REFERENCE, VMAX

__all__ = ["robot_rhs", "N_STATES"]

N_STATES = 10
NI = 0.9          # LimPID anti-windup gain (library.blocks default)


def robot_rhs(lib=np, params: Mapping[str, float] | None = None):
    """``f(t, x)`` of the PID robot for numpy (``lib=np``) or CasADi symbols (``lib=ca``).

    ``params`` overrides by the names of :class:`~library.robots.robot.RobotPID` (m1 ...,
    motor parameters as R, L, k1, Jm, b, k2 -- the same for both motors -- Kp1 ..., A1 ...,
    Vmax).
    """
    p = {**ARM, **MOTOR, **PID, **REFERENCE, "Vmax": VMAX, **(params or {})}
    R, L, k1, Jm, b, k2 = (p[n] for n in ("R", "L", "k1", "Jm", "b", "k2"))
    nd, vmax = p["Nd"], p["Vmax"]
    gains = [(p[f"Kp{j}"], p[f"Ki{j}"], p[f"Kd{j}"]) for j in (1, 2)]
    refs = [(p["A1"], p["f1"]), (p["A2"], p["f2"])]
    arm = {n: p[n] for n in ARM}

    def clip(v):
        if lib is np:
            return min(vmax, max(-vmax, v))
        return ca.fmin(vmax, ca.fmax(-vmax, v))

    def f(t, x):
        q, w, cur = x[0:2], x[2:4], x[4:6]
        dxi, dxd, volts = [], [], []
        for j in range(2):
            kp, ki, kd = gains[j]
            a, fr = refs[j]
            e = a * lib.sin(2 * np.pi * fr * t) - q[j]
            xi, xd = x[6 + 2 * j], x[7 + 2 * j]
            y_un = kp * (e + xi + nd * (-q[j] - xd))
            y = clip(y_un)
            dxi.append((e + (y - y_un) / (kp * NI)) * ki / kp)
            dxd.append(nd * kp / kd * (-q[j] - xd))
            volts.append(y)
        M = lagrange.mass_matrix(q, arm, lib)
        C = lagrange.coriolis_matrix(q, w, arm, lib)
        G = lagrange.gravity_vector(q, arm, lib)
        if lib is np:
            q, w, cur = np.asarray(q), np.asarray(w), np.asarray(cur)
            tau = k1 * k2 * cur - b * k2**2 * w
            acc = np.linalg.solve(M + Jm * k2**2 * np.eye(2), tau - C @ w - G)
            di = (np.asarray(volts) - R * cur - k1 * k2 * w) / L
            return np.concatenate([w, acc, di, [dxi[0], dxd[0], dxi[1], dxd[1]]])
        tau = k1 * k2 * cur - b * k2**2 * w
        acc = ca.solve(M + Jm * k2**2 * ca.DM.eye(2), tau - ca.mtimes(C, w) - G)
        di = (ca.vertcat(*volts) - R * cur - k1 * k2 * w) / L
        return ca.vertcat(w, acc, di, dxi[0], dxd[0], dxi[1], dxd[1])

    return f
