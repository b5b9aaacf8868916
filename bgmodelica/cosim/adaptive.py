"""Error-controlled co-simulation: the macro step adapts to a tolerance on the coupling
signals.

Each macro step H from t is taken twice from the same saved state: once as one step of H,
once as two steps of H/2 (step doubling). The difference of the coupled outputs at t + H
estimates the local error of the coupling (the zero-order hold, or the linear extrapolation
of the inputs). Accepted: the two half steps stand (two communication points). Rejected: every
FMU goes back to t through its saved FMU state (``fmi2GetFMUstate`` / ``fmi3GetFMUState``,
and, for Model Exchange units, the master's integrator state) and H shrinks. The next step is

    H_new = H * min(fac_max, max(fac_min, 0.9 * (tol / err) ** (1 / (p + 1))))

with p = 1 for held inputs and p = 2 with extrapolation. ``err`` is the largest difference
of a coupled output, relative to the largest magnitude that signal has had so far (at least
``scale_floor``). Outputs with direct feedthrough are re-evaluated with the new inputs at each
communication point. The result (one row per accepted step) has the same columns as the
fixed-step master's; its ``meta`` says how many steps were accepted and rejected, the rounds of
FMU steps taken (each steps every FMU once: three per attempt) and the largest accepted error
estimate.
"""

from __future__ import annotations

import math
import time as _time
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ..result import Result
from .checks import check_parameter_value
from .errors import CosimStepError, InvalidExperimentError, SetupError, UnknownConnectorError
from .master import Master
from .ssp import SystemStructure
from .units import make_unit

#: Python-side unit attributes saved with the FMU state
_UNIT_ATTRS = ("time", "terminated", "stop_reason", "x", "next_event", "_h_last", "_disc_set")


def _can_roll_back(master: Master, name: str) -> bool:
    md = master.infos[name].description
    part = md.coSimulation if master.interfaces[name] == "cs" else md.modelExchange
    return bool(getattr(part, "canGetAndSetFMUstate", False)
                or getattr(part, "canGetAndSetFMUState", False))


class _Saved:
    """The states of all units at one time (FMU states + the units' own variables)."""

    def __init__(self, units: Mapping[str, Any]) -> None:
        self.units = units
        self.fmu: dict[str, Any] = {}
        self.attrs: dict[str, dict[str, Any]] = {}
        for name, unit in units.items():
            fmu = unit.fmu
            self.fmu[name] = unit._call(fmu.getFMUState if unit.info.fmi_version == 3
                                        else fmu.getFMUstate)
            self.attrs[name] = {a: _copy(getattr(unit, a)) for a in _UNIT_ATTRS
                                if hasattr(unit, a)}
            if hasattr(unit, "event_times"):
                self.attrs[name]["n_events"] = len(unit.event_times)

    def restore(self) -> None:
        for name, unit in self.units.items():
            fmu = unit.fmu
            unit._call(fmu.setFMUState if unit.info.fmi_version == 3 else fmu.setFMUstate,
                       self.fmu[name])
            attrs = dict(self.attrs[name])
            n_events = attrs.pop("n_events", None)
            for a, v in attrs.items():
                setattr(unit, a, _copy(v))
            if n_events is not None:
                del unit.event_times[n_events:]

    def free(self) -> None:
        for name, unit in self.units.items():
            fmu = unit.fmu
            try:
                (fmu.freeFMUState if unit.info.fmi_version == 3 else fmu.freeFMUstate)(
                    self.fmu[name])
            except Exception:  # noqa: BLE001 - best effort
                pass
        self.fmu.clear()


def _copy(v: Any) -> Any:
    return v.copy() if isinstance(v, np.ndarray) else v


def cosimulate_adaptive(system: SystemStructure | str | Path, stop_time: float | None = None,
                        tolerance: float = 1e-4, *, interface: str | Mapping[str, str] = "cs",
                        extrapolation: bool = True, initial_step: float | None = None,
                        min_step: float | None = None, max_step: float | None = None,
                        start_time: float | None = None,
                        parameters: Mapping[str, Mapping[str, Any]] | None = None,
                        record: Iterable[str] = (), scale_floor: float = 1e-3,
                        fac_min: float = 0.2, fac_max: float = 2.0,
                        me_rtol: float = 1e-8, me_atol: float = 1e-10,
                        max_steps: int = 1_000_000) -> Result:
    """Co-simulate ``system`` (Jacobi coupling) with an error-controlled macro step.

    ``tolerance``: the relative local error allowed on every coupled output per step.
    ``extrapolation``: inputs extrapolated linearly from the last two communication points
    (else held). ``initial_step``/``min_step``/``max_step`` [s]: defaults 1e-4, 1e-9 and a
    tenth of the horizon. Every FMU must support getting and setting its state.
    """
    if not (isinstance(tolerance, (int, float)) and math.isfinite(tolerance) and tolerance > 0):
        raise InvalidExperimentError(f"tolerance must be a finite number > 0, got {tolerance!r}")
    master = Master(system, interface=interface, me_rtol=me_rtol, me_atol=me_atol)
    system, plan, names = master.system, master.plan, master.system.element_names
    lacking = [n for n in names if not _can_roll_back(master, n)]
    if lacking:
        raise SetupError("adaptive co-simulation needs FMUs that can save and restore their "
                         "state (canGetAndSetFMUstate); not: "
                         + ", ".join(f"{n} ({master.infos[n].path.name})" for n in lacking)
                         + " - use fixed macro steps for them")
    t0 = float(system.start_time if start_time is None else start_time)
    t_end = stop_time if stop_time is not None else system.stop_time
    if t_end is None or not float(t_end) > t0:
        raise InvalidExperimentError(f"stop time {t_end!r} must be after the start time {t0}")
    t_end = float(t_end)
    h_max = float(max_step) if max_step else (t_end - t0) / 10
    h_min = float(min_step) if min_step else 1e-9
    h = min(float(initial_step) if initial_step else 1e-4, h_max)
    p = 2 if extrapolation else 1

    params = {c.name: dict(c.parameters) for c in system.elements}
    for el, vals in (parameters or {}).items():
        if el not in params:
            raise UnknownConnectorError(f"parameters for unknown element {el!r}")
        for k, v in vals.items():
            params[el][k] = check_parameter_value(el, master.infos[el], k, v,
                                                  "parameter override")
    extra: dict[str, list[str]] = {n: [] for n in names}
    for full in record:
        el, _, var = full.partition(".")
        if el not in extra:
            raise UnknownConnectorError(f"record: {full!r} is not <element>.<variable>")
        master.infos[el].variable(var, el)
        extra[el].append(var)
    out_pos = {n: {y: k for k, y in enumerate(plan.outputs[n])} for n in names}
    src = {n: [None if plan.sources.get((n, u)) is None else
               (plan.sources[(n, u)][0], out_pos[plan.sources[(n, u)][0]][plan.sources[(n, u)][1]])
               for u in plan.inputs[n]] for n in names}
    start_u = {n: np.array([float(params[n].get(u, master.infos[n].variables[u].start or 0.0))
                            for u in plan.inputs[n]]) for n in names}
    coupled_out = {n: sorted({k for m in names for s in src[m] if s is not None and s[0] == n
                              for k in [s[1]]}) for n in names}

    feeds = {n: any(plan.feedthrough[n].get(o) for o in plan.outputs[n]) for n in names}

    def coupled(n: str, ys: Mapping[str, np.ndarray]) -> np.ndarray:
        u = start_u[n].copy()
        for j, s in enumerate(src[n]):
            if s is not None:
                u[j] = ys[s[0]][s[1]]
        return u

    units: dict[str, Any] = {}
    times: list[float] = []
    rows: list[np.ndarray] = []
    n_acc = n_rej = n_fmu_steps = 0
    err_max = 0.0
    wall0 = _time.perf_counter()
    try:
        for n in names:
            unit = make_unit(n, master.infos[n], master.interfaces[n], plan.inputs[n],
                             plan.outputs[n], rtol=me_rtol, atol=me_atol)
            units[n] = unit
            pset = {k: v for k, v in params[n].items()
                    if master.infos[n].variables[k].set_by_name}
            unit.setup(t0, t_end, pset, start_u[n], None)
        y = {n: units[n].get_outputs() for n in names}
        scale = {n: np.maximum(np.abs(y[n]), scale_floor) for n in names}

        def record_point(t: float) -> None:
            parts = []
            for n in names:
                parts += [coupled(n, y), y[n]]
                if extra[n]:
                    parts.append(units[n].get(extra[n]))
            times.append(t)
            rows.append(np.concatenate(parts))

        def advance(t: float, step: float, u0: dict, slope: dict | None) -> dict:
            nonlocal n_fmu_steps
            for n in names:
                units[n].step(t, step, u0[n], None if slope is None else slope[n])
            n_fmu_steps += 1
            ys = {n: units[n].get_outputs() for n in names}
            for el, _, is_out in plan.order:        # direct feedthrough at t + step
                if is_out and feeds[el]:
                    units[el].set_inputs(coupled(el, ys))
                    ys[el] = units[el].get_outputs()
            return ys

        record_point(t0)
        t = t0
        u_prev: dict | None = None
        t_prev = t0
        while t < t_end - 1e-12 * max(1.0, abs(t_end)):
            if n_acc + n_rej >= max_steps:
                raise CosimStepError(f"more than {max_steps} macro steps (tolerance "
                                     f"{tolerance:g} too tight?)", names[0], t)
            h = min(h, t_end - t)
            u_t = {n: coupled(n, y) for n in names}
            slope = None
            if extrapolation and u_prev is not None and t > t_prev:
                slope = {n: (u_t[n] - u_prev[n]) / (t - t_prev) for n in names}
            saved = _Saved(units)
            try:
                y_big = advance(t, h, u_t, slope)
                saved.restore()
                y_mid = advance(t, h / 2, u_t, slope)
                u_mid = {n: coupled(n, y_mid) for n in names}
                slope_mid = {n: (u_mid[n] - u_t[n]) / (h / 2) for n in names} \
                    if extrapolation else None
                y_small = advance(t + h / 2, h / 2, u_mid, slope_mid)
                err = 0.0
                for n in names:
                    k = coupled_out[n]
                    if k:
                        d = np.abs(y_small[n][k] - y_big[n][k]) / scale[n][k]
                        err = max(err, float(np.max(d)))
                if not math.isfinite(err):
                    err = math.inf
                if err <= tolerance or h <= h_min:
                    n_acc += 1
                    err_max = max(err_max, err)
                    y = y_small
                    t_prev, u_prev = t + h / 2, u_mid
                    t = t + h
                    for n in names:
                        np.maximum(scale[n], np.abs(y[n]), out=scale[n])
                    record_point(t)
                    factor = fac_max if err == 0 else min(
                        fac_max, max(fac_min, 0.9 * (tolerance / err) ** (1 / (p + 1))))
                    h = min(h * factor, h_max)
                    if any(u.terminated for u in units.values()):
                        break
                else:
                    n_rej += 1
                    saved.restore()
                    h = max(h * max(fac_min, 0.9 * (tolerance / err) ** (1 / (p + 1))), h_min)
            finally:
                saved.free()
    finally:
        for unit in units.values():
            unit.terminate()
    cols = []
    for n in names:
        cols += [f"{n}.{u}" for u in plan.inputs[n]] + [f"{n}.{v}" for v in plan.outputs[n]]
        cols += [f"{n}.{v}" for v in extra[n]]
    wall = _time.perf_counter() - wall0
    meta = {"master": "bgmodelica.cosim.adaptive", "order": "jacobi",
            "extrapolation": bool(extrapolation), "tolerance": tolerance,
            "steps_accepted": n_acc, "steps_rejected": n_rej,
            "communication_points": 2 * n_acc, "step_rounds": n_fmu_steps,
            "error_estimate_max": err_max, "start_time": t0, "stop_time": t_end,
            "interfaces": dict(master.interfaces), "run_seconds": wall,
            "seconds_per_simulated_second": wall / (t_end - t0)}
    return Result(np.array(times), np.array(rows), cols, meta=meta)
