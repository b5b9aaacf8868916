"""Verification of a co-simulation against the monolithic model it was split from.

:func:`verify_model` simulates the model tightly (IDAS, rtol 1e-10) as the reference and
co-simulates the SSP set-up of its parts for every macro step and scheme (Jacobi,
Gauss-Seidel, with and without input extrapolation). Variables are matched by name: an
output ``element.var`` of the co-simulation (or a variable recorded with ``record``) is
compared with the model's variable ``element.var`` or, if the model has none, its top-level
``var``. Per variable it reports the largest ``|cosim - reference|`` over the communication
points (at an event instant of the reference, the nearer of its values before and after),
the observed order of convergence between consecutive steps and the wall-clock time per
simulated second; :meth:`VerificationReport.failures` checks the errors against a tolerance.
``bgmodelica verify MODEL SSP`` is the command line of it.

This module knows no particular model (it does not import ``library``); the paper's robot
uses it through :func:`library.robots.verification.verify_robot`.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .errors import CosimStepError, InvalidExperimentError, UnknownConnectorError

#: A coupled output beyond this magnitude means the run diverged.
DIVERGED = 1e6
SCHEMES = (("jacobi", False), ("jacobi", True), ("gauss-seidel", False), ("gauss-seidel", True))
#: Points of the monolithic reference at most (the grid of all the macro steps).
MAX_REFERENCE_POINTS = 10_000_000


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def _observed(errors: list[float], steps: list[float]) -> list[float | None]:
    """Observed order between consecutive (step, error) pairs; None for the first."""
    out: list[float | None] = [None]
    for k in range(1, len(errors)):
        e0, e1 = errors[k - 1], errors[k]
        if all(math.isfinite(x) and x > 0 for x in (e0, e1)) and steps[k - 1] != steps[k]:
            out.append(math.log(e0 / e1) / math.log(steps[k - 1] / steps[k]))
        else:
            out.append(None)
    return out


def _grid(steps: Sequence[float]) -> float:
    """Largest interval dividing every step (within 1e-6 relative)."""
    base = min(steps)
    for div in range(1, 1001):
        g = base / div
        if all(abs(s / g - round(s / g)) < 1e-6 for s in steps):
            return g
    raise InvalidExperimentError(f"the macro steps {', '.join(f'{s:g}' for s in steps)} have "
                                 "no common output grid (make each a multiple of the smallest "
                                 "divided by at most 1000)")


def check_options(steps: Sequence[float], stop_time: float, me_step: float | None = None,
                  me_stop_time: float | None = None, cross_check_step: float | None = None,
                  cross_check_stop_time: float | None = None) -> float:
    """Refuse non-finite, non-positive, absurd or inconsistent steps and horizons before
    anything is built (:class:`~.errors.InvalidExperimentError`); return the output grid."""
    from .master import count_steps

    if not steps:
        raise InvalidExperimentError("no macro steps given")
    for h in steps:
        count_steps(0.0, stop_time, h)
    if me_step:
        count_steps(0.0, me_stop_time or stop_time, me_step)
    if cross_check_step:
        count_steps(0.0, cross_check_stop_time or stop_time, cross_check_step)
    grid = _grid([float(h) for h in steps] + ([float(me_step)] if me_step else []))
    points = float(stop_time) / grid
    if points > MAX_REFERENCE_POINTS:
        raise InvalidExperimentError(
            f"the reference on the common grid {grid:g} s of the macro steps over "
            f"{float(stop_time):g} s needs {points:.4g} points, more than "
            f"{MAX_REFERENCE_POINTS:.0e}: choose steps that are simple multiples of each other")
    return grid


def reference_at(ref: Any, name: str, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Values of ``ref[name]`` at ``times`` as (before, after): at a time present in the
    reference, its first and last rows there (they differ at an event instant); in between,
    linear interpolation (both the same)."""
    t = np.asarray(ref.time, dtype=float)
    y = np.asarray(ref[name], dtype=float)
    times = np.asarray(times, dtype=float)
    tol = 1e-9 * max(1.0, float(abs(t[-1]))) if len(t) else 0.0
    last = np.clip(np.searchsorted(t, times + tol, side="right") - 1, 0, len(t) - 1)
    first = np.clip(np.searchsorted(t, times - tol, side="left"), 0, len(t) - 1)
    after, before = y[last].copy(), y[first].copy()
    off = np.abs(t[last] - times) > tol
    if np.any(off):
        after[off] = before[off] = np.interp(times[off], t, y)
    return before, after


def max_error(values: Any, ref: Any, name: str, times: np.ndarray) -> float:
    """Largest ``|values - ref[name]|`` at ``times``; at an event instant of the reference
    the nearer of its values before and after the event counts (the FMU may see an event
    time a rounding error earlier or later than the communication point)."""
    before, after = reference_at(ref, name, times)
    v = np.asarray(values, dtype=float)
    err = np.minimum(np.abs(v - before), np.abs(v - after))
    if np.any(np.isnan(err)):
        return math.inf
    return float(np.max(err)) if len(err) else 0.0


def match_variables(system: Any, model_names: Sequence[str],
                    variables: Sequence[str] | None = None,
                    record: Sequence[str] = ()) -> dict[str, str]:
    """Co-simulation name -> model name of the compared variables.

    Candidates are the elements' outputs and ``record`` (``element.var``), or ``variables``
    when given; each is matched to the model's ``element.var`` or else its top-level ``var``.
    Unmatched candidates are dropped, except those asked for in ``variables`` (an
    :class:`~.errors.UnknownConnectorError`)."""
    names = set(model_names)
    if variables:
        candidates = list(variables)
    else:
        candidates = [f"{el.name}.{c.name}" for el in system.elements
                      for c in el.connectors if c.kind == "output"] + list(record)
    out: dict[str, str] = {}
    for cand in candidates:
        el, _, var = cand.partition(".")
        if cand in names:
            out[cand] = cand
        elif var in names:
            out[cand] = var
        elif variables:
            raise UnknownConnectorError(
                f"variable {cand!r}: the model has neither {cand!r} nor {var!r}")
    if not out:
        raise UnknownConnectorError(
            f"no output of the co-simulation ({', '.join(candidates) or 'none'}) matches a "
            "variable of the model by name (element.var or var): name them with variables")
    return out


@dataclass
class VerificationRow:
    """One co-simulation run: interface, scheme, macro step, error per compared variable
    (inf if the run diverged), observed order vs the previous (larger) step, wall time per
    simulated second."""

    interface: str
    order: str
    extrapolation: bool
    step: float
    errors: dict[str, float]
    observed_order: dict[str, float | None]
    wall_per_second: float | None
    status: str = "ok"                    # ok | diverged

    @property
    def scheme(self) -> str:
        return f"{self.order}{' + extrapolation' if self.extrapolation else ''}"

    @property
    def worst(self) -> float:
        return max(self.errors.values()) if self.errors else 0.0

    def to_dict(self) -> dict[str, Any]:
        return {"interface": self.interface, "order": self.order,
                "extrapolation": self.extrapolation, "step": self.step,
                "errors": {k: _finite(v) for k, v in self.errors.items()},
                "observed_order": dict(self.observed_order),
                "wall_seconds_per_simulated_second": self.wall_per_second,
                "status": self.status}


def run_schemes(system: Any, reference: Any, pairs: Mapping[str, str], steps: Sequence[float],
                stop_time: float, *, schemes: Sequence[tuple[str, bool]] = SCHEMES,
                interface: str = "cs", parameters: Mapping[str, Mapping[str, float]] | None
                = None, record: Sequence[str] = (),
                progress: Callable[[str], None] | None = None) -> list[VerificationRow]:
    """Co-simulate ``system`` for every scheme and step (largest first) and compare the
    ``pairs`` (co-simulation name -> reference name) with ``reference`` (a result holding
    every communication point). Diverged runs get infinite errors."""
    from .master import Master

    say = progress or (lambda _msg: None)
    steps = sorted((float(s) for s in steps), reverse=True)
    master = Master(system, interface=interface)
    extra = [n for n in pairs if n in record or n not in _outputs(system)]
    rows: list[VerificationRow] = []
    for order, ex in schemes:
        errs: list[dict[str, float]] = []
        walls: list[float | None] = []
        status: list[str] = []
        for h in steps:
            say(f"{interface} {order}{' + extrapolation' if ex else ''}, step {h:g} s")
            try:
                res = master.simulate(stop_time, h, order=order, extrapolation=ex,
                                      parameters=parameters if interface == "cs" else None,
                                      record=extra, max_abs=DIVERGED)
                e = {c: max_error(res[c], reference, m, res.time) for c, m in pairs.items()}
                e = {k: (v if math.isfinite(v) else math.inf) for k, v in e.items()}
                errs.append(e)
                walls.append(res.meta["run_seconds"] / stop_time)
                status.append("ok" if all(math.isfinite(x) for x in e.values())
                              else "diverged")
            except CosimStepError:
                errs.append({c: math.inf for c in pairs})
                walls.append(None)
                status.append("diverged")
        obs = {c: _observed([e[c] for e in errs], steps) for c in pairs}
        for k, h in enumerate(steps):
            rows.append(VerificationRow(interface, order, ex, h, errs[k],
                                        {c: obs[c][k] for c in pairs}, walls[k], status[k]))
    return rows


def _outputs(system: Any) -> set[str]:
    return {f"{el.name}.{c.name}" for el in system.elements for c in el.connectors
            if c.kind in ("output", "input")}


@dataclass
class VerificationReport:
    """Result of :func:`verify_model`; ``to_text()`` for people, ``to_dict()`` for JSON,
    ``failures(tol)`` for a pass/fail check."""

    model: str
    system: str
    stop_time: float
    steps: list[float]
    variables: dict[str, str]                 # co-simulation name -> model name
    rows: list[VerificationRow]
    reference: dict[str, Any]
    timings: dict[str, float] = field(default_factory=dict)

    def rows_for(self, order: str, extrapolation: bool, interface: str = "cs"
                 ) -> list[VerificationRow]:
        return [r for r in self.rows if r.order == order and r.extrapolation == extrapolation
                and r.interface == interface]

    def error(self, step: float, order: str, extrapolation: bool, variable: str,
              interface: str = "cs") -> float:
        for r in self.rows_for(order, extrapolation, interface):
            if abs(r.step - step) <= 1e-12 * max(1.0, step):
                return r.errors[variable]
        raise KeyError(f"no run with step {step}, {order}, extrapolation={extrapolation}")

    @property
    def worst(self) -> tuple[float, str, VerificationRow | None]:
        """(largest error, its variable, its run) over all runs."""
        best: tuple[float, str, VerificationRow | None] = (0.0, "", None)
        for r in self.rows:
            for name, e in r.errors.items():
                if not e <= best[0]:          # inf and nan count as worse
                    best = (e, name, r)
        return best

    def failures(self, tolerance: float) -> list[tuple[VerificationRow, str, float]]:
        """(run, variable, error) of every error above ``tolerance`` (or not finite)."""
        return [(r, n, e) for r in self.rows for n, e in r.errors.items()
                if not e <= tolerance]

    def verdict(self, tolerance: float) -> str:
        """One line: PASSED or FAILED with the worst error against ``tolerance``."""
        fails = self.failures(tolerance)
        e, name, row = self.worst
        where = (f"{name} vs {self.variables.get(name, name)}, {row.scheme}, step {row.step:g}"
                 f" s" if row is not None else "no runs")
        if fails:
            return (f"verify FAILED: max |error| {e:.3e} ({where}) exceeds the tolerance "
                    f"{tolerance:g}; {len(fails)} of {sum(len(r.errors) for r in self.rows)} "
                    "errors above it")
        return f"verify PASSED: max |error| {e:.3e} ({where}) <= tolerance {tolerance:g}"

    def to_dict(self) -> dict[str, Any]:
        return {"model": self.model, "system": self.system, "stop_time": self.stop_time,
                "steps": self.steps, "variables": self.variables,
                "rows": [r.to_dict() for r in self.rows], "reference": self.reference,
                "timings": self.timings}

    def to_text(self) -> str:
        ref = self.reference
        names = list(self.variables)
        lines = [f"Co-simulation of {self.system} vs the monolithic {self.model} "
                 f"({self.stop_time:g} s)",
                 f"reference: IDAS rtol {ref['rtol']:g}, atol {ref['atol']:g}; compared (by "
                 "name): " + ", ".join(f"{c} ~ {m}" for c, m in self.variables.items()),
                 "error = max over communication points of |cosim - reference|; p = observed "
                 "order vs the previous step; wall = s per simulated s", ""]
        width = max(11, *(len(n) + 1 for n in names))
        for interface in ("cs", "me"):
            rows_if = [r for r in self.rows if r.interface == interface]
            if not rows_if:
                continue
            if interface == "me":
                lines.append("Model Exchange FMUs (master's integrator):")
            header = f"{'scheme':<28}{'step [s]':>10}" + "".join(
                f"{n:>{width}}{'p':>6}" for n in names) + f"{'wall':>9}"
            lines += [header, "-" * len(header)]
            seen: list[tuple[str, bool]] = []
            for r in rows_if:
                if (r.order, r.extrapolation) not in seen:
                    seen.append((r.order, r.extrapolation))
            for order, ex in seen:
                for r in self.rows_for(order, ex, interface):
                    cells = ""
                    for n in names:
                        e, p = r.errors[n], r.observed_order[n]
                        cells += (f"{e:{width}.2e}" if math.isfinite(e)
                                  else f"{'diverged':>{width}}")
                        cells += f"{p:6.2f}" if p is not None else f"{'-':>6}"
                    wall = f"{r.wall_per_second:9.3f}" if r.wall_per_second is not None \
                        else f"{'-':>9}"
                    lines.append(f"{r.scheme:<28}{r.step:10.3g}{cells}{wall}")
            lines.append("")
        lines.append(f"monolithic reference: {ref['run_seconds'] / self.stop_time:.3f} s per "
                     f"simulated s at rtol {ref['rtol']:g}; compile "
                     f"{ref['compile_seconds']:.2f} s")
        return "\n".join(lines)


def _solver_tolerance(system: Any, value: float | None) -> dict[str, dict[str, float]]:
    """``solver.tolerance`` for every element whose FMU has that parameter (bgmodelica's
    Co-Simulation FMUs); nothing for the others."""
    from .fmu import read_fmu_info

    out: dict[str, dict[str, float]] = {}
    if value is None:
        return out
    for el in system.elements:
        if el.fmu_path is None:
            continue
        var = read_fmu_info(el.fmu_path).variables.get("solver.tolerance")
        if var is not None and var.causality == "parameter":
            out[el.name] = {"solver.tolerance": float(value)}
    return out


def verify_model(model: Any, system: Any, steps: Sequence[float] | None = None,
                 stop_time: float | None = None, *, variables: Sequence[str] | None = None,
                 schemes: Sequence[tuple[str, bool]] = SCHEMES, interface: str = "cs",
                 parameters: Mapping[str, Mapping[str, float]] | None = None,
                 record: Sequence[str] = (), solver_tolerance: float | None = 1e-10,
                 reference_rtol: float = 1e-10,
                 simulate_options: Mapping[str, Any] | None = None,
                 progress: Callable[[str], None] | None = None) -> VerificationReport:
    """Compare the monolithic ``model`` with the co-simulation of its parts ``system``.

    ``model``: a :class:`~bgmodelica.Component` or compiled model; ``system``: a
    :class:`~.ssp.SystemStructure` or the path of an ``.ssp``. ``steps``: macro steps [s]
    (default: 4, 2 and 1 times the SSP's step size, else 1e-3); ``stop_time``: default the
    SSP's DefaultExperiment, else 1 s. ``variables``: co-simulation names to compare (default:
    every output that matches a model variable by name, see :func:`match_variables`).
    ``parameters``: element -> {name: value} on top of the SSP bindings;
    ``solver_tolerance``: ``solver.tolerance`` of the elements that have it (None: leave it).
    ``simulate_options`` go to :func:`bgmodelica.simulate` for the reference.
    Bad steps or horizons raise :class:`~.errors.InvalidExperimentError` before anything runs.
    """
    from bgmodelica import CompiledModel, compile, simulate

    from .ssp_read import read_ssp

    say = progress or (lambda _msg: None)
    if isinstance(system, (str, Path)):
        system = read_ssp(system)
    if stop_time is None:
        stop_time = system.stop_time if system.stop_time is not None else 1.0
    if steps is None:
        h = float(system.master.get("step_size", 1e-3))
        steps = (4 * h, 2 * h, h)
    try:
        steps = sorted((float(s) for s in steps), reverse=True)
    except (TypeError, ValueError):
        raise InvalidExperimentError(f"macro steps must be numbers, got {steps!r}") from None
    grid = check_options(steps, stop_time)
    stop_time = float(stop_time)

    say("monolithic reference")
    t0 = time.perf_counter()
    compiled = model if isinstance(model, CompiledModel) else compile(model)
    compile_s = time.perf_counter() - t0
    opts = dict(simulate_options or {})
    opts.setdefault("rtol", reference_rtol)
    opts.setdefault("atol", reference_rtol * 1e-2)
    t0 = time.perf_counter()
    ref = simulate(compiled, stop_time=stop_time, interval=grid, **opts)
    run_s = time.perf_counter() - t0
    pairs = match_variables(system, [*ref.names, *getattr(ref, "aliases", {})], variables,
                            record)

    params: dict[str, dict[str, float]] = _solver_tolerance(system, solver_tolerance)
    for el, values in (parameters or {}).items():
        params.setdefault(el, {}).update(values)
    rows = run_schemes(system, ref, pairs, steps, stop_time, schemes=schemes,
                       interface=interface, parameters=params, record=record,
                       progress=progress)
    name = compiled.name or type(model).__name__
    return VerificationReport(
        str(name), system.name, stop_time, steps, pairs, rows,
        {"rtol": opts["rtol"], "atol": opts["atol"], "output_interval": grid,
         "compile_seconds": compile_s, "run_seconds": run_s},
        {"cosimulation": sum((r.wall_per_second or 0) * stop_time for r in rows)})
