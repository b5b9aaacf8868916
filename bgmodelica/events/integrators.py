"""The CasADi integrators of the event loop (CVODES for ODEs, IDAS for DAEs), built once per
settings and reused for every segment, the segments between events, and a guard that keeps
SUNDIALS' own error messages off the terminal while a failure is expected and retried."""

from __future__ import annotations

import contextlib
import math
import os
import sys

import casadi as ca
import numpy as np

from ..backends.casadi_dae import CasadiDAE
from .fast import Fast

#: output points between two events from which the recorded variables are evaluated at
#: once (below, a call per point costs less than making the mapped function)
_MAPPED_FROM = 32


@contextlib.contextmanager
def quiet_stderr():
    """Silence C-level stderr (SUNDIALS prints its error messages there)."""
    try:
        fd = sys.stderr.fileno()
    except (AttributeError, OSError, ValueError):
        yield
        return
    sys.stderr.flush()
    saved = os.dup(fd)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, fd)
        yield
    finally:
        os.dup2(saved, fd)
        os.close(saved)
        os.close(devnull)


def integrator(dae: CasadiDAE, opts: dict, tout: list[float], scaled: bool) -> ca.Function:
    """CVODES (ODE) or IDAS (DAE) integrator of the model from ``t0``: over ``tau`` in [0, 1]
    with ``t = t0 + tau*dt`` when ``scaled`` (p = [p, t0, dt]), else over offsets ``tau``
    with ``t = t0 + tau`` (p = [p, t0]). Cached in ``dae.cache`` by its settings."""
    key = ("hybrid_integrator", scaled, tuple(tout),
           tuple(sorted((k, repr(v)) for k, v in opts.items())))
    if key in dae.cache:
        return dae.cache[key]
    t0, dt, tau = ca.SX.sym("t0"), ca.SX.sym("dt"), ca.SX.sym("tau")
    t_of = t0 + tau * dt if scaled else t0 + tau
    scale = dt if scaled else 1
    x, ode = dae.x, dae.ode
    problem = {"x": x, "p": ca.vertcat(dae.p, t0, dt) if scaled else ca.vertcat(dae.p, t0),
               "t": tau, "ode": scale * ca.substitute(ode, dae.t, t_of)}
    solver = "cvodes"
    solver_opts = dict(opts, disable_internal_warnings=True, show_eval_warnings=False)
    if dae.z.numel():
        problem.update(z=dae.z, alg=ca.substitute(dae.alg, dae.t, t_of))
        solver = "idas"
        solver_opts["calc_ic"] = True
        # algebraic variables follow the states: leave them out of the local error test, whose
        # absolute tolerance their solve noise (a stiff switch) can exceed on every step
        solver_opts.setdefault("suppress_algebraic", True)
    F = ca.integrator("segment", solver, problem, 0.0, [float(v) for v in tout], solver_opts)
    if scaled:
        dae.cache[key] = F
    return F


class SegmentMixin:
    """Continuous phases of the event loop: integrate a segment through its output points
    up to the first state event (mixed into :class:`~.loop.HybridSimulator`)."""

    def _advance(self, t0: float, t1: float, x, z, outs: np.ndarray):
        """Integrate from t0 to t1 through the output points ``outs`` (inside (t0, t1));
        stop at the first state event. Returns (t, x, z, cause or None, (output times passed,
        their rows))."""
        fn = self.fn
        if t1 <= t0:
            return t0, x, z, None, (outs[:0], [])
        sel = self.selection
        outs = np.asarray(outs, dtype=float)
        if not fn.state_rel and len(outs) == 0 and sel is None:
            xf, zf = self._integrate_one(t0, t1, x, z)
            return t1, xf, zf, None, (outs[:0], [])
        checks = self.opts.checks if fn.state_rel else 1
        if sel is not None:
            checks = max(checks, int(math.ceil((t1 - t0) / sel.spacing - 1e-9)))
        out_offsets = outs - t0
        uniform = (t1 - t0) * np.arange(1, checks + 1) / checks
        if len(out_offsets):      # a check a rounding error from an output point is that point
            i = np.searchsorted(out_offsets, uniform[:-1]).clip(1, len(outs) - 1)
            pick = np.where(uniform[:-1] - out_offsets[i - 1] < out_offsets[i] - uniform[:-1],
                            out_offsets[i - 1], out_offsets[i]) if len(outs) > 1 else out_offsets
            close = np.abs(uniform[:-1] - pick) <= 1e-9 * (t1 - t0)
            uniform[:-1] = np.where(close, pick, uniform[:-1])
        offsets = np.union1d(out_offsets, uniform)
        offsets = offsets[offsets > 0]
        retry = (sel is not None or bool(fn.state_rel)) and t1 - t0 >= 1e-12 * max(1.0, abs(t0))
        try:
            if not retry:
                X, Z = self._columns(t0, x, z, offsets)
            else:        # a failure is expected now and then (retried): keep SUNDIALS quiet
                with quiet_stderr():
                    X, Z = self._columns(t0, x, z, offsets, self._retry_opts)
        except RuntimeError:
            # with dynamic state selection the current choice may fail before the next pivot
            # check, and a branch kept past a crossing not yet checked may be singular (a
            # force ~ 1/v beyond the switch to its regularization): integrate a shorter
            # stretch, whose checks switch in time
            if not retry:
                raise
            t_short = t0 + 0.25 * (t1 - t0)
            self._stretch = t_short - t0
            return self._advance(t0, t_short, x, z, outs[outs < t_short])
        self._stretch = 2 * self._stretch if t1 - t0 >= self._stretch else self._stretch
        nz = self.dae.z.numel()
        ts = t0 + offsets
        out_cols = np.searchsorted(offsets, out_offsets)
        inside = out_offsets > 0
        ts[out_cols[inside]] = outs[inside]        # output times exactly as requested
        ts[-1] = t1
        last = len(offsets)
        crossing = None
        if fn.state_rel:
            frozen = self.p[fn.rel_slot[fn.state_rel]].astype(bool)
            found = self._first_crossing(ts, X, Z if nz else np.zeros((0, len(ts))), frozen)
            if found is not None:
                j, g_before, g_j = found
                last = j
                lo = (t0, x, z) if j == 0 else (float(ts[j - 1]), X[:, j - 1],
                                                   Z[:, j - 1] if nz else z)
                g_lo = self._ind(*lo) if j == 0 else g_before
                crossing = self._locate(lo[0], lo[1], lo[2], g_lo, float(ts[j]), X[:, j],
                                        Z[:, j] if nz else z, g_j, frozen)
        if sel is not None:
            cols = np.searchsorted(offsets, uniform)
            stop_col = self._selection_column(ts, X, Z, z, cols[cols < last])
            if stop_col is not None:
                crossing = (float(ts[stop_col]), X[:, stop_col],
                            Z[:, stop_col] if nz else z, "select")
                last = stop_col + 1
        keep = (out_cols < last) & inside
        passed = self._observe(outs[keep], X[:, out_cols[keep]],
                               Z[:, out_cols[keep]] if nz else None, z)
        if crossing is not None:
            return (*crossing[:3], crossing[3], passed)
        return t1, X[:, -1], Z[:, -1] if nz else z, None, passed

    def _observe(self, times: np.ndarray, X: np.ndarray, Z: np.ndarray | None,
                 z: np.ndarray) -> tuple[np.ndarray, np.ndarray | list]:
        """The output times passed and the recorded variables there, one row each: point by
        point for a few, in one mapped evaluation for many (a long run between events has
        thousands of output points)."""
        if len(times) < _MAPPED_FROM:
            return times, [self._obs(float(tk), X[:, c], Z[:, c] if Z is not None else z)
                           for c, tk in enumerate(times)]
        from ..simulate import observer

        zs = Z if Z is not None else np.zeros((0, len(times)))
        return times, observer(self.dae, self.obs_idx)(times, X, zs, self.p)

    def _columns(self, t0: float, x, z, offsets: np.ndarray, opts: dict | None = None):
        """States and algebraic variables at ``t0 + offsets`` (one integrator call with the
        solver options ``opts``, by default the run's, or algebraic solves for a model without
        states)."""
        nz = self.dae.z.numel()
        n_t = len(offsets)
        if len(x) == 0:
            Z = np.zeros((nz, n_t))
            for c, off in enumerate(offsets):
                Z[:, c] = self._solve_z(t0 + float(off), x)
            return np.zeros((0, n_t)), Z
        F = self._shifted(tuple(offsets), opts or self._sol_opts)
        res = F(x, z, np.concatenate([self.p, [t0]]))
        self.n_segments += 1
        X = res[0].reshape(n_t, len(x)).T.copy()
        Z = res[1].reshape(n_t, nz).T.copy() if nz else np.zeros((0, n_t))
        return X, Z

    def _shifted(self, offsets: tuple[float, ...], opts: dict) -> Fast:
        """An integrator from t0 (a parameter) to ``t0 + offsets`` (cached by options)."""
        key = ("shifted", tuple(sorted((k, repr(v)) for k, v in opts.items())))
        cache = self.dae.cache.setdefault(key, {})
        if len(offsets) > 64:                       # long runs: not worth keeping
            return Fast(integrator(self.dae, opts, list(offsets), scaled=False))
        F = cache.get(offsets)
        if F is None:
            if len(cache) > 64:
                cache.pop(next(iter(cache)))
            F = Fast(integrator(self.dae, opts, list(offsets), scaled=False))
            cache[offsets] = F
        return F

    def _integrate_one(self, t0, t1, x, z):
        if len(x) == 0:
            return x, self._solve_z(t1, x)
        if self._one is None:
            self._one = Fast(integrator(self.dae, self._sol_opts, [1.0], scaled=True))
            self._pe = np.zeros(len(self.p) + 2)
        pe = self._pe
        pe[:-2] = self.p
        pe[-2], pe[-1] = t0, t1 - t0
        res = self._one(x, z, pe)
        self.n_segments += 1
        return res[0].copy(), (res[1].copy() if self.dae.z.numel() else z)

    # -- time events ------------------------------------------------------------------------
