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
from .crossings import CrossingMixin
from .fast import Fast
from .functions import HybridFunctions, build, run_calls, solve_algebraic
from .integrators import SegmentMixin
from .mixed import Cycle, EventError, MixedSystemMixin
from .schedule import is_sample_instant, next_sample, table_coefficients
from .selection import Selection, StateSelectionMixin


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


class HybridSimulator(CrossingMixin, StateSelectionMixin, MixedSystemMixin, SegmentMixin):
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
        #: per branch: the p indices its assignments write and their positions in ``assign``
        self._assigns = [(np.array([k for k, _ in a], dtype=np.int64),
                          np.array([q for _, q in a], dtype=np.int64)) for a in self.fn.assign_of]
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
            t_passed, values = passed
            if len(t_passed):
                times += t_passed.tolist()
                rows += values if isinstance(values, list) else [values]    # (a block)
                k_out += len(t_passed)
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
        return np.array(times), np.vstack(rows), failure

    @property
    def meta(self) -> dict[str, Any]:
        return {"event_times": list(self.log.times), "n_events": len(self.log.times),
                "integrator_calls": self.n_segments,
                "event_kinds": dict(_count(self.log.kinds)),
                "event_causes": dict(self.log.causes)}

    # -- continuous phase -------------------------------------------------------------------
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

    def _solve_z(self, t: float, x, guess=None) -> np.ndarray:
        """Algebraic variables at (t, x) from ``guess`` (at an event the values just before
        it), else from the last solution or the start values (see :func:`.solve_algebraic`)."""
        if self.fn.alg_solver is None:
            return np.zeros(0)
        for g in (guess, getattr(self, "_z_guess", None), self.dae.z_start):
            if g is not None and len(g) == self.dae.z.numel():
                break
        z = solve_algebraic(self.fn, g, np.concatenate([[t], x, self.p]))
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
        cycle = Cycle(len(fn.rel_slot))
        for _ in range(self.opts.max_iterations):
            if fn.alg_solver is not None:
                z = self._solve_z(t, x, z)
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
                pidx, pos = self._assigns[b]
                if pidx.size:                  # at once: a sampled buffer has thousands
                    value = assign[pos]
                    moved = np.flatnonzero(self.p[pidx] != value)
                    changing += [dae.discretes[k - nb].name for k in pidx[moved[:4]]]
                    self.p[pidx] = value
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
