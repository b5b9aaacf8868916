"""Model Exchange FMUs integrated by the master, with events.

:class:`ModelExchangeUnit` advances the FMU with SciPy's Radau IIA (order 5, L-stable, error
controlled with ``rtol``/``atol``), the inputs following the master's ramp. Within a macro
step it

* locates **state events** (a sign change of an event indicator) with the Illinois method,
  to ``event_tol`` (relative) seconds, each trial state integrated from the step's start at
  the unit's tolerances (not the dense output, whose error an indicator may amplify), and
  stops right after the crossing;
* stops exactly at **time events** (``nextEventTime``);
* handles **step events** (``completedIntegratorStep`` asking for event mode);
* iterates each event to a fixed point (``newDiscreteStates`` / ``updateDiscreteStates``),
  re-reads the states when the FMU changed them, and honours a terminate request;
* sets discrete inputs (Integer, Boolean, discrete Real) only at event instants, in event mode.

With ``euler_step`` it integrates instead with forward Euler at that fixed step, an event
taken at the end of the step where an indicator changed sign (no location): the algorithm of
the FMI standard's example importer, with which the Modelica Reference-FMUs results were made.
"""

from __future__ import annotations

import ctypes
import functools
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from .archive import _one_line
from .errors import CosimStepError
from .units import _Unit
from .values import PortAccess


def _crossed(z0: np.ndarray, z1: np.ndarray) -> np.ndarray:
    """Indicators whose sign (> 0 or <= 0, as FMI counts a zero) changed."""
    return (z0 > 0) != (z1 > 0)


class ModelExchangeUnit(_Unit):
    """A Model Exchange FMU instance integrated by the master (SciPy Radau, with events)."""

    interface = "me"

    def __init__(self, *args: Any, rtol: float = 1e-8, atol: float = 1e-10,
                 event_tol: float = 1e-12, euler_step: float | None = None, **kw: Any) -> None:
        super().__init__(*args, **kw)
        self.euler_step = euler_step
        self.rtol = rtol
        self.atol = atol
        self.event_tol = event_tol
        self.nx = self.info.n_states
        self.nz = self.info.n_event_indicators
        self.x = np.zeros(self.nx)
        self._z = np.zeros(self.nz)
        self._h_last: float | None = None
        self.n_rhs = 0
        self.next_event: float | None = None
        self.event_times: list[float] = []
        ins = [self.info.variables[n] for n in self.input_names]
        disc = [v.variability != "continuous" or v.type != "Real" for v in ins]
        self._cont = np.flatnonzero(~np.array(disc, dtype=bool)) if ins else np.zeros(0, int)
        self._disc = np.flatnonzero(np.array(disc, dtype=bool)) if ins else np.zeros(0, int)
        self._in_cont = PortAccess(self.info.fmi_version, [ins[i] for i in self._cont])
        self._in_disc = PortAccess(self.info.fmi_version, [ins[i] for i in self._disc])
        self._disc_set: np.ndarray | None = None
        self._fmi2 = self.info.fmi_version == 2

    # inputs ---------------------------------------------------------------------------------
    def _set_inputs(self, values: np.ndarray) -> None:
        """Continuous inputs at any time; discrete ones only when they change, at an event."""
        values = np.asarray(values, dtype=float)
        if len(self._cont):
            self._in_cont.set(self.fmu, values[self._cont])
        if len(self._disc):
            d = values[self._disc]
            if self._disc_set is None or not np.array_equal(d, self._disc_set):
                if self._disc_set is None:            # initialization: any mode will do
                    self._in_disc.set(self.fmu, d)
                else:
                    self._event(lambda: self._in_disc.set(self.fmu, d))
                self._disc_set = d.copy()

    def set_text(self, values: Mapping[str, Any]) -> None:
        """String/Binary inputs are discrete: set in event mode once the run has started."""
        if values and getattr(self, "_running", False):
            self._event(lambda: self.set_values(values))
        else:
            self.set_values(values)

    def _set_continuous_inputs(self, values: np.ndarray) -> None:
        if len(self._cont):
            self._in_cont.set(self.fmu, np.asarray(values, dtype=float)[self._cont])

    # set-up -----------------------------------------------------------------------------------
    def setup(self, start: float, stop: float, parameters: dict[str, float],
              inputs: np.ndarray, tolerance: float | None = None) -> None:
        self._instantiate(slave=False)
        fmu = self.fmu
        self.time = start
        if self._fmi2:
            self._call(fmu.setupExperiment, tolerance, start, stop)
            self.set_values(parameters)
            self.set_inputs(inputs)
            self._call(fmu.enterInitializationMode)
            self._call(fmu.exitInitializationMode)
        else:
            self.set_values(parameters)
            self.set_inputs(inputs)
            self._call(fmu.enterInitializationMode, tolerance, start, stop)
            self._call(fmu.exitInitializationMode)
        if self.nx == 0 and not self._fmi2:
            self.nx = int(self._call(fmu.getNumberOfContinuousStates))
            self.x = np.zeros(self.nx)
        self._iterate()                       # the initial event iteration (event mode)
        self._get_states()
        self._running = True

    # FMU calls ----------------------------------------------------------------------------------
    def _ptr(self, arr: np.ndarray) -> Any:
        return arr.ctypes.data_as(ctypes.POINTER(ctypes.c_double))

    def _get_states(self) -> None:
        if self.nx:
            self._call(self.fmu.getContinuousStates, self._ptr(self.x), self.nx)

    def _set_state(self, t: float, x: np.ndarray) -> None:
        self.fmu.setTime(t)
        if self.nx:
            xs = np.ascontiguousarray(x, dtype=float)
            self.fmu.setContinuousStates(self._ptr(xs), self.nx)

    def _rhs(self, t: float, x: np.ndarray, u0: np.ndarray, slope: np.ndarray | None,
             t0: float) -> np.ndarray:
        self._set_state(t, x)
        self._set_continuous_inputs(u0 if slope is None else u0 + slope * (t - t0))
        out = np.empty(self.nx)
        if self._fmi2:
            self.fmu.getDerivatives(self._ptr(out), self.nx)
        else:
            self.fmu.getContinuousStateDerivatives(self._ptr(out), self.nx)
        self.n_rhs += 1
        return out

    def _indicators(self, t: float, x: np.ndarray, u0: np.ndarray, slope: np.ndarray | None,
                    t0: float) -> np.ndarray:
        self._set_state(t, x)
        self._set_continuous_inputs(u0 if slope is None else u0 + slope * (t - t0))
        z = np.empty(self.nz)
        if self.nz:
            self.fmu.getEventIndicators(self._ptr(z), self.nz)
        return z

    # events -------------------------------------------------------------------------------------
    def _iterate(self) -> None:
        """Event iteration in event mode, then back to continuous-time mode."""
        fmu = self.fmu
        for _ in range(1000):
            if self._fmi2:
                needed, term, _nom, changed, defined, t_next = self._call(fmu.newDiscreteStates)
            else:
                needed, term, _nom, changed, defined, t_next = self._call(
                    fmu.updateDiscreteStates)
            if term:
                self._request_stop("the FMU asked to terminate the simulation at an event")
                break
            if not needed:
                break
        else:
            raise CosimStepError(f"element {self.name!r}: event iteration does not converge at "
                                 f"t={self.time:g} (1000 iterations)", self.name, self.time)
        self.next_event = float(t_next) if defined else None
        if not self.terminated:
            self._call(fmu.enterContinuousTimeMode)
        if changed or not self.event_times:
            self._get_states()

    def _event(self, action: Any = None) -> None:
        """Handle an event at ``self.time``: event mode, ``action`` (e.g. set discrete
        inputs), event iteration, continuous-time mode, states re-read if they changed."""
        self._call(self.fmu.enterEventMode)
        if action is not None:
            self._call(action)
        self._iterate()
        self._get_states()
        self.event_times.append(float(self.time))

    def _request_stop(self, why: str) -> None:
        self.terminated = True
        self.stop_reason = why

    def _locate(self, state_at: Any, ta: float, tb: float, za: np.ndarray, zb: np.ndarray,
                args: tuple) -> float:
        """The time just after the first crossing in ``(ta, tb]``: the Illinois method (false
        position whose endpoint value is halved when that endpoint is kept twice), each trial
        kept within the middle 80 % of the bracket. ``state_at(t)`` gives the state at t, the
        FMU the indicators."""
        tol = self.event_tol * max(1.0, abs(tb))
        fa, fb = za.copy(), zb.copy()            # the (possibly halved) values for the secant
        kept = 0                                 # -1: a kept last time, +1: b kept
        while tb - ta > tol:
            crossed = np.flatnonzero(_crossed(za, zb))
            # the earliest secant estimate over the crossing indicators picks the next split
            cand = []
            for i in crossed:
                d = fb[i] - fa[i]
                cand.append(ta - fa[i] * (tb - ta) / d if d != 0 else 0.5 * (ta + tb))
            tm = min(max(min(cand), ta + 0.1 * (tb - ta)), tb - 0.1 * (tb - ta))
            zm = self._indicators(tm, state_at(tm), *args)
            if _crossed(za, zm).any():
                tb, zb, fb = tm, zm, zm.copy()
                if kept == -1:
                    fa = 0.5 * fa
                kept = -1
            else:
                ta, za, fa = tm, zm, zm.copy()
                if kept == 1:
                    fb = 0.5 * fb
                kept = 1
        return tb

    # the step ---------------------------------------------------------------------------------
    def step(self, t: float, h: float, u0: np.ndarray, slope: np.ndarray | None = None) -> None:
        """Integrate from ``t`` to ``t + h`` with the inputs ``u0 + slope (s - t)``, stopping
        at every event; ends early (``terminated``) when the FMU asks to stop."""
        from scipy.integrate import Radau

        self.time = t
        t_end = t + h
        args = (u0, slope, t)
        self._set_inputs(u0)                 # discrete inputs change at the step's start
        tc = t
        guard = 0
        while tc < t_end and not self.terminated:
            guard += 1
            if guard > 100000:
                raise CosimStepError(f"element {self.name!r}: more than 100000 events in the "
                                     f"step at t={t:g} (chattering?)", self.name, tc)
            t_stop = t_end
            time_event = self.next_event is not None and self.next_event <= t_end + \
                1e-12 * max(1.0, abs(t_end))
            if time_event:
                t_stop = max(tc, min(self.next_event, t_end))
            if self.nx == 0 and self.nz == 0:
                tc = t_stop
                self.time = tc
                self._call(self._set_state, tc, self.x)
                self._set_continuous_inputs(u0 if slope is None else u0 + slope * (tc - t))
            elif t_stop > tc:
                tc = self._euler(tc, t_stop, args) if self.euler_step else \
                    self._integrate(tc, t_stop, args, Radau)
            if self.terminated:
                break
            if tc >= t_stop and time_event and (self.next_event is None
                                                 or self.next_event <= tc + 1e-12 * max(
                                                     1.0, abs(tc))):
                self.time = tc
                self._call(self._set_state, tc, self.x)
                self._event()
        self.time = min(tc, t_end) if self.terminated else t_end
        self._call(self._set_state, self.time, self.x)
        self._set_continuous_inputs(u0 if slope is None else u0 + slope * (self.time - t))
        if not all(math.isfinite(v) for v in self.x):
            raise CosimStepError(f"element {self.name!r}: states not finite at "
                                 f"t={self.time:g}", self.name, self.time)

    def _integrate(self, tc: float, t_stop: float, args: tuple, Radau: Any) -> float:
        """Integrate from ``tc`` towards ``t_stop``; return the time reached (``t_stop``, or
        the time of a state or step event, which is handled)."""
        span = t_stop - tc
        first = None if self._h_last is None else min(self._h_last, span)
        if first is not None and (tc + first) - tc <= 0:
            first = None
        fun = (lambda s, x: self._rhs(s, x, *args)) if self.nx else (
            lambda s, x: np.zeros(0))
        try:
            solver = Radau(fun, tc, self.x if self.nx else np.zeros(1), t_stop,
                           rtol=self.rtol, atol=self.atol, first_step=first) if self.nx else None
        except Exception as err:
            raise self._failure(tc, err) from err
        z_prev = self._indicators(tc, self.x, *args) if self.nz else self._z
        t_old = tc
        while True:
            if solver is None:                   # no states: one "step" to t_stop
                t_new, x_new, dense = t_stop, self.x, (lambda s: self.x)
            else:
                try:
                    msg = solver.step()
                except CosimStepError:
                    raise
                except Exception as err:
                    raise self._failure(t_old, err) from err
                if solver.status == "failed":
                    raise self._failure(t_old, msg)
                t_new, x_new = float(solver.t), np.array(solver.y)
                dense = solver.dense_output()
                if t_new > t_old:
                    self._h_last = t_new - t_old
            if self.nz:
                z_new = self._indicators(t_new, x_new, *args)
                if _crossed(z_prev, z_new).any():
                    x_old = self.x.copy()
                    exact = functools.partial(self._state_at, t_old, x_old, fun=fun,
                                              Radau=Radau) if self.nx else dense
                    te = self._locate(exact, t_old, t_new, z_prev, z_new, args)
                    self.x = np.array(x_new if te >= t_new else exact(te)) if self.nx \
                        else self.x
                    self.time = te
                    self._call(self._set_state, te, self.x)
                    self._event()
                    return te
                z_prev = z_new
            self.x = x_new
            self.time = t_new
            self._call(self._set_state, t_new, self.x)
            enter, term = self._call(self.fmu.completedIntegratorStep)
            if term:
                self._request_stop("the FMU asked to terminate the simulation "
                                   "(completedIntegratorStep)")
                return t_new
            if enter:
                self._event()
                return t_new
            if solver is None or solver.status == "finished" or t_new >= t_stop:
                return t_stop
            t_old = t_new

    def _euler(self, tc: float, t_stop: float, args: tuple) -> float:
        """Forward Euler steps of ``euler_step`` from ``tc`` towards ``t_stop``; return the
        time reached (``t_stop``, or the end of the step with a state or step event)."""
        z_prev = self._indicators(tc, self.x, *args) if self.nz else self._z
        t0, k = tc, 0
        while tc < t_stop:
            k += 1
            t_new = t0 + k * self.euler_step
            if t_new >= t_stop - 1e-12 * max(1.0, abs(t_stop)):
                t_new = t_stop
            dx = self._rhs(tc, self.x, *args) if self.nx else self.x
            self.x = self.x + (t_new - tc) * dx
            tc = self.time = t_new
            if not np.all(np.isfinite(self.x)):
                raise self._failure(tc, "the states are not finite")
            z_new = self._indicators(tc, self.x, *args) if self.nz else \
                self._call(self._set_state, tc, self.x)
            enter, term = self._call(self.fmu.completedIntegratorStep)
            if term:
                self._request_stop("the FMU asked to terminate the simulation "
                                   "(completedIntegratorStep)")
                return tc
            if enter or (self.nz and _crossed(z_prev, z_new).any()):
                self._event()
                return tc
            z_prev = z_new
        return t_stop

    def _state_at(self, t0: float, x0: np.ndarray, t1: float, *, fun: Any,
                  Radau: Any) -> np.ndarray:
        """The state at ``t1`` integrated from ``(t0, x0)`` at the unit's tolerances (for
        event location: the dense output is less accurate than the steps, and an event
        indicator may amplify its error)."""
        if not t1 > t0:
            return np.array(x0)
        span = t1 - t0
        solver = Radau(fun, t0, x0, t1, rtol=self.rtol, atol=self.atol,
                       first_step=min(self._h_last or span, span))
        while solver.status == "running":
            msg = solver.step()
            if solver.status == "failed":
                raise self._failure(t0, msg)
        return np.array(solver.y)

    def _failure(self, t: float, err: Any) -> CosimStepError:
        said = self.fmu_errors()[-1:]
        detail = f"{err}" + (f" -- the FMU says: {said[0]}" if said else "")
        return CosimStepError(f"element {self.name!r}: integration failed at t={t:g}: "
                              f"{_one_line(detail, 600)}", self.name, t)
