"""The paper's closed-form dynamics of the two-link planar arm (Baghli & El Bakkali 2014,
Eq. 8 and Eq. 11), for reference and for the independent baselines of tests and benchmarks.

    M(q) q'' + C(q, q') q' + G(q) = tau

q1 is the angle of link 1 from the world x axis, q2 the angle of link 2 relative to link 1;
gravity ``g`` acts along -y. With c2 = cos q2, s2 = sin q2, c1 = cos q1, c12 = cos(q1 + q2)::

    M11 = I1 + I2 + m1 lc1^2 + m2 (l1^2 + lc2^2 + 2 l1 lc2 c2)
    M12 = M21 = I2 + m2 (lc2^2 + l1 lc2 c2)
    M22 = I2 + m2 lc2^2
    C = [[-m2 l1 lc2 s2 q2',  -m2 l1 lc2 s2 (q1' + q2')],
         [ m2 l1 lc2 s2 q1',   0                       ]]
    G = [(m1 lc1 + m2 l1) g c1 + m2 g lc2 c12,  m2 g lc2 c12]

I1, I2 are the link inertias about their centres of mass, lc1, lc2 the distances of the
centres of mass from the joints (the paper's Eq. 1 uses lc = l/2). ``l2`` does not enter the
dynamics (only the end-effector position).

Every function works on numpy arrays (floats) and on CasADi symbols alike: pass ``np`` (default)
or ``ca`` as ``lib``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

__all__ = ["ARM_DEFAULTS", "mass_matrix", "coriolis_matrix", "gravity_vector",
           "forward_dynamics", "inverse_dynamics", "lagrange_rhs", "end_effector"]

#: Arm parameters of a small lab arm (see :mod:`library.robots.params`).
ARM_DEFAULTS: dict[str, float] = {
    "m1": 3.0, "m2": 2.0, "l1": 0.5, "l2": 0.4, "lc1": 0.25, "lc2": 0.2,
    "I1": 3.0 * 0.5**2 / 12, "I2": 2.0 * 0.4**2 / 12, "g": 9.81,
}


def _p(p: Mapping[str, Any] | None) -> dict[str, Any]:
    out = dict(ARM_DEFAULTS)
    if p:
        out.update(p)
    return out


def _mat(lib, rows):
    if lib is np:
        return np.array(rows, dtype=float)
    return lib.vertcat(*[lib.horzcat(*r) for r in rows])


def _vec(lib, items):
    if lib is np:
        return np.array(items, dtype=float)
    return lib.vertcat(*items)


def mass_matrix(q, p: Mapping[str, Any] | None = None, lib=np):
    """Inertia matrix M(q) (2x2) [kg.m2]."""
    p = _p(p)
    c2 = lib.cos(q[1])
    m2, l1, lc1, lc2 = p["m2"], p["l1"], p["lc1"], p["lc2"]
    m11 = p["I1"] + p["I2"] + p["m1"] * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2)
    m12 = p["I2"] + m2 * (lc2**2 + l1 * lc2 * c2)
    m22 = p["I2"] + m2 * lc2**2
    return _mat(lib, [[m11, m12], [m12, m22]])


def coriolis_matrix(q, qd, p: Mapping[str, Any] | None = None, lib=np):
    """Centrifugal and Coriolis matrix C(q, q') (2x2) [kg.m2/s], Eq. 8b/11."""
    p = _p(p)
    h = p["m2"] * p["l1"] * p["lc2"] * lib.sin(q[1])
    return _mat(lib, [[-h * qd[1], -h * (qd[0] + qd[1])], [h * qd[0], 0 * h]])


def gravity_vector(q, p: Mapping[str, Any] | None = None, lib=np):
    """Gravity torques G(q) [N.m], Eq. 8c/11."""
    p = _p(p)
    g = p["g"]
    c1, c12 = lib.cos(q[0]), lib.cos(q[0] + q[1])
    return _vec(lib, [(p["m1"] * p["lc1"] + p["m2"] * p["l1"]) * g * c1
                      + p["m2"] * g * p["lc2"] * c12,
                      p["m2"] * g * p["lc2"] * c12])


def inverse_dynamics(q, qd, qdd, p: Mapping[str, Any] | None = None, lib=np):
    """Joint torques ``tau = M q'' + C q' + G`` [N.m]."""
    M, C, G = mass_matrix(q, p, lib), coriolis_matrix(q, qd, p, lib), gravity_vector(q, p, lib)
    if lib is np:
        return M @ np.asarray(qdd, float) + C @ np.asarray(qd, float) + G
    return lib.mtimes(M, _vec(lib, list(qdd))) + lib.mtimes(C, _vec(lib, list(qd))) + G


def forward_dynamics(q, qd, tau, p: Mapping[str, Any] | None = None, lib=np):
    """Joint accelerations ``q'' = M^-1 (tau - C q' - G)`` [rad/s2] (Eq. 12)."""
    M, C, G = mass_matrix(q, p, lib), coriolis_matrix(q, qd, p, lib), gravity_vector(q, p, lib)
    if lib is np:
        return np.linalg.solve(M, np.asarray(tau, float) - C @ np.asarray(qd, float) - G)
    return lib.solve(M, _vec(lib, list(tau)) - lib.mtimes(C, _vec(lib, list(qd))) - G)


def lagrange_rhs(p: Mapping[str, Any] | None = None, tau=(0.0, 0.0)):
    """``f(t, [q1, q2, w1, w2])`` for scipy: the free (or constant-torque) arm as an ODE."""
    pp = _p(p)
    tau = np.asarray(tau, float)

    def f(_t, y):
        return np.concatenate([y[2:], forward_dynamics(y[:2], y[2:], tau, pp)])

    return f


def end_effector(q, p: Mapping[str, Any] | None = None, lib=np):
    """Tip position (x, y) [m] of link 2."""
    p = _p(p)
    return (p["l1"] * lib.cos(q[0]) + p["l2"] * lib.cos(q[0] + q[1]),
            p["l1"] * lib.sin(q[0]) + p["l2"] * lib.sin(q[0] + q[1]))
