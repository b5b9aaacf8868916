"""Parameter estimation: :func:`fit` a compiled model's parameters to measured trajectories.

Weighted least squares over one or several experiments (:class:`Experiment`: a table whose
columns are matched to the model's variables by name, plus the parameter values that differ
between experiments, e.g. the supply voltage). The model is simulated at exactly the measured
times (single shooting) and ``scipy.optimize.least_squares`` (trust-region reflective, with
bounds) is given the Jacobian of the residuals from the forward sensitivities of the run
(:mod:`.sensitivity`); models with events get central finite differences instead, labelled so
in the report.

Residual of column c at time t_k: ``w_c (y_c(t_k; p) - d_c(t_k))`` with ``w_c`` = 1 / RMS of
the column by default (relative errors; pass ``weights={"rotor.w": 1/sigma}`` for known
noise levels). Missing values (NaN, empty CSV cells) are skipped.

The report (:class:`FitResult`): estimates, standard errors from the covariance
``s^2 (J^T J)^-1`` with ``s^2`` = sum of squared residuals / (n - p), 95 % confidence
intervals from Student's t with n - p degrees of freedom, correlations, and the residuals
(:meth:`FitResult.plot_residuals`). A set of free parameters that the data cannot determine
is refused before the optimization, and checked again at the solution, with the rank of the
(column-normalized) sensitivity matrix: :class:`IdentifiabilityError` names the combination
of parameters that leaves the outputs unchanged.
"""

from __future__ import annotations

import math
import time as _time
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import OptionError, SimulationError
from .identifiability import check_identifiable
from .measured import Experiment, FitError, as_experiments, load_table


@dataclass
class _Prepared:
    name: str
    grid: np.ndarray
    rows: np.ndarray            # positions of the data times in grid
    columns: list[str]
    data: dict[str, np.ndarray]
    weights: dict[str, float]
    obs_idx: list[int]
    col_pos: list[tuple[int, float]]      # (position in obs_idx, sign) per column
    dae: Any
    p: np.ndarray
    params: dict[str, Any]
    masks: dict[str, np.ndarray]


@dataclass
class FitResult:
    """Estimates and their uncertainty; ``to_dict()`` is what ``bgmodelica fit --json``
    prints."""

    model: str
    names: list[str]
    estimates: dict[str, float]
    initial: dict[str, float]
    std_errors: dict[str, float]
    ci95: dict[str, tuple[float, float]]
    covariance: np.ndarray
    correlation: np.ndarray
    cost: float
    rms: float
    n_data: int
    dof: int
    nfev: int
    njev: int
    success: bool
    message: str
    jacobian: str
    singular_values: list[float]
    condition: float
    seconds: float
    units: dict[str, str] = field(default_factory=dict)
    experiments: list[dict[str, Any]] = field(default_factory=list, repr=False)

    def to_dict(self) -> dict[str, Any]:
        return {
            "model": self.model,
            "parameters": {n: {"estimate": self.estimates[n], "std_error": self.std_errors[n],
                               "ci95": list(self.ci95[n]), "initial": self.initial[n],
                               "unit": self.units.get(n, "")} for n in self.names},
            "correlation": np.round(self.correlation, 6).tolist(),
            "cost": self.cost, "rms_weighted_residual": self.rms, "n_data": self.n_data,
            "dof": self.dof, "nfev": self.nfev, "njev": self.njev, "success": self.success,
            "message": self.message, "jacobian": self.jacobian,
            "singular_values": self.singular_values, "condition": self.condition,
            "seconds": self.seconds,
            "experiments": [{"name": e["name"], "rms_residual": {
                c: float(np.sqrt(np.nanmean(e["residual"][c] ** 2))) for c in e["columns"]}}
                for e in self.experiments],
        }

    def table(self) -> str:
        w = max(9, *(len(n) for n in self.names))
        lines = [f"fit of {self.model}: {self.n_data} data, {len(self.names)} parameters, "
                 f"{self.nfev} evaluations, {'converged' if self.success else 'NOT converged'}"
                 f" ({self.message})",
                 f"  {'parameter':<{w}}  {'estimate':>14}  {'std error':>10}  "
                 f"{'95% interval':>31}"]
        for n in self.names:
            lo, hi = self.ci95[n]
            unit = self.units.get(n, "")
            lines.append(f"  {n:<{w}}  {self.estimates[n]:14.8g}  {self.std_errors[n]:10.3g}  "
                         f"[{lo:14.8g}, {hi:14.8g}] {unit}")
        lines.append(f"  weighted rms residual {self.rms:.3g}, condition {self.condition:.3g}, "
                     f"jacobian: {self.jacobian}")
        return "\n".join(lines)

    def plot_residuals(self, path: str | Path | None = None) -> Any:
        """Data and fitted model (left), residuals (right), one row per fitted column."""
        import matplotlib

        if path is not None:
            matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        rows = [(e, c) for e in self.experiments for c in e["columns"]]
        fig, axes = plt.subplots(len(rows), 2, figsize=(10, 2.6 * len(rows)), squeeze=False)
        for (e, c), (a, b) in zip(rows, axes, strict=True):
            label = f"{e['name']}: {c}" if len(self.experiments) > 1 else c
            unit = e["units"].get(c, "")
            a.plot(e["time"], e["data"][c], ".", ms=2.5, color="0.4", label="data")
            a.plot(e["time"], e["model"][c], color="C0", lw=1.2, label="fitted model")
            a.set_ylabel(f"{label} [{unit}]" if unit else label, fontsize=8)
            a.legend(fontsize=7)
            b.plot(e["time"], e["residual"][c], ".", ms=2.5, color="C3")
            b.axhline(0.0, color="0.3", lw=0.8)
            b.set_ylabel(f"residual [{unit}]" if unit else "residual", fontsize=8)
            for ax in (a, b):
                ax.grid(True, alpha=0.3)
        for ax in axes[-1]:
            ax.set_xlabel("time [s]")
        fig.suptitle(f"fit of {self.model}: " + ", ".join(
            f"{n} = {self.estimates[n]:.4g} +- {(self.ci95[n][1] - self.ci95[n][0]) / 2:.2g}"
            for n in self.names) + " (95 %)", fontsize=9)
        fig.tight_layout()
        if path is not None:
            fig.savefig(path, dpi=110)
            plt.close(fig)
        return fig


def _free_spec(free: Any, defaults: dict[str, float], decls: dict[str, Any]):
    """(names, initial values, lower, upper) from ``free``: names, or name -> guess, or
    name -> (guess, low, high)."""
    if isinstance(free, str):
        free = [free]
    if isinstance(free, Mapping):
        items = list(free.items())
    else:
        items = [(n, None) for n in free]
    if not items:
        raise FitError("fit: no free parameter (free=[...], --free NAME)")
    names, x0, lo, hi = [], [], [], []
    for name, spec in items:
        guess, low, high = None, None, None
        if isinstance(spec, (tuple, list)):
            if len(spec) != 3:
                raise FitError(f"free {name}: expected (guess, low, high), got {spec!r}")
            guess, low, high = spec
        else:
            guess = spec
        if guess is None:
            guess = defaults[name]
        d = decls.get(name)
        if low is None:
            low = getattr(d, "min", None) if d is not None else None
        if high is None:
            high = getattr(d, "max", None) if d is not None else None
        low = -np.inf if low is None else float(low)
        high = np.inf if high is None else float(high)
        guess = float(guess)
        if not math.isfinite(guess):
            raise FitError(f"free {name}: the initial value {guess!r} is not finite")
        if not low <= guess <= high or low >= high:
            raise FitError(f"free {name}: the initial value {guess:g} is outside its bounds "
                           f"[{low:g}, {high:g}]")
        names.append(name)
        x0.append(guess)
        lo.append(low)
        hi.append(high)
    if len(set(names)) != len(names):
        raise FitError("fit: a free parameter is named twice")
    return names, np.array(x0), np.array(lo), np.array(hi)


def fit(model: Any, data: Any, free: Any, *, params: Mapping[str, Any] | None = None,
        weights: Mapping[str, float] | None = None, start_time: float = 0.0,
        rtol: float = 1e-8, atol: float = 1e-10, max_step: float | None = None,
        max_nfev: int = 100, jacobian: str = "auto", rank_tol: float | None = None,
        ftol: float = 1e-10, xtol: float = 1e-10, gtol: float = 1e-10,
        units: str = "error") -> FitResult:
    """Estimate the parameters ``free`` of ``model`` from ``data``.

    model: a CompiledModel, a Component or a MODEL reference (``"library.examples:RC"``).
    data: one experiment or a list of them (an :class:`Experiment`, a CSV path, a DataFrame,
    a mapping with ``"time"``). free: parameter names (starting from the model's values), or
    ``{name: guess}``, or ``{name: (guess, low,
    high)}`` (default bounds: the declared ``min``/``max``). params: fixed overrides for every
    experiment. weights: ``{column: 1/sigma}`` (default 1/RMS of each column). jacobian:
    ``"auto"`` (forward sensitivities, or finite differences for models with events),
    ``"forward"`` or ``"fd"``. rank_tol: relative singular value below which the free set is
    refused as non-identifiable (default 1e-6 with forward sensitivities, 1e-4 with finite
    differences).
    """
    from scipy.optimize import least_squares
    from scipy.stats import t as student

    from ..compiler import CompiledModel
    from ..compiler import compile as compile_model
    from .sensitivity import parameter_indices

    t_begin = _time.perf_counter()
    compiled = model if isinstance(model, CompiledModel) else compile_model(model, units=units)
    dae = compiled.dae
    if jacobian not in ("auto", "forward", "fd"):
        raise OptionError(f"jacobian must be 'auto', 'forward' or 'fd', got {jacobian!r}")
    from ..simulate import _selector

    smooth = dae.hybrid is None and _selector(compiled) is None
    if jacobian == "forward" and not smooth:
        from .sensitivity import refuse_events

        refuse_events(dae, selection=None if dae.hybrid is not None else "dynamic")
    use_fd = jacobian == "fd" or (jacobian == "auto" and not smooth)
    if rank_tol is None:
        rank_tol = 1e-4 if use_fd else 1e-6
    experiments = as_experiments(data)
    pnames = [q.name for q in dae.parameters] + [u.name for u in dae.inputs]
    p_default = dae.p_vector(_p_only(dae, dict(params or {}), compiled))
    defaults = dict(zip(pnames, p_default[:len(pnames)], strict=True))   # not discretes
    flat = compiled.reduced.model
    decls = {q.name: q.decl for q in flat.parameters}
    decls.update({u.name: u.decl for u in flat.inputs})
    if isinstance(free, str):
        free = [free]
    given = list(free.keys()) if isinstance(free, Mapping) else list(free)
    wrt = parameter_indices(dae, given)                   # unknown names: a clear error
    resolved = {g: pnames[i] for g, i in zip(given, wrt, strict=True)}   # aliases followed
    free = ({resolved[g]: v for g, v in free.items()} if isinstance(free, Mapping)
            else [resolved[g] for g in given])
    free_names, x0, lo, hi = _free_spec(free, defaults, decls)
    prepared = [_prepare(compiled, e, k, dict(params or {}), weights, free_names, start_time,
                         use_fd) for k, e in enumerate(experiments)]
    n_data = sum(int(m.sum()) for e in prepared for m in e.masks.values())
    n_par = len(free_names)
    if n_data <= n_par:
        raise FitError(f"fit: {n_data} data points for {n_par} free parameters; need more data")
    scale = np.where(x0 != 0, np.abs(x0), 1.0)
    cache: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}

    def evaluate(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        key = np.asarray(theta, dtype=float).tobytes()
        if key not in cache:
            values = theta * scale
            rs, js = [], []
            for e in prepared:
                r, J = _residuals(compiled, e, wrt, free_names, values, rtol, atol, max_step,
                                  use_fd)
                rs.append(r)
                js.append(J)
            cache.clear()
            cache[key] = (np.concatenate(rs), np.vstack(js) * scale)    # d r / d theta
        return cache[key]

    theta0 = x0 / scale
    r0, J0 = evaluate(theta0)
    check_identifiable(J0 / scale, free_names, rank_tol, "at the initial values")
    sol = least_squares(lambda th: evaluate(th)[0], theta0, jac=lambda th: evaluate(th)[1],
                        bounds=(lo / scale, hi / scale), method="trf", x_scale=1.0,
                        ftol=ftol, xtol=xtol, gtol=gtol, max_nfev=max_nfev)
    r, Jt = evaluate(sol.x)
    est = sol.x * scale
    J = Jt / scale                                            # d r / d p (physical units)
    sv = check_identifiable(J, free_names, rank_tol, "at the estimates")
    dof = n_data - n_par
    s2 = float(r @ r) / dof
    U, S, Vt = np.linalg.svd(J, full_matrices=False)
    cov = s2 * (Vt.T / S**2) @ Vt
    se = np.sqrt(np.maximum(np.diag(cov), 0.0))
    tq = float(student.ppf(0.975, dof))
    corr = cov / np.outer(se, se) if np.all(se > 0) else np.full_like(cov, np.nan)
    exps = [_report_experiment(compiled, e, wrt, est, rtol, atol, max_step) for e in prepared]
    units_of = {n: getattr(decls.get(n), "unit", "") or "" for n in free_names}
    return FitResult(
        model=compiled.name, names=free_names,
        estimates={n: float(v) for n, v in zip(free_names, est, strict=True)},
        initial={n: float(v) for n, v in zip(free_names, x0, strict=True)},
        std_errors={n: float(v) for n, v in zip(free_names, se, strict=True)},
        ci95={n: (float(v - tq * s), float(v + tq * s))
              for n, v, s in zip(free_names, est, se, strict=True)},
        covariance=cov, correlation=corr, cost=float(0.5 * r @ r),
        rms=float(np.sqrt(np.mean(r**2))), n_data=n_data, dof=dof, nfev=int(sol.nfev),
        njev=int(sol.njev or 0), success=bool(sol.success), message=str(sol.message),
        jacobian=("central finite differences" if use_fd else "forward sensitivities "
                  "(CasADi AD of the CVODES/IDAS integration)"),
        singular_values=[float(v) for v in sv], condition=float(sv[0] / sv[-1])
        if sv[-1] > 0 else float("inf"), seconds=_time.perf_counter() - t_begin,
        units=units_of, experiments=exps)


def _p_only(dae: Any, params: dict[str, Any], compiled: Any) -> dict[str, Any]:
    from ..core.units import with_units
    from ..overrides import split_overrides

    p_over, _starts = split_overrides(dae, with_units(params, compiled))
    return p_over


def _resolve_column(dae: Any, name: str) -> tuple[str, float] | None:
    from ..overrides import resolve_alias

    pset = {q.name for q in dae.parameters} | {u.name for u in dae.inputs}
    kept, sign = resolve_alias(name, dae.aliases or {}, pset, dae.observed_index)
    if kept in dae.observed_index:
        return kept, sign
    return None


def _prepare(compiled: Any, exp: Experiment, k: int, params: dict[str, Any],
             weights: Mapping[str, float] | None, free: list[str], start_time: float,
             use_fd: bool) -> _Prepared:
    from ..core.units import with_units
    from ..overrides import did_you_mean, split_overrides, with_starts

    dae = compiled.dae
    name = exp.name or (Path(exp.data).name if isinstance(exp.data, (str, Path))
                        else f"experiment {k + 1}")
    times, table = load_table(exp.data, exp.columns, name)
    t0 = float(exp.start_time if exp.start_time is not None else start_time)
    if times[0] < t0 - 1e-12:
        raise FitError(f"{name}: data at t = {times[0]:g} s before the start time {t0:g} s")
    columns, col_pos, keep = [], [], []
    for c in table:
        res = _resolve_column(dae, c)
        if res is None:
            known = list(dae.names[:dae.n_variables or len(dae.names)]) + list(dae.aliases)
            raise FitError(f"{name}: column {c!r} is not a variable of {compiled.name}"
                           f"{did_you_mean(c, known)}")
        columns.append(c)
        keep.append(dae.observed_index[res[0]])
        col_pos.append(res)
    obs_idx = sorted(set(keep))
    col_pos = [(obs_idx.index(dae.observed_index[kept]), sign) for kept, sign in col_pos]
    all_params = with_units({**params, **exp.params}, compiled)
    clash = [f for f in free if f in all_params]
    if clash:
        raise FitError(f"{name}: {clash[0]!r} is both free and set to a value")
    p_over, start_over = split_overrides(dae, all_params)
    p = dae.p_vector(p_over)
    dae_e = with_starts(dae, start_over) if start_over else dae
    grid = times if abs(times[0] - t0) <= 1e-12 * max(1.0, abs(t0)) \
        else np.concatenate([[t0], times])
    rows = np.arange(len(grid) - len(times), len(grid))
    if use_fd:
        h = np.diff(grid)
        if len(h) and np.max(np.abs(h - h[0])) > 1e-9 * h[0]:
            raise FitError(f"{name}: with finite differences (a model with events) the data "
                           "times must be equally spaced from the start time")
    masks = {c: np.isfinite(table[c]) for c in columns}
    wts = {}
    for c in columns:
        given = (exp.weights or {}).get(c, (weights or {}).get(c))
        if given is None:
            v = table[c][masks[c]]
            rms = float(np.sqrt(np.mean(v**2))) if len(v) else 0.0
            given = 1.0 / rms if rms > 0 else 1.0
        wts[c] = float(given)
        if not math.isfinite(wts[c]) or wts[c] <= 0:
            raise FitError(f"{name}: the weight of {c!r} must be positive")
    if not any(m.any() for m in masks.values()):
        raise FitError(f"{name}: no finite data values")
    return _Prepared(name, grid, rows, columns, table, wts, obs_idx, col_pos, dae_e, p,
                     all_params, masks)


def _simulate_exp(compiled: Any, e: _Prepared, wrt: list[int], free: list[str],
                  values: np.ndarray, rtol: float, atol: float, max_step: float | None,
                  use_fd: bool):
    """(Y (N x n_obs) on the grid, S (n_free x N x n_obs))."""
    from .sensitivity import finite_difference_sensitivities, forward_run

    try:
        if not use_fd:
            p = e.p.copy()
            p[wrt] = values
            Y, S, _ = forward_run(compiled, e.dae, p, e.grid, wrt, e.obs_idx, rtol=rtol,
                                  atol=atol, max_step=max_step)
            return Y, S
        over = dict(e.params)
        over.update(dict(zip(free, map(float, values), strict=True)))
        names = [compiled.dae.names[k] for k in e.obs_idx]
        res = finite_difference_sensitivities(
            compiled, free, stop_time=float(e.grid[-1]), start_time=float(e.grid[0]),
            grid=e.grid, params=over, outputs=names, rtol=rtol, atol=atol, max_step=max_step)
        Y = np.column_stack([res[n] for n in names])
        S = np.stack([np.column_stack([res.sensitivity(n, f) for n in names]) for f in free])
        return Y, S
    except SimulationError as err:
        vals = ", ".join(f"{n} = {v:.6g}" for n, v in zip(free, values, strict=True))
        raise FitError(f"{e.name}: the simulation failed at {vals}: {err}") from None


def _residuals(compiled, e: _Prepared, wrt, free, values, rtol, atol, max_step, use_fd):
    Y, S = _simulate_exp(compiled, e, wrt, free, values, rtol, atol, max_step, use_fd)
    rs, js = [], []
    for c, (j, sign) in zip(e.columns, e.col_pos, strict=True):
        m = e.masks[c]
        w = e.weights[c]
        y = sign * Y[e.rows, j]
        rs.append(w * (y - e.data[c])[m])
        js.append((w * sign * S[:, e.rows, j].T)[m])
    r = np.concatenate(rs)
    if not np.all(np.isfinite(r)):
        vals = ", ".join(f"{n} = {v:.6g}" for n, v in zip(free, values, strict=True))
        raise FitError(f"{e.name}: the model gives non-finite values at {vals}")
    return r, np.vstack(js)


def _report_experiment(compiled, e: _Prepared, wrt, est, rtol, atol, max_step) -> dict:
    from ..simulate import simulate
    from .sweeps import on_grid

    over = dict(e.params)
    pnames = [q.name for q in compiled.dae.parameters] + [u.name for u in compiled.dae.inputs]
    over.update({pnames[i]: float(v) for i, v in zip(wrt, est, strict=True)})
    names = [compiled.dae.names[k] for k in e.obs_idx]
    model_vals = {}
    from ..simulate import _selector

    if compiled.dae.hybrid is None and _selector(compiled) is None:
        p = e.p.copy()
        p[wrt] = est
        from .sensitivity import forward_run

        Y, _S, _ = forward_run(compiled, e.dae, p, e.grid, wrt[:1], e.obs_idx, rtol=rtol,
                               atol=atol, max_step=max_step)
    else:
        r = simulate(compiled, stop_time=float(e.grid[-1]), start_time=float(e.grid[0]),
                     interval=float(e.grid[1] - e.grid[0]), params=over, outputs=names,
                     rtol=rtol, atol=atol, max_step=max_step)
        Y = on_grid(r, names, e.grid)
    flat = compiled.reduced.model
    units = {v.name: v.decl.unit or "" for v in flat.variables}
    for c, (j, sign) in zip(e.columns, e.col_pos, strict=True):
        model_vals[c] = sign * Y[e.rows, j]
    t = e.grid[e.rows]
    return {"name": e.name, "time": t, "columns": list(e.columns),
            "data": {c: e.data[c] for c in e.columns}, "model": model_vals,
            "residual": {c: model_vals[c] - e.data[c] for c in e.columns},
            "units": {c: units.get(_resolve_column(compiled.dae, c)[0], "") for c in e.columns}}
