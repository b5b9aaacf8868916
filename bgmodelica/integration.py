"""Running CasADi's integrators over an output grid: construction (cached per model and
settings), the consistent initial derivative for IDAS, chunked runs with progress, and
numpy results without DM conversions."""

from __future__ import annotations

from typing import Any

import casadi as ca
import numpy as np

from .backends.casadi_dae import CasadiDAE
from .errors import ParameterError
from .events.fast import Fast


def _integrator(dae: CasadiDAE, solver: str, t0: float, tout: np.ndarray, opts: dict):
    x, ode = dae.x, dae.ode
    if x.numel() == 0:                      # purely algebraic model: integrate a dummy state
        x, ode = ca.SX.sym("_dummy"), ca.SX(0)
    problem = {"x": x, "p": dae.p, "t": dae.t, "ode": ode}
    if dae.z.numel():
        if solver != "idas":
            raise ParameterError(f"solver {solver!r} cannot handle the algebraic variables "
                                 f"{', '.join(dae.algebraic_names[:5])}; use 'idas'")
        problem.update(z=dae.z, alg=dae.alg)
    return ca.integrator("sim", solver, problem, float(t0), list(map(float, tout)), opts)


def _cached_integrator(dae: CasadiDAE, solver: str, t0: float, tout: np.ndarray, opts: dict):
    """The integrator for these settings, reused by repeated runs of the same model."""
    key = ("integrator", solver, float(t0), np.asarray(tout, dtype=float).tobytes(),
           tuple(sorted((k, repr(v)) for k, v in opts.items())))
    cache = dae.cache.setdefault("integrators", {})
    if key not in cache:
        if len(cache) >= 4:
            cache.pop(next(iter(cache)))
        cache[key] = _integrator(dae, solver, t0, tout, opts)
    return cache[key]


def _xdot(dae: CasadiDAE, t: float, x, z, p) -> list[float]:
    """Consistent initial state derivative for IDAS (we skip IDACalcIC: x0, z0 are solved)."""
    if "xdot" not in dae.cache:
        dae.cache["xdot"] = ca.Function("xdot0", [dae.t, dae.x, dae.z, dae.p], [dae.ode])
    f = dae.cache["xdot"]
    return [float(v) for v in np.asarray(f(t, x, z, p)).ravel()]


def _integrate(dae: CasadiDAE, solver: str, grid: np.ndarray, x0, z0, p, opts, progress):
    nx = max(dae.x.numel(), 1)
    x0 = x0 if dae.x.numel() else np.zeros(1)
    chunks = [grid] if progress is None else np.array_split(grid, min(20, len(grid) - 1))
    if progress is not None:          # overlapping chunks: each starts where the last ended
        chunks = [np.concatenate(([chunks[k - 1][-1]], c)) if k else c
                  for k, c in enumerate(chunks)]
    xs, zs = [x0.reshape(nx, 1)], [np.asarray(z0).reshape(-1, 1)]
    # one chunk (the usual run): the solver writes the states and algebraic variables
    # straight into the trajectories (their columns follow x0, z0), instead of into its own
    # buffers copied afterwards; a large model's trajectory is then held once (800 MB for
    # 1e5 states at 1001 points)
    nz = len(z0)
    single = len(chunks) == 1 and len(grid) > 1
    whole_x = np.empty((len(grid), nx)) if single else None
    whole_z = np.empty((len(grid), nz)) if single and nz else None
    stats: dict[str, Any] = {}
    failure = None
    xk, zk = x0, z0
    for chunk in chunks:
        if len(chunk) < 2:
            continue
        try:
            chunk_opts = dict(opts)
            if solver != "idas":
                chunk_opts.pop("calc_ic", None)      # an IDAS-only option
            if solver == "idas" and dae.x.numel():
                chunk_opts["init_xdot"] = _xdot(dae, chunk[0], xk, zk, p)
            F = _cached_integrator(dae, solver, chunk[0], chunk[1:], chunk_opts)
            into = {}
            for name, whole, first in (("xf", whole_x, x0), ("zf", whole_z, z0)):
                if whole is not None:
                    whole[0] = np.asarray(first, dtype=float).ravel()
                    into[name] = whole[1:].reshape(-1)
            xf, zf, run_stats = _run_integrator(F, xk, zk, p, nx, nz, len(chunk) - 1, into)
        except RuntimeError as err:
            failure = str(err)
            break
        xs.append(xf)
        zs.append(zf)
        xk, zk = xf[:, -1], zf[:, -1] if len(z0) else z0
        for key, val in run_stats.items():
            if isinstance(val, (int, float)) and not isinstance(val, bool):
                stats[key] = stats.get(key, 0) + val
        if progress is not None:
            progress(float((chunk[-1] - grid[0]) / (grid[-1] - grid[0])))
    if failure is not None and progress is None and len(grid) > 2:
        return _integrate(dae, solver, grid, x0, z0, p, opts, lambda _f: None)
    if not dae.x.numel():
        X = np.zeros((0, sum(a.shape[1] for a in xs)))
    elif whole_x is not None and failure is None:
        X = whole_x.T                                 # (nx, points), no copy
    else:
        X = np.hstack(xs)[: dae.x.numel()]
    Z = whole_z.T if whole_z is not None and failure is None else np.hstack(zs)
    return X, Z, stats, failure


def _run_integrator(F: ca.Function, x0, z0, p, nx: int, nz: int, n_out: int,
                    into: dict[str, np.ndarray] | None = None):
    """``F(x0, z0, p)`` as numpy ``(xf, zf, stats)``, ``nx x n_out`` and ``nz x n_out``, through
    bound buffers (:class:`~bgmodelica.events.fast.Fast`): converting CasADi's DM results
    costs more than integrating a large model. ``into``: flat buffers the outputs ``"xf"``,
    ``"zf"`` are written to (the results are then their views). A failed run is repeated
    through the plain call, whose exception carries the solver's message."""
    fast = Fast(F, {F.index_out(name): buf for name, buf in (into or {}).items()})
    fast.args[F.index_in("x0")][:] = np.asarray(x0, dtype=float).ravel()
    if nz:
        fast.args[F.index_in("z0")][:] = np.asarray(z0, dtype=float).ravel()
    fast.args[F.index_in("p")][:] = np.asarray(p, dtype=float).ravel()
    try:
        fast()
    except RuntimeError:
        F(x0=x0, z0=z0, p=p)           # raises with the message
        raise
    # views of this call's own buffers (a fresh Fast per run): the caller's hstack copies once
    xf = fast.res[F.index_out("xf")].reshape(n_out, nx).T
    zf = fast.res[F.index_out("zf")].reshape(n_out, nz).T if nz else np.zeros((0, n_out))
    return xf, zf, fast.stats()
