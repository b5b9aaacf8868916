"""Direct collocation of a :class:`~.problem.Problem` and its solution by IPOPT.

The horizon ``[0, T]`` is cut into intervals at the mesh fractions ``s_0 = 0 < ... < s_N =
1`` (``t = T s``; in a minimum-time problem T is a decision variable). On each interval
the states are a degree-3 polynomial through the start point and the three Radau IIA points
``c = (4 -+ sqrt 6)/10, 1`` (order 5 at the mesh points, L-stable; the last point is the
next interval's start, so states are continuous); the DAE as simulated, ``x' = f(t, x, z,
p)`` and ``0 = g(t, x, z, p)``, holds at the three points, where the algebraic variables
live; the controls are linear on each interval and may jump at the mesh points (a bang-bang
control switching at a mesh point is exact, a smooth one is followed to second order), a
table a re-simulation takes as it is (exact up to the collocation error). The Lagrange term is
integrated by the Radau quadrature, path constraints hold at the collocation points.
Variables are scaled by ``Problem.scale_x`` and the control ranges; the NLP is built in SX
and solved with IPOPT's exact Hessian.
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from .problem import Problem

_S6 = math.sqrt(6.0)
#: Radau IIA collocation points on [0, 1] and their quadrature weights
RADAU = np.array([(4 - _S6) / 10, (4 + _S6) / 10, 1.0])
WEIGHTS = np.array([(16 - _S6) / 36, (16 + _S6) / 36, 1.0 / 9.0])


def _derivative_matrix() -> np.ndarray:
    """``D[r, j]``: derivative at ``RADAU[j]`` of the Lagrange polynomial of node ``r`` on
    the nodes ``(0, *RADAU)``."""
    nodes = np.concatenate([[0.0], RADAU])
    out = np.zeros((4, 3))
    for r in range(4):
        others = [nodes[m] for m in range(4) if m != r]
        poly = np.poly1d(others, r=True) / np.prod([nodes[r] - o for o in others])
        out[r] = poly.deriv()(RADAU)
    return out


DERIV = _derivative_matrix()


@dataclass
class Trajectory:
    """Values on a mesh: ``X`` states at ``(0, then the 3 collocation points of each
    interval)``, shape (3N+1, nx); ``Z`` algebraic variables at the collocation points (3N,
    nz); ``U`` controls per interval at its start then its end (N, 2 nu), linear between;
    ``T`` the horizon [s]."""

    mesh: np.ndarray
    T: float
    X: np.ndarray
    Z: np.ndarray
    U: np.ndarray

    def times(self) -> np.ndarray:
        """The times of the rows of ``X`` [s]."""
        h = np.diff(self.mesh)
        inner = (self.mesh[:-1, None] + h[:, None] * RADAU[None, :]).ravel()
        return self.T * np.concatenate([[0.0], inner])

    def control_table(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        """Control ``i`` as a table: times [s] (a mesh point twice where it may jump) and
        values, linear in between."""
        nu = self.U.shape[1] // 2
        times = np.repeat(self.T * self.mesh, 2)[1:-1]
        values = np.column_stack([self.U[:, i], self.U[:, nu + i]]).ravel()
        return times, values


@dataclass
class Solution:
    """An IPOPT run: the trajectory, the objective and the solver's report."""

    trajectory: Trajectory
    objective: float
    status: str
    success: bool
    iterations: int
    seconds: float
    violation: dict[str, float] = field(default_factory=dict)   # worst constraint groups


def solve(problem: Problem, guess: Trajectory, *, max_iter: int = 3000,
          tol: float = 1e-10) -> Solution:
    """Transcribe ``problem`` on ``guess.mesh`` and solve it from ``guess``."""
    dae = problem.dae
    mesh = guess.mesh
    n, nx, nz, nu = len(mesh) - 1, dae.x.numel(), dae.z.numel(), len(problem.slots)
    sx = problem.scale_x
    sz = _scale(guess.Z, axis=0, size=nz)
    su = np.tile([_range_scale(lo, hi, guess.U[:, i::nu]) for i, (lo, hi)
                  in enumerate(problem.bounds)], 2)
    point = _point_function(problem)

    w, w0, lbw, ubw = [], [], [], []
    g, lbg, ubg, labels = [], [], [], []

    def var(name: str, size: int, start, lo, hi, scale) -> ca.SX:
        v = ca.SX.sym(name, size)
        w.append(v)
        w0.append(np.asarray(start, float).ravel() / scale)
        lbw.append(np.asarray(lo, float).ravel() / scale)
        ubw.append(np.asarray(hi, float).ravel() / scale)
        return v * scale

    def con(expr, lo, hi, label: str) -> None:
        g.append(expr)
        size = expr.numel()
        lbg.append(np.broadcast_to(np.asarray(lo, float), (size,)))
        ubg.append(np.broadcast_to(np.asarray(hi, float), (size,)))
        labels.extend([label] * size)

    if problem.minimum_time:
        T = var("T", 1, guess.T, 1e-6 * guess.T, 1e3 * guess.T, guess.T)
    else:
        T = ca.SX(problem.stop_time)
    lo_u = np.array([b[0] for b in problem.bounds])
    hi_u = np.array([b[1] for b in problem.bounds])
    inf_x = np.full(3 * nx, np.inf)
    inf_z = np.full(3 * nz, np.inf)
    xa = ca.DM(problem.x0)
    quad = 0
    path_lo = np.array([c.lo for c in problem.path])
    path_hi = np.array([c.hi for c in problem.path])
    out = None
    for k in range(n):
        h = T * (mesh[k + 1] - mesh[k])
        t0 = T * mesh[k]
        Xc = var(f"X{k}", 3 * nx, guess.X[1 + 3 * k:4 + 3 * k], -inf_x, inf_x, np.tile(sx, 3))
        Zc = var(f"Z{k}", 3 * nz, guess.Z[3 * k:3 * k + 3], -inf_z, inf_z, np.tile(sz, 3))
        Uk = var(f"U{k}", 2 * nu, guess.U[k], np.tile(lo_u, 2), np.tile(hi_u, 2), su)
        out = point(t0, h, xa, Xc, Zc, Uk[:nu], Uk[nu:])
        con(out[0] / np.tile(sx, 3), 0, 0, "collocation")
        if nz:
            con(out[1], 0, 0, "algebraic equations")
        quad = quad + out[2]
        for j, c in enumerate(problem.path):
            con(out[3][j::len(problem.path)], path_lo[j], path_hi[j], c.label)
        xa = Xc[2 * nx:]
    end = out[4]
    for j, c in enumerate(problem.final):
        con(end[j], c.lo, c.hi, c.label)
    objective = out[5] + quad + (T if problem.minimum_time else 0)

    nlp = {"x": ca.vertcat(*w), "f": objective, "g": ca.vertcat(*g)}
    opts = {"print_time": False, "ipopt.print_level": 0, "ipopt.sb": "yes",
            "ipopt.max_iter": max_iter, "ipopt.tol": tol}
    solver = ca.nlpsol("ocp", "ipopt", nlp, opts)
    t_start = _time.perf_counter()
    res = solver(x0=np.concatenate(w0), lbx=np.concatenate(lbw), ubx=np.concatenate(ubw),
                 lbg=np.concatenate(lbg), ubg=np.concatenate(ubg))
    seconds = _time.perf_counter() - t_start
    stats = solver.stats()
    flat = np.asarray(res["x"]).ravel()
    traj = _unpack(flat, w0, problem, guess, sx, sz, su)
    gval = np.asarray(res["g"]).ravel()
    viol = _violations(gval, np.concatenate(lbg), np.concatenate(ubg), labels)
    return Solution(traj, float(res["f"]), str(stats.get("return_status", "unknown")),
                    bool(stats.get("success", False)), int(stats.get("iter_count", -1)),
                    seconds, viol)


def _unpack(flat: np.ndarray, w0: list[np.ndarray], problem: Problem, guess: Trajectory,
            sx: np.ndarray, sz: np.ndarray, su: np.ndarray) -> Trajectory:
    nx, nz, nu = len(sx), len(sz), len(su)   # nu: 2 per control
    pos = 0
    T = problem.stop_time
    if problem.minimum_time:
        T = float(flat[0] * guess.T)
        pos = 1
    n = len(guess.mesh) - 1
    X = np.zeros((3 * n + 1, nx))
    Z = np.zeros((3 * n, nz))
    U = np.zeros((n, nu))
    lo = np.tile([b[0] for b in problem.bounds], 2)
    hi = np.tile([b[1] for b in problem.bounds], 2)
    X[0] = problem.x0
    for k in range(n):
        X[1 + 3 * k:4 + 3 * k] = (flat[pos:pos + 3 * nx].reshape(3, nx)) * sx
        pos += 3 * nx
        Z[3 * k:3 * k + 3] = (flat[pos:pos + 3 * nz].reshape(3, nz)) * sz if nz else 0
        pos += 3 * nz
        U[k] = np.clip(flat[pos:pos + nu] * su, lo, hi)   # IPOPT relaxes bounds by 1e-8
        pos += nu
    return Trajectory(guess.mesh.copy(), float(T), X, Z, U)


def _violations(g: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                labels: list[str]) -> dict[str, float]:
    """The largest violation of each constraint group, worst first."""
    gap = np.maximum(lo - g, g - hi)
    out: dict[str, float] = {}
    for label, v in zip(labels, gap, strict=True):
        if v > out.get(label, 0.0):
            out[label] = float(v)
    return dict(sorted(out.items(), key=lambda kv: -kv[1]))


def _scale(values: np.ndarray, axis: int, size: int) -> np.ndarray:
    if size == 0:
        return np.ones(0)
    big = np.max(np.abs(values), axis=axis) if values.size else np.zeros(size)
    return np.maximum(big, 1.0)


def _range_scale(lo: float, hi: float, guess: np.ndarray) -> float:
    finite = [abs(v) for v in (lo, hi) if math.isfinite(v)]
    return max(max(finite) if finite else 0.0, float(np.max(np.abs(guess), initial=0.0)), 1.0)


def _point_function(problem: Problem) -> ca.Function:
    """One interval: ``(t0, h, x_start, X (3 nx), Z (3 nz), u_start, u_end)`` -> collocation
    defects,
    algebraic residuals, the Radau quadrature of the Lagrange term, the path expressions at
    the three points, the final-condition expressions and the Mayer term at the end."""
    dae = problem.dae
    nx, nz = dae.x.numel(), dae.z.numel()
    ua = ca.SX.sym("ua", len(problem.slots))
    ub = ca.SX.sym("ub", len(problem.slots))
    t0, h = ca.SX.sym("t0"), ca.SX.sym("h")
    xa = ca.SX.sym("xa", nx)
    X = ca.SX.sym("X", 3 * nx)
    Z = ca.SX.sym("Z", 3 * nz)
    path = ca.vertcat(*[c.expr for c in problem.path]) if problem.path else ca.SX(0, 1)
    final = ca.vertcat(*[c.expr for c in problem.final]) if problem.final else ca.SX(0, 1)
    f = ca.Function("f", [dae.t, dae.x, dae.z, dae.p],
                    [dae.ode, dae.alg, problem.lagrange, path, final, problem.mayer])
    defects, algs, paths = [], [], []
    quad = 0
    nodes = [xa] + [X[j * nx:(j + 1) * nx] for j in range(3)]
    for j in range(3):
        xj, zj = nodes[j + 1], Z[j * nz:(j + 1) * nz]
        p = control_parameters(problem, ua + RADAU[j] * (ub - ua))
        ode, alg, lag, pth, fin, may = f(t0 + RADAU[j] * h, xj, zj, p)
        slope = sum(DERIV[r, j] * nodes[r] for r in range(4))
        defects.append(slope - h * ode)
        algs.append(alg)
        paths.append(pth)
        quad = quad + WEIGHTS[j] * h * lag
    return ca.Function("interval", [t0, h, xa, X, Z, ua, ub],
                       [ca.vertcat(*defects), ca.vertcat(*algs), quad, ca.vertcat(*paths),
                        fin, may])


def control_parameters(problem: Problem, u: ca.SX) -> ca.SX:
    """The parameter vector of the model with the control slots set to ``u``."""
    p = ca.SX(ca.DM(problem.p))
    for i, slot in enumerate(problem.slots):
        p[slot] = u[i]
    return p
