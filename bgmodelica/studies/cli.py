"""Command-line subcommands of the studies (wired into ``bgmodelica`` through
``bgmodelica.cli._EXTENSIONS`` with :func:`register`):

``bgmodelica sweep MODEL --grid NAME=start:stop:n --sample NAME=DIST --n N --seed S
--scheduler local|serial|tcp://HOST:PORT --workers N -o sweep.nc [-o summary.parquet]``
    parameter sweep / Monte Carlo on Dask (``--outputs``, ``--set``, ``--stop-time``,
    ``--interval``, ``--plot band.png --plot-var NAME``, ``--sampling lhs``). ``MODEL`` may
    also be an ``.fmu``.
``bgmodelica fit MODEL data.csv [more.csv ...] --free NAME[=GUESS[:LOW:HIGH]] [--json]``
    least-squares estimation of the free parameters from measured trajectories (columns
    matched to variables by name), with standard errors and 95 % intervals
    (``--set``, ``--weight COLUMN=1/SIGMA``, ``--plot residuals.png``).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..errors import OptionError

_FORMATS = (".nc", ".zarr", ".parquet", ".csv")


def _pairs(items: list[str], option: str) -> dict[str, str]:
    out: dict[str, str] = {}
    for item in items:
        name, sep, value = item.partition("=")
        name = name.strip()
        if not sep or not name or not value.strip():
            raise OptionError(f"{option} expects NAME=VALUE, got {item!r}")
        if name in out:
            raise OptionError(f"{option} {name} is given twice")
        out[name] = value.strip()
    return out


def _check_outputs(paths: list[str]) -> list[Path]:
    from ..output_checks import check_distinct_outputs, check_output_file

    out = []
    for p in paths:
        path = Path(p)
        if path.suffix.lower() not in _FORMATS:
            raise OptionError(f"-o {p}: unknown format; use {', '.join(_FORMATS)} (netCDF, "
                              "Zarr, Parquet or CSV summary)")
        if path.suffix.lower() == ".zarr":
            if path.exists() and not path.is_dir():
                raise OptionError(f"-o {p}: exists and is not a Zarr directory")
            check_output_file(path.parent / (path.name + ".probe"), "-o")
        else:
            check_output_file(path, "-o")
        out.append(path)
    check_distinct_outputs(*[("-o", p) for p in out])
    return out


def _load(args: argparse.Namespace):
    """(model: CompiledModel or .fmu path, reference or None)."""
    from ..cli import _model_kwargs

    if args.model.lower().endswith(".fmu"):
        if args.arg:
            raise OptionError("--arg applies to Python models, not to an FMU")
        if not Path(args.model).is_file():
            raise OptionError(f"{args.model}: no such FMU")
        return args.model, None, {}
    from ..compiler import compile as compile_model
    from ..loader import load_model

    kwargs = _model_kwargs(args.arg)
    return compile_model(load_model(args.model, **kwargs), units=args.units), args.model, kwargs


def cmd_sweep(args: argparse.Namespace) -> int:
    from ..cli import _parse_sets
    from ..output_checks import check_plot_file
    from ..validate import check_run_options
    from .cluster import check_scheduler
    from .sweeps import sweep

    check_run_options(stop_time=args.stop_time, interval=args.interval, rtol=args.rtol,
                      atol=args.atol)
    check_scheduler(args.scheduler, args.workers)
    grid = _pairs(args.grid, "--grid")
    dists = _pairs(args.sample, "--sample")
    if dists and args.n is None:
        raise OptionError("--sample needs the number of samples: --n N")
    if args.n is not None and not dists:
        raise OptionError("--n needs at least one --sample NAME=DIST")
    outputs = args.output or []
    if args.plot:
        check_plot_file(args.plot, "--plot")
    if args.plot_var and not args.plot:
        raise OptionError("--plot-var needs --plot FILE")
    paths = _check_outputs(outputs)
    model, ref, kwargs = _load(args)
    name = Path(model).stem if isinstance(model, str) else model.name
    if not paths:
        paths = _check_outputs([f"{name}_sweep.nc"])
    show = args.progress if args.progress is not None else sys.stderr.isatty()
    res = sweep(model, grid=grid or None, samples=args.n, distributions=dists or None,
                seed=args.seed, outputs=args.outputs, stop_time=args.stop_time,
                interval=args.interval, params=_parse_sets(args.set), rtol=args.rtol,
                atol=args.atol, solver=args.solver, sampling=args.sampling,
                scheduler=args.scheduler,
                workers=args.workers, batch_size=args.batch_size, progress=show, ref=ref,
                ref_kwargs=kwargs, units=args.units)
    for p in paths:
        res.save(p)
    m = res.meta
    print(f"{name}: {m['n_runs']} runs ({m['n_failed']} failed) on {m['workers']} worker(s) "
          f"[{m['scheduler']}] in {m['wall_seconds']:.2f} s -> "
          + ", ".join(str(p) for p in paths))
    for f in res.failures()[:5]:
        vals = ", ".join(f"{k}={v:.6g}" for k, v in f["parameters"].items())
        print(f"failed run {f['run']} ({vals}): {f['error']}")
    if m["n_failed"] > 5:
        print(f"... {m['n_failed'] - 5} more failed runs (see 'status' and 'error')")
    if args.plot:
        var = args.plot_var or res.outputs[0]
        res.plot_band(var, args.plot)
        print(f"band plot of {var} -> {args.plot}")
    return 1 if m["n_failed"] == m["n_runs"] else 0


def _free(items: list[str]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for item in items:
        name, sep, spec = item.partition("=")
        name = name.strip()
        if not name:
            raise OptionError(f"--free expects NAME[=GUESS[:LOW:HIGH]], got {item!r}")
        if name in out:
            raise OptionError(f"--free {name} is given twice")
        if not sep:
            out[name] = None
            continue
        parts = spec.split(":")
        try:
            vals = [float(v) if v.strip() else None for v in parts]
        except ValueError:
            raise OptionError(f"--free {item!r}: GUESS, LOW and HIGH must be numbers") from None
        if any(v is not None and not math.isfinite(v) for v in vals[:1]) \
                or len(vals) not in (1, 3):
            raise OptionError(f"--free {item!r}: expected NAME=GUESS or NAME=GUESS:LOW:HIGH")
        out[name] = vals[0] if len(vals) == 1 else tuple(vals)
    return out


def cmd_fit(args: argparse.Namespace) -> int:
    from ..cli import _parse_sets
    from ..output_checks import check_plot_file
    from .fitting import Experiment, fit

    if not args.free:
        raise OptionError("fit needs at least one --free NAME")
    free = _free(args.free)
    for d in args.data:
        if not Path(d).is_file():
            raise OptionError(f"{d}: no such data file")
    if args.plot:
        check_plot_file(args.plot, "--plot")
    weights = {k: float(v) for k, v in _pairs(args.weight, "--weight").items()}
    model, _ref, _kw = _load(args)
    if isinstance(model, str):
        raise OptionError("fit works on Python models (the sensitivities come from the "
                          "compiled DAE), not on FMUs")
    res = fit(model, [Experiment(d) for d in args.data], free, params=_parse_sets(args.set),
              weights=weights or None, start_time=args.start_time, rtol=args.rtol,
              atol=args.atol, max_nfev=args.max_nfev, jacobian=args.jacobian)
    if args.json:
        print(json.dumps(res.to_dict(), indent=2))
    else:
        print(res.table())
    if args.plot:
        res.plot_residuals(args.plot)
        if not args.json:
            print(f"residuals -> {args.plot}")
    return 0 if res.success else 1


def register(sub: Any, model_args: Callable[[argparse.ArgumentParser], None]) -> None:
    sw = sub.add_parser("sweep", help="parameter sweep / Monte Carlo on Dask -> netCDF, Zarr, "
                                      "Parquet")
    model_args(sw)
    sw.add_argument("--grid", action="append", default=[], metavar="NAME=SPEC",
                    help="grid axis: start:stop:n, start:stop:n:log or v1,v2,... "
                         "(several: Cartesian product)")
    sw.add_argument("--sample", action="append", default=[], metavar="NAME=DIST",
                    help="Monte Carlo: normal(m,s), uniform(a,b), lognormal(mu,s), "
                         "triangular(a,m,b) or +-P%% of the model's value")
    sw.add_argument("--n", type=int, default=None, help="number of samples")
    sw.add_argument("--seed", type=int, default=None, help="random seed (reproducible draws)")
    sw.add_argument("--sampling", choices=("random", "lhs"), default="random",
                    help="independent draws or a Latin hypercube")
    sw.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                    help="fixed override for every run")
    sw.add_argument("--outputs", nargs="+", default=None, metavar="NAME",
                    help="variables to record (default: the states)")
    sw.add_argument("--stop-time", type=float, default=1.0, help="[s] (default 1)")
    sw.add_argument("--interval", type=float, default=None, help="output step [s]")
    sw.add_argument("--rtol", type=float, default=1e-6)
    sw.add_argument("--atol", type=float, default=1e-8)
    sw.add_argument("--solver", choices=("auto", "idas", "cvodes"), default="auto",
                    help="integrator (auto: CVODES when the reduced model is an ODE, IDAS "
                         "otherwise)")
    sw.add_argument("--scheduler", default="local",
                    help="'local' (a LocalCluster, default), 'serial' (no Dask) or the address "
                         "of a Dask scheduler, e.g. tcp://HOST:8786")
    sw.add_argument("--workers", type=int, default=None,
                    help="local: number of worker processes; remote: wait for this many")
    sw.add_argument("--batch-size", type=int, default=None, help="runs per Dask task")
    sw.add_argument("-o", "--output", action="append", default=None, metavar="FILE",
                    help="sweep.nc (netCDF), sweep.zarr, summary.parquet / .csv; repeatable "
                         "(default <Model>_sweep.nc)")
    sw.add_argument("--plot", help="band plot (mean, quantiles, min-max) PNG/SVG/PDF")
    sw.add_argument("--plot-var", help="variable of the band plot (default: the first output)")
    sw.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                    help="progress bar (default: when stderr is a terminal)")
    sw.set_defaults(func=cmd_sweep)

    ft = sub.add_parser("fit", help="estimate parameters from measured trajectories")
    model_args(ft)
    ft.add_argument("data", nargs="+", help="CSV file(s): first column 'time', other columns "
                                            "named like model variables; one per experiment")
    ft.add_argument("--free", action="append", default=[], metavar="NAME[=GUESS[:LOW:HIGH]]",
                    help="parameter to estimate (repeatable)")
    ft.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                    help="fixed override for every experiment")
    ft.add_argument("--weight", action="append", default=[], metavar="COLUMN=W",
                    help="weight of a column (1/sigma; default 1/RMS of the column)")
    ft.add_argument("--start-time", type=float, default=0.0, help="model start time [s]")
    ft.add_argument("--rtol", type=float, default=1e-8)
    ft.add_argument("--atol", type=float, default=1e-10)
    ft.add_argument("--max-nfev", type=int, default=100, help="most model evaluations")
    ft.add_argument("--jacobian", choices=("auto", "forward", "fd"), default="auto",
                    help="forward sensitivities (smooth models) or finite differences")
    ft.add_argument("--json", action="store_true", help="machine-readable report")
    ft.add_argument("--plot", help="residual plot (PNG/SVG/PDF)")
    ft.set_defaults(func=cmd_fit)
    for p in (sw, ft):
        p.add_argument("--units", choices=("error", "warn", "off"), default="error",
                       help="dimensional analysis of the equations at compile time")
