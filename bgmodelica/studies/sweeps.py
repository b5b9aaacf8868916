"""Parameter sweeps and Monte Carlo studies on Dask: :func:`sweep`.

The model compiles once (in the calling process); the compiled model travels once to each
worker (:mod:`.payload`), and every run only changes parameters (``simulate(compiled,
params=...)``), so the integrators built by a worker's first run serve all its later runs.
Runs go to the workers in batches and stream back as they finish (a progress bar on stderr).
A run that fails is recorded with its error and its parameters (the rows computed before the
failure are kept, the rest is NaN); it never aborts the study.

The result is an :class:`xarray.Dataset` (:class:`SweepResult` ``.dataset``) with a ``run``
dimension and the ``time`` axis: one variable per recorded output (``units`` attribute), the
varied parameters as coordinates along ``run``, ``status`` / ``error`` / ``run_seconds`` /
``worker`` per run, and the study's settings as attributes. It saves as netCDF (``.nc``),
Zarr (``.zarr``) and, for the per-run summary metrics (final, min, max, mean of each output),
Parquet (``.parquet``) or CSV. Models with events are sampled at the output times (the right
limit at an event on the grid).
"""

from __future__ import annotations

import json
import math
import os
import socket
import sys
import time as _time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import OptionError, ParameterError, SimulationError
from .cluster import check_scheduler, dask_client, n_workers
from .design import design, parse_grid
from .payload import FmuModel, ModelPayload, payload_for

# -- one batch of runs, on a worker -------------------------------------------------------------

@dataclass
class Settings:
    """What every run of a study shares."""

    grid: np.ndarray
    outputs: list[str]
    start_time: float
    stop_time: float
    interval: float | None
    rtol: float
    atol: float
    solver: str = "auto"
    fixed: dict[str, Any] = field(default_factory=dict)
    max_steps: int = 100000


def _worker_id() -> str:
    return f"{socket.gethostname()}:{os.getpid()}"


def run_batch(payload: ModelPayload, jobs: list[tuple[int, dict[str, float]]],
              settings: Settings) -> list[dict[str, Any]]:
    """Run ``jobs`` (run index, parameter values) of one study on this worker."""
    model, lock = payload.get()
    out = []
    with lock:
        for index, values in jobs:
            out.append(_run_one(model, index, values, settings))
    return out


def _run_one(model: Any, index: int, values: dict[str, float],
             s: Settings) -> dict[str, Any]:
    t0 = _time.perf_counter()
    error = None
    data = np.full((len(s.grid), len(s.outputs)), np.nan)
    try:
        if isinstance(model, FmuModel):
            data = model.simulate(s.grid, {**s.fixed, **values}, s.outputs, s.rtol)
        else:
            from ..simulate import simulate

            try:
                res = simulate(model, stop_time=s.stop_time, interval=s.interval,
                               params={**s.fixed, **values}, start_time=s.start_time,
                               rtol=s.rtol, atol=s.atol, solver=s.solver, outputs=s.outputs,
                               max_steps=s.max_steps)
            except SimulationError as err:
                if err.result is not None and len(err.result.time):
                    data = on_grid(err.result, s.outputs, s.grid)
                raise
            data = on_grid(res, s.outputs, s.grid)
    except Exception as err:  # noqa: BLE001 -- recorded with the run, never lost
        from ..validate import one_line

        error = f"{type(err).__name__}: {one_line(str(err), 500)}"
    return {"run": index, "values": np.asarray(data, dtype=float), "error": error,
            "seconds": _time.perf_counter() - t0, "worker": _worker_id()}


def on_grid(result: Any, names: Sequence[str], grid: np.ndarray) -> np.ndarray:
    """Values of ``names`` at the ``grid`` times (the last row of a time: the right limit at an
    event); NaN where the result has no row at a grid time (a failed run's tail)."""
    t = np.asarray(result.time, dtype=float)
    cols = np.column_stack([result[n] for n in names]) if names else np.zeros((len(t), 0))
    if len(t) == len(grid) and np.array_equal(t, grid):
        return cols
    idx = np.searchsorted(t, grid, side="right") - 1
    scale = max(1.0, float(np.max(np.abs(grid)))) if len(grid) else 1.0
    ok = (idx >= 0) & (np.abs(t[np.clip(idx, 0, None)] - grid) <= 1e-12 * scale) \
        if len(t) else np.zeros(len(grid), bool)
    out = np.full((len(grid), len(names)), np.nan)
    out[ok] = cols[idx[ok]]
    return out


# -- the study ------------------------------------------------------------------------------------

@dataclass
class SweepResult:
    """The runs of a study: ``dataset`` (xarray) plus the timing of the study in ``meta``."""

    dataset: Any
    meta: dict[str, Any] = field(default_factory=dict)

    def __getitem__(self, name: str) -> Any:
        return self.dataset[name]

    def __repr__(self) -> str:
        """One line: model, runs, outputs and parameters (the data: :attr:`dataset`)."""
        attrs = self.dataset.attrs

        def few(names: list[str]) -> str:
            return ", ".join(names[:3]) + (f", ... ({len(names)})" if len(names) > 3 else "")

        return (f"SweepResult({attrs.get('model', '?')}: {attrs.get('n_runs', '?')} runs, "
                f"{attrs.get('n_failed', 0)} failed; outputs {few(self.outputs)}; "
                f"parameters {few(self.parameters)})")

    @property
    def outputs(self) -> list[str]:
        return json.loads(self.dataset.attrs["outputs"])

    @property
    def parameters(self) -> list[str]:
        return json.loads(self.dataset.attrs["parameters"])

    @property
    def ok(self) -> np.ndarray:
        """Boolean mask of the runs that succeeded."""
        return np.asarray(self.dataset["status"].values == "ok")

    def failures(self) -> list[dict[str, Any]]:
        """Failed runs: index, parameter values and error message."""
        ds = self.dataset
        out = []
        for k in np.flatnonzero(~self.ok):
            out.append({"run": int(ds["run"].values[k]),
                        "parameters": {p: float(ds[p].values[k]) for p in self.parameters},
                        "error": str(ds["error"].values[k])})
        return out

    def summary(self):
        """Per-run metrics as a pandas DataFrame: run, parameters, status, error, seconds, and
        ``OUTPUT:final``, ``:min``, ``:max``, ``:mean`` of each output (NaN-aware)."""
        import pandas as pd

        ds = self.dataset
        cols: dict[str, Any] = {"run": ds["run"].values}
        for p in self.parameters:
            cols[p] = ds[p].values
        cols["status"] = ds["status"].values.astype(str)
        cols["error"] = ds["error"].values.astype(str)
        cols["run_seconds"] = ds["run_seconds"].values
        import warnings

        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)     # all-NaN rows of failed runs
            for name in self.outputs:
                v = ds[name].values
                last = np.array([row[np.isfinite(row)][-1] if np.isfinite(row).any()
                                 else np.nan for row in v])
                cols[f"{name}:final"] = last
                cols[f"{name}:min"] = np.nanmin(v, axis=1)
                cols[f"{name}:max"] = np.nanmax(v, axis=1)
                cols[f"{name}:mean"] = np.nanmean(v, axis=1)
        return pd.DataFrame(cols)

    def save(self, path: str | Path) -> Path:
        """Write by extension: ``.nc`` (netCDF 4 via h5netcdf, else netCDF 3 via scipy),
        ``.zarr`` (the dataset), ``.parquet`` / ``.csv`` (the summary metrics)."""
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix == ".nc":
            try:
                import h5netcdf  # noqa: F401

                self.dataset.to_netcdf(path, engine="h5netcdf")
            except ImportError:
                self.dataset.to_netcdf(path, engine="scipy")
        elif suffix == ".zarr":
            import warnings

            with warnings.catch_warnings():
                warnings.simplefilter("ignore")   # zarr v3: consolidated metadata notice
                self.dataset.to_zarr(path, mode="w")
        elif suffix == ".parquet":
            self.summary().to_parquet(path, index=False)
        elif suffix == ".csv":
            self.summary().to_csv(path, index=False)
        else:
            raise OptionError(f"-o {path}: unknown format (use .nc, .zarr, .parquet or .csv)")
        return path

    def plot_band(self, name: str, path: str | Path | None = None,
                  quantiles: tuple[float, float] = (0.05, 0.95), ax: Any = None,
                  show_runs: int = 0) -> Any:
        """Band plot of ``name`` over the successful runs: mean, median, the ``quantiles``
        band and the min-max envelope (``show_runs`` individual runs drawn thinly)."""
        import matplotlib

        if path is not None:
            matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        if name not in self.dataset:
            raise OptionError(f"{name!r} was not recorded; recorded: "
                              f"{', '.join(self.outputs)}")
        t = self.dataset["time"].values
        v = self.dataset[name].values[self.ok]
        if not len(v):
            raise OptionError("no successful run to plot")
        fig = None
        if ax is None:
            fig, ax = plt.subplots(figsize=(8, 4.5))
        lo, hi = np.nanquantile(v, quantiles, axis=0)
        ax.fill_between(t, np.nanmin(v, axis=0), np.nanmax(v, axis=0), color="C0", alpha=0.12,
                        lw=0, label="min - max")
        ax.fill_between(t, lo, hi, color="C0", alpha=0.3, lw=0,
                        label=f"{quantiles[0]:.0%} - {quantiles[1]:.0%}")
        for row in v[:show_runs]:
            ax.plot(t, row, color="0.5", lw=0.4)
        ax.plot(t, np.nanmean(v, axis=0), color="C0", lw=1.5, label="mean")
        ax.plot(t, np.nanmedian(v, axis=0), color="C1", lw=1.0, ls="--", label="median")
        unit = self.dataset[name].attrs.get("units", "")
        ax.set_xlabel("time [s]")
        ax.set_ylabel(f"{name} [{unit}]" if unit else name)
        ax.set_title(f"{self.dataset.attrs.get('model', '')}: {name}, {len(v)} runs")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize=8)
        if path is not None and fig is not None:
            fig.tight_layout()
            fig.savefig(path, dpi=120)
            plt.close(fig)
        return fig


def sweep(model: Any, grid: Mapping[str, Any] | None = None, samples: int | None = None,
          distributions: Mapping[str, Any] | None = None, seed: int | None = None,
          outputs: Sequence[str] | None = None, stop_time: float = 1.0,
          interval: float | None = None, *, params: Mapping[str, Any] | None = None,
          start_time: float = 0.0, rtol: float = 1e-6, atol: float = 1e-8,
          solver: str = "auto", max_steps: int = 100000, sampling: str = "random",
          client: Any = None, scheduler: str | None = "local", workers: int | None = None,
          batch_size: int | None = None, progress: bool = True, ref: str | None = None,
          ref_kwargs: Mapping[str, Any] | None = None, ship: str = "auto",
          units: str = "error") -> SweepResult:
    """Run ``model`` over a parameter grid and/or Monte Carlo samples.

    model: a CompiledModel, a Component (compiled once here), a MODEL reference
    (``"library.examples:RC"``; with ``ref_kwargs``, and workers may load it themselves) or
    the path of an ``.fmu``.
    grid: ``{name: values}`` (a sequence, ``"start:stop:n"``, ``"start:stop:n:log"`` or
    ``"v1,v2"``), Cartesian product of the axes. samples + distributions: ``samples`` draws of
    ``{name: "normal(3,0.1)" | "uniform(a,b)" | "lognormal(mu,s)" | "triangular(a,m,b)" |
    "+-5%" | scipy.stats distribution}``, reproducible with ``seed``; ``sampling="lhs"`` for a
    Latin hypercube. With both, each grid point gets ``samples`` draws.
    outputs: variables to record (default: the states). params: fixed overrides for every
    run. stop_time, interval, start_time, rtol, atol, solver, max_steps: as in
    :func:`bgmodelica.simulate`.
    client / scheduler / workers: see :mod:`bgmodelica.studies.cluster` (``scheduler=
    "serial"`` runs in this process without Dask). batch_size: runs per Dask task (default:
    about 8 tasks per worker). ship: ``"auto"`` (pickle the compiled model, else the model
    reference ``ref`` + ``ref_kwargs`` compiled once per worker), ``"pickle"`` or
    ``"reference"``.
    """
    from ..validate import check_run_options, output_grid

    opt = check_run_options(start_time=start_time, stop_time=stop_time, interval=interval,
                            rtol=rtol, atol=atol, max_steps=max_steps, solver=solver)
    scheduler, workers = check_scheduler(scheduler if client is None else "local", workers)
    if ship not in ("auto", "pickle", "reference"):
        raise OptionError(f"ship must be 'auto', 'pickle' or 'reference', got {ship!r}")
    t_start = _time.perf_counter()
    payload = payload_for(model, ref=ref, kwargs=dict(ref_kwargs or {}), units=units,
                          mode=ship)
    local, _lock = payload.get()
    fixed = dict(params or {})
    if isinstance(local, FmuModel):
        outputs = list(outputs) if outputs is not None else local.default_outputs()
        default = local.default
        for n in [*outputs, *fixed, *(grid or {}), *(distributions or {})]:
            if n not in local.variables:
                raise ParameterError(f"{n!r} is not a variable of the FMU {local.name}")
        units_of = local.units
        name = local.name
    else:
        outputs, default, units_of = _check_names(local, outputs, fixed, grid, distributions)
        name = local.name
    names, values = design(grid, samples, distributions, seed, default, sampling)
    times = output_grid(opt["start_time"], opt["stop_time"], opt["interval"], len(outputs))
    settings = Settings(times, list(outputs), opt["start_time"], opt["stop_time"],
                        opt["interval"], opt["rtol"], opt["atol"], solver, fixed,
                        opt["max_steps"])
    jobs = [(k, {n: float(v) for n, v in zip(names, row, strict=True)})
            for k, row in enumerate(values)]
    bar = _progress_bar(len(jobs), f"sweep {name}", progress)
    outcomes: dict[int, dict[str, Any]] = {}
    address, workers_used = "serial", 1
    try:
        if scheduler == "serial" and client is None:
            for job in jobs:
                outcomes[job[0]] = run_batch(payload, [job], settings)[0]
                bar.update(1)
        else:
            with dask_client(client, scheduler, workers) as cl:
                address = str(cl.scheduler.address)
                workers_used = n_workers(cl)
                _run_on_dask(cl, payload, jobs, settings, batch_size, workers_used,
                             outcomes, bar)
    finally:
        bar.close()
    wall = _time.perf_counter() - t_start
    ds = _dataset(name, names, values, outcomes, settings, units_of, local)
    ds.attrs.update({
        "scheduler": address, "workers": workers_used, "seed": -1 if seed is None else seed,
        "samples": -1 if samples is None else int(samples), "sampling": sampling,
        "grid": json.dumps({k: parse_grid(k, v).tolist() for k, v in (grid or {}).items()}),
        "distributions": json.dumps({k: str(v) for k, v in (distributions or {}).items()}),
        "fixed_parameters": json.dumps({k: str(v) for k, v in fixed.items()}),
        "payload": payload.kind, "payload_bytes": payload.size, "wall_seconds": wall,
    })
    meta = {"wall_seconds": wall, "workers": workers_used, "scheduler": address,
            "payload": payload.kind, "payload_bytes": payload.size,
            "n_runs": len(jobs), "n_failed": int(np.sum(ds["status"].values != "ok"))}
    return SweepResult(ds, meta)


def _run_on_dask(cl, payload, jobs, settings, batch_size, workers, outcomes, bar) -> None:
    from distributed import as_completed

    if batch_size is None:
        batch_size = max(1, math.ceil(len(jobs) / (8 * max(workers, 1))))
    if isinstance(batch_size, bool) or not isinstance(batch_size, int) or batch_size < 1:
        raise OptionError(f"batch_size must be a positive integer, got {batch_size!r}")
    batches = [jobs[k:k + batch_size] for k in range(0, len(jobs), batch_size)]
    shipped = cl.scatter(payload, broadcast=True, hash=False)
    futures = {}
    for batch in batches:
        fut = cl.submit(run_batch, shipped, batch, settings, pure=False, retries=1)
        futures[fut] = batch
    try:
        for fut in as_completed(list(futures)):
            batch = futures[fut]
            try:
                for out in fut.result():
                    outcomes[out["run"]] = out
            except Exception as err:  # noqa: BLE001 -- a lost worker: the runs are failures
                for index, _values in batch:
                    outcomes[index] = {"run": index, "values": None, "seconds": float("nan"),
                                       "worker": "", "error": f"{type(err).__name__}: {err}"}
            bar.update(len(batch))
    finally:
        for fut in futures:
            fut.release()
        shipped.release()


def _progress_bar(total: int, desc: str, enabled: bool):
    from tqdm.auto import tqdm

    return tqdm(total=total, desc=desc, unit="run", file=sys.stderr, disable=not enabled,
                leave=False)


def _check_names(compiled, outputs, fixed, grid, distributions):
    """Validate output and parameter names against the compiled model (before any run);
    returns the outputs, a function giving a parameter's value in the model, and units."""
    from ..core.units import with_units
    from ..overrides import split_overrides
    from ..simulate import _output_indices

    dae = compiled.dae
    if outputs is None:
        outputs = list(dae.state_names)
    outputs = list(outputs)
    if not outputs:
        raise OptionError("no outputs to record")
    _output_indices(dae, outputs, compiled.reduced.model.aliases)
    varied = {n: 0.0 for n in [*(grid or {}), *(distributions or {})]}
    split_overrides(dae, {**with_units(dict(fixed), compiled), **varied})
    pnames = [q.name for q in dae.parameters] + [u.name for u in dae.inputs]
    p_fixed = dae.p_vector({k: v for k, v in with_units(dict(fixed), compiled).items()
                            if k in pnames})

    def default(name: str) -> float:
        if name in pnames:
            return float(p_fixed[pnames.index(name)])
        k = dae.observed_index.get(name)
        if k is not None:
            for kk, v in dae.fixed:
                if kk == k:
                    return float(v)
        raise OptionError(f"{name!r}: a relative spread (+-P%) needs a parameter or a fixed "
                          "start value; give an explicit distribution")

    flat = compiled.reduced.model
    units_of = {v.name: v.decl.unit or "" for v in flat.variables}
    units_of.update({q.name: q.decl.unit or "" for q in flat.parameters})
    units_of.update({u.name: u.decl.unit or "" for u in flat.inputs})
    for a, (rep, _s) in flat.aliases.items():
        units_of.setdefault(a, units_of.get(rep, ""))
    return outputs, default, units_of


def _dataset(name, names, values, outcomes, s: Settings, units_of, local):
    import xarray as xr

    n_runs, n_t, n_out = len(values), len(s.grid), len(s.outputs)
    data = np.full((n_runs, n_t, n_out), np.nan)
    status = np.array(["ok"] * n_runs, dtype=object)
    error = np.array([""] * n_runs, dtype=object)
    seconds = np.full(n_runs, np.nan)
    worker = np.array([""] * n_runs, dtype=object)
    for k in range(n_runs):
        out = outcomes.get(k)
        if out is None:
            status[k], error[k] = "failed", "the run was not executed"
            continue
        if out["values"] is not None:
            data[k] = out["values"]
        if out["error"]:
            status[k], error[k] = "failed", out["error"]
        seconds[k] = out["seconds"]
        worker[k] = out["worker"]
    data_vars = {}
    for j, o in enumerate(s.outputs):
        data_vars[o] = (("run", "time"), data[:, :, j], {"units": units_of.get(o, "")})
    data_vars["status"] = ("run", status.astype(str))
    data_vars["error"] = ("run", error.astype(str))
    data_vars["run_seconds"] = ("run", seconds, {"units": "s"})
    data_vars["worker"] = ("run", worker.astype(str))
    coords = {"run": np.arange(n_runs), "time": ("time", s.grid, {"units": "s"})}
    for k, p in enumerate(names):
        if p in data_vars:
            raise OptionError(f"{p!r} is both varied and recorded as an output")
        coords[p] = ("run", values[:, k], {"units": units_of.get(p, "")})
    from .. import __version__

    attrs = {"model": name, "outputs": json.dumps(list(s.outputs)),
             "parameters": json.dumps(list(names)), "start_time": s.start_time,
             "stop_time": s.stop_time, "rtol": s.rtol, "atol": s.atol, "solver": s.solver,
             "n_runs": n_runs, "n_failed": int(np.sum(status != "ok")),
             "bgmodelica_version": __version__,
             "kind": "fmu" if isinstance(local, FmuModel) else "compiled model"}
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)
