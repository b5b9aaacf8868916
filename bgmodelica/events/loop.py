"""The event loop: integrate between events, locate state events, hit time events exactly,
iterate the discrete equations to a fixed point, re-initialize, restart.

Continuous phases run on CasADi's SUNDIALS integrators (CVODES for ODEs, IDAS for DAEs) in a
time-scaled form ``x' = dt*f(t0 + tau*dt, ...)`` over ``tau`` in [0, 1], so one integrator
serves every segment. A segment ends at the next output point, time event or stop time. The
state-event indicators are checked at ``checks`` points inside each segment; a crossing
(a relation whose value differs from its frozen value) is bracketed and located by the
Illinois method on re-integrations from the bracket's start, to ``event_tol`` in time. The
event is taken at the right end of the bracket, where the relation has its new value.

At every event the result gets two rows with the same time: the left limit (values before
the event) and the right limit (after the event iteration and re-initialization).

The indicators and the location of crossings are in :mod:`.crossings`, dynamic state
selection between events in :mod:`.selection`.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field, replace
from typing import Any

import casadi as ca
import numpy as np

from ..backends.casadi_dae import CasadiDAE
from ..backends.casadi_init import initialize
from ..core.flatmodel import HybridPart
from ..errors import SimulationError
from . import mixed
from .crossings import CrossingMixin
from .fast import Fast
from .functions import HybridFunctions, build, run_calls
from .integrators import integrator as _integrator
from .integrators import quiet_stderr as _quiet_stderr
from .schedule import is_sample_instant, next_sample, table_coefficients
from .selection import Selection, StateSelectionMixin


class EventError(SimulationError):
    """Event handling failed: the event iteration did not converge, or events chatter."""


@dataclass
class EventOptions:
    """max_iterations: event-iteration bound; checks: indicator checks per segment;
    event_tol: time tolerance of state-event location [s] (relative to max(1, |t|));
    zeno_events: consecutive events closer than ``zeno_dt`` that count as chattering;
    relation_tol: an indicator this close to zero may keep either relation value when the
    event iteration has to search a mixed system (see :mod:`.mixed`); retry_steps: step
    budget (per output interval) of an integration that is retried shorter if it fails."""

    max_iterations: int = 100
    checks: int = 8
    event_tol: float = 1e-13
    zeno_events: int = 50
    zeno_dt: float = 1e-10
    relation_tol: float = 1e-8
    #: solver step budget of an integration that is retried on a shorter stretch if it fails
    retry_steps: int = 5000


@dataclass
class EventLog:
    times: list[float] = field(default_factory=list)
    kinds: list[str] = field(default_factory=list)
    causes: dict[str, int] = field(default_factory=dict)


class HybridSimulator(CrossingMixin, StateSelectionMixin):
    """Simulate one hybrid model for one parameter vector (see the module docstring)."""

    def __init__(self, dae: CasadiDAE, p: np.ndarray, rtol: float, atol: float,
                 max_step: float | None, max_steps: int, obs_idx: list[int],
                 options: EventOptions | None = None, selection: Selection | None = None,
                 solver_options: dict | None = None) -> None:
        if dae.hybrid is None:
            dae = replace(dae, hybrid=HybridPart())
        self.dae = dae
        self.fn: HybridFunctions = build(dae)
        self.selection = selection
        self._pending = None
        self.p = np.array(p, dtype=float)
        self.opts = options or EventOptions()
        self.obs_idx = obs_idx
        self.log = EventLog()
        self.stats: dict[str, float] = {}
        sol_opts: dict[str, Any] = {"abstol": atol, "reltol": rtol, "max_num_steps": max_steps}
        if max_step is not None:
            sol_opts["max_step_size"] = float(max_step)
        sol_opts.update(solver_options or {})
        self._step_fast = Fast(self.fn.step)
        self._ind_fast = Fast(self.fn.indicators)
        self.n_segments = 0
        self._sol_opts = sol_opts
        # a failure that will be retried should not spend the whole step budget first
        self._retry_opts = dict(sol_opts, max_num_steps=min(
            int(sol_opts.get("max_num_steps", max_steps)), self.opts.retry_steps))
        self._one: ca.Function | None = None
        hyb = dae.hybrid or HybridPart()
        nb = dae.n_base
        self.sample_slots = [nb + s.slot for s in hyb.samples]
        fp = ca.Function("sample_times", [dae.p], [ca.vertcat(
            *[ca.vertcat(s.start, s.interval) for s in hyb.samples])] if hyb.samples
            else [ca.SX(0, 1)])
        st = np.asarray(fp(self.p)).ravel()
        self.samples = [(float(st[2 * k]), float(st[2 * k + 1]), self.sample_slots[k])
                        for k in range(len(hyb.samples))]
        for start, interval, _ in self.samples:
            if not (math.isfinite(start) and math.isfinite(interval) and interval > 0):
                raise EventError(f"sample(start={start}, interval={interval}): the interval "
                                 "must be a positive finite number", 0.0)
        self.tables = [(t, nb + t.c0, nb + t.c1) for t in hyb.tables]
        self.cond_pre = np.zeros(0)
        #: per relation: how far past zero its indicator must go to change it between events
        self.hysteresis = np.zeros(len(self.fn.relations))
        nz = dae.z.numel()
        self._on_z = np.array([bool(nz and ca.depends_on(r.indicator, dae.z))
                               for r in self.fn.relations], dtype=bool)
        self._time_next = math.inf
        self._time_cause = ""
        self._stretch = math.inf        # longest stretch to integrate at once [s]
        self.recent: deque[tuple[float, str]] = deque(maxlen=self.opts.zeno_events)
        self.init_notes: list[str] = []           # of the initial conditions

    # -- public -----------------------------------------------------------------------------
    def run(self, grid: np.ndarray, progress=None) -> tuple[np.ndarray, np.ndarray, str | None]:
        """Simulate over ``grid`` (output points); returns times, rows (observed ``obs_idx``)
        and a solver failure message (None on success). ``progress(fraction)`` is called
        now and then."""
        t = float(grid[0])
        x, z = self._initialize(t)
        if self.selection is not None:
            x, z = self._initial_selection(t, x, z)
        next_report = 0.05
        times: list[float] = [t]
        rows: list[np.ndarray] = [self._obs(t, x, z)]

        def record() -> None:
            times.append(t)
            rows.append(self._obs(t, x, z))

        stop = float(grid[-1])
        k_out = 1
        failure = None
        while t < stop:
            t_event, kind = self._next_time_event(t, stop)
            t_end = t_event
            if self.selection is not None:       # short stretches: a failure costs little
                t_end = _snap(grid, k_out, min(t_event, t + self.selection.stretch))
            if t + self._stretch < t_end:        # shortened after a failed integration
                t_end = _snap(grid, k_out, t + self._stretch)
            j = k_out
            while j < len(grid) and grid[j] < t_end:
                j += 1
            try:
                t, x, z, crossed, passed = self._advance(t, t_end, x, z, grid[k_out:j])
            except RuntimeError as err:
                failure = str(err)
                break
            for t_k, row in passed:
                times.append(t_k)
                rows.append(row)
                k_out += 1
            if progress is not None and (t - grid[0]) >= next_report * (stop - grid[0]):
                progress(min(1.0, (t - grid[0]) / (stop - grid[0])))
                next_report += 0.05
            if crossed == "select":
                x, z = self._switch(t, x, z)
                if k_out < len(grid) and grid[k_out] == t:    # the switch fell on an output
                    record()
                    k_out += 1
                continue
            if crossed is None and kind is not None and t == t_event:
                crossed = kind
            if crossed is not None:
                x, z, left, right = self._event(t, x, z, crossed)
                times += [t, t]
                rows += [left, right]
                while k_out < len(grid) and grid[k_out] <= t:
                    k_out += 1
            elif t >= stop:
                record()
                k_out = len(grid)
            elif k_out < len(grid) and grid[k_out] == t:
                record()
                k_out += 1
        if progress is not None and failure is None:
            progress(1.0)
        if failure is None and self.dae.hybrid.terminal >= 0:
            x, z, left, right = self._event(t, x, z, "terminal")
            times += [t, t]
            rows += [left, right]
        return np.array(times), np.array(rows), failure

    @property
    def meta(self) -> dict[str, Any]:
        return {"event_times": list(self.log.times), "n_events": len(self.log.times),
                "integrator_calls": self.n_segments,
                "event_kinds": dict(_count(self.log.kinds)),
                "event_causes": dict(self.log.causes)}

    # -- continuous phase -------------------------------------------------------------------
    def _advance(self, t0: float, t1: float, x, z, outs: np.ndarray):
        """Integrate from t0 to t1 through the output points ``outs`` (inside (t0, t1));
        stop at the first state event. Returns (t, x, z, cause or None, output rows)."""
        fn = self.fn
        if t1 <= t0:
            return t0, x, z, None, []
        sel = self.selection
        outs = np.asarray(outs, dtype=float)
        if not fn.state_rel and len(outs) == 0 and sel is None:
            xf, zf = self._integrate_one(t0, t1, x, z)
            return t1, xf, zf, None, []
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
                with _quiet_stderr():
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
            G = np.asarray(self._ind_map(last)(ts.reshape(1, -1), X, Z, self.p))
            frozen = self.p[fn.rel_slot[fn.state_rel]].astype(bool)
            cols = np.nonzero(self._crossed(G, frozen).any(axis=0))[0]
            if cols.size:
                j = int(cols[0])
                last = j
                lo = (t0, x, z) if j == 0 else (float(ts[j - 1]), X[:, j - 1],
                                                   Z[:, j - 1] if nz else z)
                g_lo = self._ind(*lo) if j == 0 else G[:, j - 1]
                crossing = self._locate(lo[0], lo[1], lo[2], g_lo, float(ts[j]), X[:, j],
                                        Z[:, j] if nz else z, G[:, j], frozen)
        if sel is not None:
            cols = np.searchsorted(offsets, uniform)
            stop_col = self._selection_column(ts, X, Z, z, cols[cols < last])
            if stop_col is not None:
                crossing = (float(ts[stop_col]), X[:, stop_col],
                            Z[:, stop_col] if nz else z, "select")
                last = stop_col + 1
        passed = []
        for k, c in enumerate(out_cols):
            if c < last and out_offsets[k] > 0:
                tk = float(outs[k])
                passed.append((tk, self._obs(tk, X[:, c], Z[:, c] if nz else z)))
        if crossing is not None:
            return (*crossing[:3], crossing[3], passed)
        return t1, X[:, -1], Z[:, -1] if nz else z, None, passed

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
            return Fast(_integrator(self.dae, opts, list(offsets), scaled=False))
        F = cache.get(offsets)
        if F is None:
            if len(cache) > 64:
                cache.pop(next(iter(cache)))
            F = Fast(_integrator(self.dae, opts, list(offsets), scaled=False))
            cache[offsets] = F
        return F

    def _integrate_one(self, t0, t1, x, z):
        if len(x) == 0:
            return x, self._solve_z(t1, x)
        if self._one is None:
            self._one = Fast(_integrator(self.dae, self._sol_opts, [1.0], scaled=True))
            self._pe = np.zeros(len(self.p) + 2)
        pe = self._pe
        pe[:-2] = self.p
        pe[-2], pe[-1] = t0, t1 - t0
        res = self._one(x, z, pe)
        self.n_segments += 1
        return res[0].copy(), (res[1].copy() if self.dae.z.numel() else z)

    # -- time events ------------------------------------------------------------------------
    def _next_time_event(self, t: float, stop: float) -> tuple[float, str | None]:
        best, kind = math.inf, None
        for start, interval, _ in self.samples:
            ts = next_sample(start, interval, t)
            if ts < best:
                best, kind = ts, "sample"
        for table, _, _ in self.tables:
            ts = table_coefficients(table, t)[2]
            if ts < best:
                best, kind = ts, "table"
        if self._time_next < best:
            best, kind = self._time_next, "time"
        if best > stop:
            return stop, None
        return best, kind

    # -- events -----------------------------------------------------------------------------
    def _initialize(self, t0: float):
        fn = self.fn
        self._time_next = math.inf
        self._update_tables(t0)
        hyb = self.dae.hybrid
        if hyb.initial >= 0:                 # initial() holds during initialization
            self.p[self.dae.n_base + hyb.initial] = 1.0
        x, z = self._consistent(t0, None)
        for _ in range(self.opts.max_iterations):
            g, dgdt, *_ = self._step(t0, x, z)
            vals = self._relation_values(t0, g, dgdt)
            if np.array_equal(vals, self.p[fn.rel_slot]):
                break
            self.p[fn.rel_slot] = vals
            x, z = self._consistent(t0, None)
        # conditions true at the start do not fire; initial() and samples at t0 do
        out = self._step(t0, x, z)
        self.cond_pre = np.asarray(out[2], dtype=float).copy()
        if fn.initial_branch is not None:
            self.cond_pre[fn.initial_branch] = 0.0
        self._set_pre_from(out, discrete=False)     # pre() of discrete variables: start
        samples = [slot for start, interval, slot in self.samples
                   if is_sample_instant(start, interval, t0)]
        x, z, _ = self._iterate(t0, x, z, samples)
        return x, z

    def _consistent(self, t: float, x, fixed: list[tuple[int, float]] | None = None):
        """Consistent (x, z) at t: the model's initial conditions when ``x`` is None,
        else ``x`` kept (except ``fixed`` re-initialized variables) and z solved."""
        dae = self.dae
        if x is None:
            init = initialize(dae, self.p, t)
            if not self.init_notes:
                self.init_notes = list(init.notes)
            return init.x0, init.z0
        if fixed:
            d = replace(dae, x_start=np.asarray(x, dtype=float), fixed=fixed,
                        initial=dae.initial[:0], initial_labels=[])  # not initial
            init = initialize(d, self.p, t)
            return init.x0, init.z0
        return x, self._solve_z(t, x)

    def _solve_z(self, t: float, x) -> np.ndarray:
        if self.fn.alg_solver is None:
            return np.zeros(0)
        guess = getattr(self, "_z_guess", None)
        if guess is None or len(guess) != self.dae.z.numel():
            guess = self.dae.z_start
        z = np.asarray(self.fn.alg_solver(guess, np.concatenate([[t], x, self.p]))).ravel()
        self._z_guess = z
        return z

    def _step(self, t, x, z) -> list[np.ndarray]:
        """g, dgdt, cond, assign, reinit, pre, obs at (t, x, z) (copies)."""
        return [r.copy() for r in self._step_fast(t, x, z, self.p)]

    def _set_pre_from(self, out, discrete: bool = True) -> None:
        """pre() slots from the step outputs ``out``; with ``discrete`` False only those of
        continuous-time variables (discrete ones keep their start value at initialization)."""
        fn = self.fn
        if fn.pre_slot.size:
            keep = np.zeros(len(fn.pre_slot), dtype=bool) if discrete else fn.pre_discrete
            self.p[fn.pre_slot] = np.where(keep, self.p[fn.pre_slot], out[5])

    def _update_tables(self, t: float) -> None:
        for table, i0, i1 in self.tables:
            c0, c1, _ = table_coefficients(table, t)
            self.p[i0], self.p[i1] = c0, c1

    def _event(self, t: float, x, z, cause: str):
        """Handle an event at t (state, time, sample, table or terminal); returns the new
        (x, z) and the left- and right-limit rows."""
        self._note(t, cause)
        out = self._step(t, x, z)
        left = out[6][self.obs_idx]
        self._set_pre_from(out)            # left limits of every pre() source
        if self.tables:
            self._update_tables(t)
        samples = [slot for start, interval, slot in self.samples
                   if is_sample_instant(start, interval, t)]
        if cause == "terminal":
            self.p[self.dae.n_base + self.dae.hybrid.terminal] = 1.0
        before = (out[0], self.p[self.fn.rel_slot].copy())
        x, z, out = self._iterate(t, x, z, samples, before)
        return x, z, left, out[6][self.obs_idx]

    def _iterate(self, t: float, x, z, samples: list[int], before=None):
        """Event iteration to a fixed point of the discrete equations; returns (x, z) and the
        step outputs at the converged point. ``before``: the indicators and relation values
        before the event."""
        fn = self.fn
        dae = self.dae
        nb = dae.n_base
        for slot in samples:
            self.p[slot] = 1.0
        flags = bool(samples) or dae.hybrid.initial >= 0 and self.p[nb + dae.hybrid.initial]
        changing: list[str] = []
        cycle = _Cycle(len(fn.rel_slot))
        for _ in range(self.opts.max_iterations):
            if fn.alg_solver is not None:
                z = self._solve_z(t, x)
            out = self._step(t, x, z)
            g, dgdt, cond, assign, reinit, pre_src, _ = out
            changing = []
            rel = self._relation_values(t, g, dgdt)
            moved = cycle.moved(rel, self.p[fn.rel_slot], g, self.opts.relation_tol)
            if moved.any():
                changing += [fn.relations[k].text for k in np.nonzero(moved)[0][:4]]
                if cycle.closes(self.p[fn.rel_slot], rel, moved):
                    rel = self._settle(t, x, cycle)
                self.p[fn.rel_slot] = rel
                continue
            cycle.reset()
            fired = []
            for ids in fn.branch_of:
                for b in ids:
                    if cond[b] and not self.cond_pre[b]:
                        fired.append(b)
                        break
            self.cond_pre = cond
            if fn.calls is not None and any(fn.call_of[b] for b in fired):
                run_calls(fn, t, x, z, self.p, fired)
                out = self._step(t, x, z)
                assign, reinit, pre_src = out[3], out[4], out[5]
            new_x, fixed = np.array(x, dtype=float), []
            for b in fired:
                for pidx, pos in fn.assign_of[b]:
                    if self.p[pidx] != assign[pos]:
                        changing.append(dae.discretes[pidx - nb].name)
                    self.p[pidx] = assign[pos]
                for name, pos in fn.reinit_of[b]:
                    rep, sign = dae.aliases.get(name, (name, 1.0))
                    value = sign * reinit[pos]
                    changing.append(f"reinit({name})")
                    if rep in dae.state_names:
                        new_x[dae.state_names.index(rep)] = value
                    else:
                        fixed.append((dae.observed_index[rep], value))
            if fn.pre_slot.size:
                # discrete variables defined by equations: pre() must catch up with them
                lag = fn.pre_discrete & (pre_src != self.p[fn.pre_slot])
                changing += [dae.hybrid.pre[k][1] for k in np.nonzero(lag)[0][:4]]
                self.p[fn.pre_slot] = np.where(fn.pre_discrete, pre_src, self.p[fn.pre_slot])
            if fixed:
                fixed += [(dae.observed_index[n], float(new_x[i]))
                          for i, n in enumerate(dae.state_names) if new_x[i] != x[i]]
                x, z = self._consistent(t, new_x, fixed)
            elif fired:
                x = new_x
            if not changing:
                break
        else:
            names = ", ".join(dict.fromkeys(changing))
            raise EventError(
                f"event iteration at t = {t:g} s did not converge after "
                f"{self.opts.max_iterations} iterations: {names} keep changing (a discrete "
                "equation without pre() feeding back on itself?)", t)
        if flags:
            # after the instant: clocks fall and initial() ends; conditions are re-armed
            for slot in samples:
                self.p[slot] = 0.0
            if dae.hybrid.initial >= 0:
                self.p[nb + dae.hybrid.initial] = 0.0
            out = self._step(t, x, z)
            self.cond_pre = out[2]
            self._set_pre_from(out)
        self._schedule_time_relations(t, out[0], out[1])
        self._keep_settled(t, out[0], out[1], before)
        return x, z, out

    def _keep_settled(self, t: float, g: np.ndarray, dgdt: np.ndarray, before) -> None:
        """Relations at rounding level change again only once their indicator is past the
        tolerance: one left against the sign of its indicator (settled within the tolerance,
        e.g. a friction element sliding with zero relative acceleration), and one on
        algebraic variables whose crossing vanished when they were solved again at the event
        (the integrator's algebraic error made it)."""
        fn = self.fn
        value = self.p[fn.rel_slot]
        tol = self.opts.relation_tol
        keep = self._relation_values(t, g, dgdt) != value
        if before is not None:
            g_left, frozen = before
            vanished = (self._relation_values(t, g_left, dgdt) != frozen) & (value == frozen)
            keep |= vanished & (np.abs(g) <= tol) & (np.abs(g_left) <= tol) & self._on_z
        self.hysteresis = np.where(keep, tol, 0.0)

    def _settle(self, t: float, x, cycle: _Cycle) -> np.ndarray:
        """Relation values of a mixed system whose event iteration cycles (see
        :mod:`.mixed`); raises :class:`EventError` when no combination is consistent.

        Under each combination the discrete variables defined by equations settle first
        (their pre() catches up, as in the event iteration with the relations frozen). A
        combination may be consistent only with the pre() values another one leads to (a
        friction element that keeps sliding once it started: ``pre(startForward)``), so
        the search is repeated from each of those."""
        fn = self.fn
        saved = self.p[fn.rel_slot].copy()
        pre_slot, lagging = fn.pre_slot, fn.pre_discrete
        saved_pre = self.p[pre_slot].copy()
        reached: dict[bytes, np.ndarray] = {}

        def evaluate(trial: np.ndarray):
            self.p[fn.rel_slot] = trial
            self.p[pre_slot] = start_pre
            for _ in range(self.opts.max_iterations):
                z = self._solve_z(t, x) if fn.alg_solver is not None else np.zeros(0)
                g, dgdt, *_, pre_src, _ = self._step(t, x, z)
                moved = lagging & (pre_src != self.p[pre_slot])
                if not moved.any():
                    break
                self.p[pre_slot] = np.where(lagging, pre_src, self.p[pre_slot])
            reached.setdefault(self.p[pre_slot].tobytes(), self.p[pre_slot].copy())
            return self._relation_values(t, g, dgdt), g

        free = list(np.nonzero(cycle.free)[0])
        names = ", ".join(dict.fromkeys(fn.relations[k].text for k in free[:6]))
        if len(free) > mixed.MAX_FREE:
            raise EventError(f"event iteration at t = {t:g} s cycles through {len(free)} "
                             f"relations ({names}, ...), too many to search", t)
        start_pre = saved_pre
        found, miss = mixed.search(evaluate, cycle.first, free, self.opts.relation_tol)
        for start_pre in list(reached.values()) if found is None else []:
            if np.array_equal(start_pre, saved_pre):
                continue
            found, other = mixed.search(evaluate, cycle.first, free, self.opts.relation_tol)
            miss = min(miss, other)
            if found is not None:
                break
        self.p[fn.rel_slot] = saved
        if found is None:
            self.p[pre_slot] = saved_pre
            raise EventError(f"event iteration at t = {t:g} s: no consistent values of "
                             f"{names} (the mixed system they close has no solution; the "
                             f"closest misses by {miss:.3g})", t)
        evaluate(found)                     # the pre() values the combination settles to
        self.p[fn.rel_slot] = saved
        cycle.settled(found)
        return found

    def _note(self, t: float, cause: str) -> None:
        kind = cause.split(":", 1)[0]
        self.log.times.append(t)
        self.log.kinds.append(kind)
        key = cause.split(":", 1)[1] if ":" in cause else (
            self._time_cause if kind == "time" else kind)
        self.log.causes[key] = self.log.causes.get(key, 0) + 1
        self.recent.append((t, key))
        if len(self.recent) == self.recent.maxlen:
            span = self.recent[-1][0] - self.recent[0][0]
            if span <= self.opts.zeno_dt * max(1.0, abs(t)):
                worst = max(set(k for _, k in self.recent),
                            key=lambda k: sum(1 for _, c in self.recent if c == k))
                raise EventError(
                    f"chattering at t = {t:.12g} s: {len(self.recent)} events within "
                    f"{span:.3g} s, triggered by {worst}; the model switches back and forth "
                    "without time passing (Zeno behaviour). Add hysteresis or a stuck/rest "
                    "mode", t)

    def _obs(self, t, x, z) -> np.ndarray:
        return self._step_fast(t, x, z, self.p)[6][self.obs_idx]


class _Cycle:
    """Bookkeeping of relation values within one event iteration: the first values, the
    combinations seen, which relations moved, and which were settled by a search."""

    def __init__(self, n: int) -> None:
        self.first: np.ndarray | None = None
        self.seen: set[bytes] = set()
        self.free = np.zeros(n, dtype=bool)
        self.tolerant = np.zeros(n, dtype=bool)

    def moved(self, rel: np.ndarray, frozen: np.ndarray, g: np.ndarray, tol: float):
        """Relations whose value changes; a settled one changes only beyond ``tol``."""
        if self.first is None:
            self.first = rel.copy()
        return (rel != frozen) & ~(self.tolerant & (np.abs(g) <= tol))

    def closes(self, frozen: np.ndarray, rel: np.ndarray, moved: np.ndarray) -> bool:
        """Record a step from ``frozen`` to ``rel``; True when ``rel`` was seen before."""
        self.seen.add(frozen.tobytes())
        self.free |= moved
        return rel.tobytes() in self.seen

    def settled(self, rel: np.ndarray) -> None:
        self.tolerant |= self.free
        self.first = rel.copy()
        self.seen.clear()
        self.free[:] = False

    def reset(self) -> None:
        """The relations are stable: discrete changes may start a new cycle."""
        self.seen.clear()
        self.free[:] = False


def _snap(grid: np.ndarray, k: int, t: float) -> float:
    """``t`` [s], or the output time ``grid[k:]`` within a rounding error of it."""
    j = int(np.searchsorted(grid, t))
    for i in (j - 1, j):
        if k <= i < len(grid) and abs(grid[i] - t) <= 1e-12 * max(1.0, abs(t)) + 1e-15:
            return float(grid[i])
    return t


def _count(items: list[str]) -> dict[str, int]:
    out: dict[str, int] = {}
    for k in items:
        out[k] = out.get(k, 0) + 1
    return out
