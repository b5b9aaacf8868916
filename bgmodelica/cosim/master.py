"""A fixed-step co-simulation master for FMUs described by an SSP set-up.

Macro step ``H`` (communication points ``t_k = t0 + k H``), two orders:

* **Jacobi** (``order="jacobi"``): every unit steps from ``t_k`` with the coupling values of
  ``t_k``; units are independent within a step.
* **Gauss-Seidel** (``order="gauss-seidel"``): units step one after the other (``sequence``,
  default: the order of the elements in the SSD); a unit uses the ``t_{k+1}`` outputs of the
  units already stepped and the ``t_k`` outputs of the others.

Inputs over a step are ``u(t) = u0 + slope (t - t_k)``:

* no extrapolation: ``slope = 0``, ``u0`` = the newest coupling value (zero-order hold);
* ``extrapolation=True``: linear. For a value already known at ``t_{k+1}`` (Gauss-Seidel: its
  unit has stepped and the output does not depend directly on an input still at ``t_k``) the
  line through its values at ``t_k`` and ``t_{k+1}`` (*interpolation*); otherwise (always in
  Jacobi) the line through the values at ``t_{k-1}`` and ``t_k`` (*extrapolation*).
  Model Exchange units follow the ramp; Co-Simulation units hold its mean over the step
  (``u0 + slope H/2``, the same integral: second order for integrated quantities).

Outputs with direct feedthrough (from the FMUs' ``<ModelStructure>``): with
``propagate=True`` (default) the master evaluates, at every communication point, the
outputs in the topological order of the feedthrough graph after setting the exact coupling
values of that instant, so recorded and coupled values are consistent (``y = g(x, u)`` at
``t_k``). With ``propagate=False`` the outputs are those read right after ``doStep`` (with the
inputs held during the step), as simple masters (and ``fmucontainer``) do.

Units: Co-Simulation FMUs (``interface="cs"``, their own solver via ``doStep``) or Model
Exchange FMUs integrated here (``"me"``: SciPy Radau per macro step); per element with a dict.

Speed: the common cases (either order without extrapolation or input signals, Co-Simulation
units whose coupled connectors are all Real) run as a flat loop over one value vector
(:mod:`.flat_loop`) that calls the FMUs' C functions directly; its results are those of the
general loop to the last bit. With extrapolation in Gauss-Seidel order, which inputs read
values already at ``t_{k+1}`` is found once per run.

Results: :class:`bgmodelica.Result` with ``<element>.<variable>`` names: every connector
(inputs: the coupled value at the communication point) and any variable asked for in
``record``; bound parameters are in ``result.parameters``; ``result.meta`` has the options
and wall-clock times.

Everything is checked before an FMU is instantiated: start/stop time and macro step must be
finite, the horizon a multiple of the step and the number of macro steps at most
``max_steps`` (default :data:`MAX_STEPS`; the message gives the number that would be
needed), the recorded table at most :data:`MAX_RECORD_BYTES`; parameter overrides must name
settable real parameters (or inputs) with finite values inside the FMU's ``[min, max]``
(:class:`~.errors.InvalidExperimentError`, :class:`~.errors.InvalidParameterError`,
:class:`~.errors.UnknownConnectorError`).
"""

from __future__ import annotations

import math
import time as _time
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..result import Result
from . import flat_loop
from .archive import _size
from .checks import Plan, check_parameter_value, check_system
from .errors import (
    CosimStepError,
    InvalidExperimentError,
    SetupError,
    UnknownConnectorError,
)
from .experiment import MAX_STEPS, ORDERS, _finite, _norm_order, count_steps  # noqa: F401
from .fmu import FmuInfo, read_fmu_info
from .signals import input_signals
from .ssp import SystemStructure
from .ssp_read import read_ssp
from .text import TextChannel
from .units import make_unit

MAX_RECORD_BYTES = 4 << 30           # the recorded table (points x columns x 8 bytes)


class Master:
    """Co-simulation of ``system`` (a :class:`~.ssp.SystemStructure` or the path of an
    ``.ssp``). The set-up is checked at construction (see :mod:`.checks`).

    ``interface``: ``"cs"`` (default), ``"me"``, ``"auto"`` (the SSD ``implementation``
    attribute, else CS when available) or a dict element -> interface.
    ``allow_unconnected``: keep unconnected inputs at their start values instead of raising.
    ``me_rtol``/``me_atol``: tolerances of the Model Exchange integrator; ``me_euler_step``:
    forward Euler at this fixed step instead (see :mod:`.me_unit`).
    """

    def __init__(self, system: SystemStructure | str | Path, *,
                 interface: str | Mapping[str, str] = "cs", allow_unconnected: bool = False,
                 me_rtol: float = 1e-8, me_atol: float = 1e-10,
                 me_euler_step: float | None = None) -> None:
        if not isinstance(system, SystemStructure):
            system = read_ssp(system)
        self.system = system
        self.infos: dict[str, FmuInfo] = {}
        for comp in system.elements:
            if comp.fmu_path is None:
                raise SetupError(f"element {comp.name!r}: FMU file unknown (source "
                                 f"{comp.source!r})")
            self.infos[comp.name] = read_fmu_info(comp.fmu_path)
        self.plan: Plan = check_system(system, self.infos, allow_unconnected)
        if isinstance(interface, Mapping):
            unknown = sorted(set(interface) - set(self.infos))
            if unknown:
                raise UnknownConnectorError(f"interface given for unknown element(s) "
                                            f"{', '.join(unknown)} (elements: "
                                            f"{', '.join(system.element_names)})")
        for name, tol in (("me_rtol", me_rtol), ("me_atol", me_atol)):
            if not (isinstance(tol, (int, float)) and math.isfinite(tol) and tol > 0):
                raise InvalidExperimentError(f"{name} must be finite and > 0, got {tol!r}")
        self.interfaces = {c.name: self._interface(c.name, c.implementation, interface)
                           for c in system.elements}
        if me_euler_step is not None and not _finite(me_euler_step, "me_euler_step") > 0:
            raise InvalidExperimentError(f"me_euler_step must be > 0, got {me_euler_step!r}")
        self.me_rtol, self.me_atol, self.me_euler_step = me_rtol, me_atol, me_euler_step

    def _interface(self, name: str, implementation: str, wanted: Any) -> str:
        info = self.infos[name]
        if not info.cs_identifier and not info.me_identifier:
            offers = ("only Scheduled Execution, which this master does not run (it runs "
                      "Co-Simulation and Model Exchange FMUs)") if info.scheduled_execution \
                else "neither Co-Simulation nor Model Exchange"
            raise SetupError(f"element {name!r}: {info.path.name} offers {offers}")
        if isinstance(wanted, Mapping):
            wanted = wanted.get(name, "cs")
        if wanted == "auto":
            if implementation == "ModelExchange" and info.me_identifier:
                return "me"
            return "cs" if info.cs_identifier else "me"
        if wanted not in ("cs", "me"):
            raise SetupError(f"interface must be 'cs', 'me' or 'auto', not {wanted!r}")
        if wanted == "cs" and not info.cs_identifier:
            raise SetupError(f"element {name!r}: {info.path.name} has no Co-Simulation "
                             "interface (use interface='me')")
        if wanted == "me" and not info.me_identifier:
            raise SetupError(f"element {name!r}: {info.path.name} has no Model Exchange "
                             "interface (use interface='cs')")
        return wanted

    # ------------------------------------------------------------------------------------
    def simulate(self, stop_time: float | None = None, step: float | None = None, *,
                 order: str = "jacobi", extrapolation: bool = False, propagate: bool = True,
                 start_time: float | None = None, sequence: Sequence[str] | None = None,
                 parameters: Mapping[str, Mapping[str, float]] | None = None,
                 record: Iterable[str] = (), tolerance: float | None = None,
                 record_every: int = 1, max_abs: float | None = None,
                 max_steps: int | None = None,
                 inputs: Mapping[str, tuple[Any, Any]] | None = None) -> Result:
        """Run the co-simulation and return the :class:`~bgmodelica.Result`.

        ``stop_time``/``step``: default from the SSD (DefaultExperiment, the master
        annotation's ``step_size``; else 1e-3 s). ``parameters``: element -> {name: value}
        on top of the SSD bindings. ``record``: extra variables ``element.variable``.
        ``tolerance``: passed to the FMUs' ``setupExperiment`` (None: not defined).
        ``record_every``: keep every n-th communication point (the last one always).
        ``max_abs``: stop with :class:`~.errors.CosimStepError` as soon as a coupled output
        exceeds this magnitude (an unstable coupling; None: only non-finite values stop).
        ``max_steps``: refuse runs with more macro steps (default :data:`MAX_STEPS`).
        ``inputs``: ``{"element.input": (times, values)}`` signals for unconnected inputs
        (linear between breakpoints, a repeated time is a jump, the end values held); within
        a macro step they ramp from their value at its start to the one at its end.
        """
        system = self.system
        order = _norm_order(order)
        t0 = _finite(system.start_time if start_time is None else start_time, "start time")
        t_end = stop_time if stop_time is not None else system.stop_time
        if t_end is None:
            raise InvalidExperimentError("no stop time: give stop_time or set the SSD "
                                         "DefaultExperiment")
        t_end = _finite(t_end, "stop time")
        h = _finite(step if step is not None else system.master.get("step_size", 1e-3),
                    "macro step")
        n_steps = count_steps(t0, t_end, h, max_steps)
        span = t_end - t0
        if tolerance is not None and not (_finite(tolerance, "tolerance") > 0):
            raise InvalidExperimentError(f"tolerance must be > 0, got {tolerance!r}")
        if max_abs is not None and not float(max_abs) > 0:      # NaN would never trigger
            raise InvalidExperimentError(f"max_abs must be > 0, got {max_abs!r}")
        try:
            every = int(record_every)
        except (TypeError, ValueError):
            every = 0
        if every < 1 or every != record_every:
            raise InvalidExperimentError(f"record_every must be a positive integer, got "
                                         f"{record_every!r}")
        names = system.element_names
        seq = list(sequence) if sequence is not None else list(names)
        if sorted(seq) != sorted(names):
            raise SetupError(f"sequence {seq} must list every element once ({names})")
        plan = self.plan
        params = {c.name: dict(c.parameters) for c in system.elements}
        for el, vals in (parameters or {}).items():
            if el not in params:
                raise UnknownConnectorError(f"parameters for unknown element {el!r} "
                                            f"(elements: {', '.join(names)})")
            for p, v in vals.items():
                if p not in self.infos[el].variables:
                    raise UnknownConnectorError(f"element {el!r} has no variable {p!r}")
                params[el][p] = check_parameter_value(el, self.infos[el], p, v,
                                                      "parameter override")
        extra: dict[str, list[str]] = {n: [] for n in names}
        text_extra: dict[str, list[str]] = {n: [] for n in names}
        for full in record:
            el, _, var = full.partition(".")
            if el not in extra or not var:
                raise UnknownConnectorError(f"record: {full!r} is not <element>.<variable> "
                                            f"(elements: {', '.join(names)})")
            is_text = self.infos[el].variable(var, el).type in ("String", "Binary")
            (text_extra if is_text else extra)[el].append(var)
        text = TextChannel(plan, self.infos, names, text_extra)
        n_cols = sum(len(plan.inputs[n]) + len(plan.outputs[n]) + len(extra[n])
                     for n in names)
        n_rows = n_steps // every + 1 + (1 if n_steps % every else 0)
        if n_rows * (n_cols + 1) * 8 > MAX_RECORD_BYTES:
            raise InvalidExperimentError(
                f"recording {n_rows} communication points of {n_cols} variables needs "
                f"{_size(n_rows * (n_cols + 1) * 8)}, more than {_size(MAX_RECORD_BYTES)}: "
                "record fewer points (record_every)")

        # index tables -------------------------------------------------------------------
        out_pos = {n: {y: k for k, y in enumerate(plan.outputs[n])} for n in names}
        src_index: dict[str, list[tuple[str, int] | None]] = {}
        start_u: dict[str, np.ndarray] = {}
        for n in names:
            src_index[n] = []
            su = []
            for u in plan.inputs[n]:
                s = plan.sources.get((n, u))
                src_index[n].append(None if s is None else (s[0], out_pos[s[0]][s[1]]))
                var = self.infos[n].variables[u]
                su.append(params[n].get(u, var.start if var.start is not None else 0.0))
            start_u[n] = np.array(su, dtype=float)
        has_feed = {n: any(plan.feedthrough[n].get(y) for y in plan.outputs[n])
                    for n in names}
        signals = input_signals(inputs or {}, plan, src_index)
        for n, given in signals.items():
            for j, f in given:
                start_u[n][j] = f(t0)
        t_now = [t0]                    # the time the coupled inputs are evaluated at

        units = {}
        wall0 = _time.perf_counter()
        try:
            for comp in system.elements:
                n = comp.name
                unit = make_unit(n, self.infos[n], self.interfaces[n], plan.inputs[n],
                                 plan.outputs[n], rtol=self.me_rtol, atol=self.me_atol,
                                 euler_step=self.me_euler_step)
                units[n] = unit
                pset = {k: v for k, v in params[n].items()
                        if self.infos[n].variables[k].set_by_name}
                unit.setup(t0, t_end, pset, start_u[n], tolerance)
            y = {n: units[n].get_outputs() for n in names}
            last_set = {n: start_u[n].copy() for n in names}

            # per element: (source element, its output positions, our input positions)
            gather: dict[str, list[tuple[str, np.ndarray, np.ndarray]]] = {}
            for n in names:
                by_src: dict[str, tuple[list[int], list[int]]] = {}
                for j, s in enumerate(src_index[n]):
                    if s is not None:
                        pair = by_src.setdefault(s[0], ([], []))
                        pair[0].append(s[1])
                        pair[1].append(j)
                gather[n] = [(src, np.array(a), np.array(b)) for src, (a, b) in by_src.items()]
            gs_fresh, gs_stale = plan.gauss_seidel_sources(seq, src_index)
            # elements whose outputs feed through, in evaluation order (repeats kept apart)
            feed_order: list[str] = []
            for el, _, is_out in plan.order:
                if is_out and has_feed[el] and (not feed_order or feed_order[-1] != el):
                    feed_order.append(el)

            def coupled(n: str, ys: dict[str, np.ndarray]) -> np.ndarray:
                u = start_u[n].copy()
                for src, from_pos, to_pos in gather[n]:
                    u[to_pos] = ys[src][from_pos]
                for j, f in signals.get(n, ()):
                    u[j] = f(t_now[0])
                return u

            def propagate_outputs() -> None:
                for el in feed_order:
                    u = coupled(el, y)
                    last = last_set[el]
                    if last is None or u.tolist() != last.tolist():
                        units[el].set_inputs(u)
                        last_set[el] = u
                        y[el] = units[el].get_outputs()

            if propagate:
                propagate_outputs()
            if text:
                text.start(units)
            wall_setup = _time.perf_counter() - wall0

            # recording ------------------------------------------------------------------
            cols: list[str] = []
            for n in names:
                cols += [f"{n}.{u}" for u in plan.inputs[n]]
                cols += [f"{n}.{v}" for v in plan.outputs[n]]
                cols += [f"{n}.{v}" for v in extra[n]]
            data = np.empty((n_rows, len(cols)))
            times = np.empty(n_rows)
            row = 0

            def record_point(k: int, t: float) -> None:
                nonlocal row
                if k % every and k != n_steps:
                    return
                parts = []
                for n in names:
                    u = coupled(n, y)
                    if n not in signals:        # the next step starts from these inputs
                        reuse[n] = u
                    parts.append(u)
                    parts.append(y[n])
                    if extra[n]:
                        parts.append(units[n].get(extra[n]))
                data[row] = np.concatenate(parts) if parts else []
                times[row] = t
                row += 1
                if text:
                    text.record()

            def diverging(ys: dict[str, np.ndarray], t: float) -> None:
                """Raise when an output at ``t + h`` is not finite (or exceeds max_abs)."""
                for n in names:
                    bad_mask = ~np.isfinite(ys[n])
                    if max_abs is not None:
                        bad_mask |= np.abs(ys[n]) > max_abs
                    if bad_mask.any():
                        bad = [f"{plan.outputs[n][i]} = {ys[n][i]:g}"
                               for i in np.flatnonzero(bad_mask)]
                        raise CosimStepError(
                            f"element {n!r}: output(s) {', '.join(bad)} at t={t + h:g}: the "
                            f"co-simulation diverges (unstable coupling at macro step {h:g} s?)",
                            n, t + h)

            reuse: dict[str, np.ndarray] = {}     # inputs recorded at the last point
            record_point(0, t0)
            terminated: dict[str, Any] | None = None
            u_prev: dict[str, np.ndarray] | None = None
            wall1 = _time.perf_counter()
            if not text and flat_loop.applies(units, order=order,
                                              extrapolation=extrapolation, signals=signals):
                loop = flat_loop.FlatLoop(units, names, start_u, gather, feed_order, extra)
                loop.load(y)
                row, terminated = loop.run(
                    t0, h, n_steps, every, propagate, last_set, data, times, row, diverging,
                    max_abs is not None, sequence=seq if order == "gauss-seidel" else None,
                    feedthrough={n for n in names if has_feed[n]})
            else:
                for k in range(n_steps):
                    t = t0 + k * h
                    t_now[0] = t
                    u_now = {n: reuse[n] if n in reuse else coupled(n, y) for n in names}
                    reuse.clear()
                    if order == "jacobi":
                        for n in names:
                            slope = None
                            if extrapolation and u_prev is not None and len(u_now[n]):
                                slope = (u_now[n] - u_prev[n]) / h
                            if n in signals:
                                slope = np.zeros(len(u_now[n])) if slope is None else slope
                                for j, f in signals[n]:
                                    slope[j] = (f(t + h, True) - u_now[n][j]) / h
                            units[n].step(t, h, u_now[n], slope)
                            last_set[n] = u_now[n] if slope is None else None
                        y = {n: units[n].get_outputs() for n in names}
                    else:
                        y_old = dict(y)
                        for n in seq:
                            u0 = u_now[n].copy()
                            slope = np.zeros_like(u0) if extrapolation else None
                            if not extrapolation:
                                for src, from_pos, to_pos in gather[n]:
                                    u0[to_pos] = y[src][from_pos]   # the newest value there is
                            else:
                                for src, from_pos, to_pos in gs_fresh[n]:
                                    old = y_old[src][from_pos]      # a t_k+1 value: interpolate
                                    u0[to_pos] = old
                                    slope[to_pos] = (y[src][from_pos] - old) / h
                                stale = gs_stale[n]
                                if u_prev is not None and len(stale):
                                    slope[stale] = (u_now[n][stale] - u_prev[n][stale]) / h
                            if n in signals:
                                slope = np.zeros_like(u0) if slope is None else slope
                                for j, f in signals[n]:
                                    u0[j] = f(t)
                                    slope[j] = (f(t + h, True) - u0[j]) / h
                            units[n].step(t, h, u0, slope)
                            last_set[n] = u0 if slope is None else None
                            y[n] = units[n].get_outputs()
                            if propagate and has_feed[n]:
                                u = coupled(n, y)
                                units[n].set_inputs(u)
                                last_set[n] = u
                                y[n] = units[n].get_outputs()
                    t_now[0] = t + h
                    for n in names:
                        if last_set[n] is None:
                            last_set[n] = np.full(len(u_now[n]), np.nan)
                    if propagate:
                        propagate_outputs()
                    if text:
                        text.exchange()
                    u_prev = u_now
                    stopped = [n for n in names if units[n].terminated]
                    if stopped:
                        first = min(stopped, key=lambda n: units[n].time)
                        terminated = {"element": first, "time": units[first].time,
                                      "reason": units[first].stop_reason}
                        record_point(n_steps, units[first].time)
                        break
                    if max_abs is not None or \
                            not np.isfinite(np.concatenate(list(y.values()))).all():
                        diverging(y, t)
                    record_point(k + 1, t0 + (k + 1) * h)
            wall_run = _time.perf_counter() - wall1
        finally:
            for unit in units.values():
                unit.terminate()

        parameters_out = {}
        for n in names:
            for v in self.infos[n].parameters:
                if v.type == "Real":
                    val = params[n].get(v.name, v.start)
                    if val is not None:
                        parameters_out[f"{n}.{v.name}"] = float(val)
        units_of = {}
        for n in names:
            for v in plan.inputs[n] + plan.outputs[n] + extra[n]:
                units_of[f"{n}.{v}"] = self.infos[n].variables[v].unit
        units_of.update(text.units_of)
        meta = {
            "master": "bgmodelica.cosim", "order": order, "extrapolation": bool(extrapolation),
            "propagate": bool(propagate), "step": h, "steps": n_steps, "start_time": t0,
            "stop_time": t_end, "interfaces": dict(self.interfaces),
            "sequence": seq if order == "gauss-seidel" else None,
            "setup_seconds": wall_setup, "run_seconds": wall_run,
            "seconds_per_simulated_second": wall_run / span,
            "terminated": terminated,
            "events": {n: list(u.event_times) for n, u in units.items()
                       if self.interfaces[n] == "me"},
            "me_rhs_evaluations": {n: getattr(u, "n_rhs", None) for n, u in units.items()
                                   if self.interfaces[n] == "me"},
        }
        return Result(times[:row], data[:row], cols, parameters=parameters_out, units=units_of,
                      meta=meta, text=text.table())


def cosimulate(system: SystemStructure | str | Path, stop_time: float | None = None,
               step: float | None = None, *, interface: str | Mapping[str, str] = "cs",
               **options: Any) -> Result:
    """One-call form: ``Master(system, interface=...).simulate(stop_time, step, **options)``."""
    return Master(system, interface=interface).simulate(stop_time, step, **options)

