"""Command-line subcommands of the co-simulation package (wired into ``bgmodelica`` through
``bgmodelica.cli._EXTENSIONS`` with :func:`register`):

``bgmodelica cosim SSP [--step H] [--order jacobi|gauss-seidel] [--stop-time T] [-o out.csv]``
    co-simulate an SSP set-up with the fixed-step master (``--extrapolation``,
    ``--interface cs|me|auto``, ``--no-propagate``, ``--set ELEMENT.NAME=VALUE``,
    ``--record ELEMENT.VAR``, ``--plot out.png``).
``bgmodelica cosim MODEL.fmu [--step H] [--stop-time T] [--input in.csv] [-o out.csv]``
    one FMU through the same master (:func:`~.single.simulate_fmu`): ``--step`` is the
    communication and output interval, ``--set NAME=VALUE`` (any type), ``--record VAR``,
    ``--interface`` (default auto: CS when the FMU has it); the same as ``simulate-fmu``.
``bgmodelica verify MODEL SSP [--step 4e-3,2e-3,1e-3] [--stop-time T] [--tolerance TOL] [--json]``
    any model, monolithic vs the co-simulation of its parts (variables matched by name,
    :func:`~.verify.verify_model`): error table per variable, observed convergence order,
    both orders with and without extrapolation (``--order``, ``--extrapolation``), wall time
    per simulated second; exit status 1 when an error exceeds ``--tolerance`` (``--vars``,
    ``--set``, ``--record``, ``--interface``, ``--static-states``). The paper's robot with its
    split check, Model Exchange runs and fmucontainer cross-check is
    :func:`library.robots.verification.verify_robot`.

Bad input (an unsafe or broken SSP/FMU, an inconsistent set-up, non-finite or absurd times
and steps, an output folder that does not exist) ends in one line on stderr and exit status
2, before anything runs; the output files are written only after a successful run, under a
temporary name renamed at the end (no partial output).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..errors import ParameterError
from .errors import CosimError, InvalidExperimentError


def _sets(items: list[str]) -> dict[str, dict[str, float]]:
    out: dict[str, dict[str, float]] = {}
    for item in items:
        name, sep, value = item.partition("=")
        el, dot, var = name.strip().partition(".")
        if not sep or not dot or not var:
            raise ParameterError(f"--set expects ELEMENT.NAME=VALUE, got {item!r}")
        try:
            x = float(value)
        except ValueError:
            raise ParameterError(f"--set {name}: {value!r} is not a number") from None
        if not math.isfinite(x):
            raise ParameterError(f"--set {name}: {value!r} is not finite")
        out.setdefault(el, {})[var.strip()] = x
    return out


def _writable(path: str | None, what: str) -> Path | None:
    """``path`` as a Path after checking that its folder exists (before the run)."""
    if not path:
        return None
    p = Path(path)
    if p.is_dir():
        raise CosimError(f"{what} {p} is a folder, not a file")
    if not p.parent.is_dir():
        raise CosimError(f"cannot write the {what} {p}: the folder {p.parent} does not exist")
    return p


def _write_atomically(path: Path, write: Callable[[Path], Any], what: str) -> None:
    """``write(tmp)`` to a temporary file next to ``path``, then rename it to ``path``."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=path.suffix,
                               dir=path.parent)
    os.close(fd)
    try:
        write(Path(tmp))
        os.replace(tmp, path)
    except OSError as err:
        Path(tmp).unlink(missing_ok=True)
        raise CosimError(f"cannot write the {what} {path}: {err.strerror or err}") from None
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _is_fmu(path: str) -> bool:
    return Path(path).suffix.lower() == ".fmu"


def cmd_cosim(args: argparse.Namespace) -> int:
    """``bgmodelica cosim``: run an SSP set-up (or one FMU), write the CSV (and a plot)."""
    from .master import Master
    from .ssp_read import read_ssp

    for value, what in ((args.stop_time, "--stop-time"), (args.step, "--step")):
        if value is not None and not (math.isfinite(value) and value > 0):
            raise InvalidExperimentError(f"{what} must be a finite number > 0, got {value}")
    if _is_fmu(args.ssp):
        return _run_fmu(args, args.ssp, args.step, "_cosim")
    if args.input:
        raise CosimError("--input is for a single FMU; an SSP set-up drives its inputs "
                         "with connections")
    sets = _sets(args.set)
    out_arg = _writable(args.output, "output file")
    plot = _writable(args.plot, "plot")
    system = read_ssp(args.ssp)
    safe = re.sub(r"[^A-Za-z0-9_.-]", "_", system.name).lstrip(".") or "system"
    out = out_arg or _writable(f"{safe}_cosim.csv", "output file")   # in the working folder
    assert out is not None
    master = Master(system, interface=args.interface or "cs", me_euler_step=args.euler_step)
    order = args.order or system.master.get("order", "jacobi")
    extrapolation = args.extrapolation
    if extrapolation is None:
        extrapolation = bool(system.master.get("extrapolation", False))
    res = master.simulate(args.stop_time, args.step, order=order, extrapolation=extrapolation,
                          propagate=not args.no_propagate, parameters=sets,
                          record=args.record or ())
    if args.plot_vars:
        missing = [n for n in args.plot_vars if n not in res.names]
        if missing:
            raise CosimError(f"--plot-vars: no result variable {', '.join(missing)} (record "
                             "locals with --record ELEMENT.VAR)")
    _write_atomically(out, res.to_csv, "output file")
    meta = res.meta
    print(f"{system.name}: {len(system.elements)} elements ({', '.join(system.element_names)}),"
          f" {meta['order']}{' + extrapolation' if meta['extrapolation'] else ''}, "
          f"step {meta['step']:g} s, {meta['steps']} steps to t = {meta['stop_time']:g} s; "
          f"run {meta['run_seconds']:.3f} s ({meta['seconds_per_simulated_second']:.3f} s "
          f"per simulated s) -> {out}")
    if plot is not None:
        names = args.plot_vars or [n for n in res.names
                                   if n.split(".", 1)[0] == system.element_names[0]][:6]
        _write_atomically(plot, lambda tmp: res.plot(names, tmp,
                                                     title=f"{system.name} (co-simulation)"),
                          "plot")
        print(f"plot -> {plot}")
    return 0


def cmd_simulate_fmu(args: argparse.Namespace) -> int:
    """``bgmodelica simulate-fmu``: one FMU through the master, results to CSV."""
    for value, what in ((args.stop_time, "--stop-time"), (args.interval, "--interval")):
        if value is not None and not (math.isfinite(value) and value > 0):
            raise InvalidExperimentError(f"{what} must be a finite number > 0, got {value}")
    return _run_fmu(args, args.fmu, args.interval, "")


def _run_fmu(args: argparse.Namespace, fmu: str, interval: float | None, suffix: str) -> int:
    """One FMU through the master (``simulate-fmu``, ``cosim MODEL.fmu``): the CSV at ``-o``
    (default ``<model><suffix>.csv``) and the optional plot."""
    from .single import simulate_fmu

    sets = {}
    for item in args.set:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            raise CosimError(f"--set {item!r}: expected NAME=VALUE")
        sets[name.strip()] = value.strip()
    out_arg = _writable(args.output, "output file")
    plot = _writable(getattr(args, "plot", None), "plot")
    res = simulate_fmu(fmu, stop_time=args.stop_time, interval=interval,
                       parameters=sets, inputs=args.input, interface=args.interface or "auto",
                       rtol=getattr(args, "rtol", 1e-8), atol=getattr(args, "atol", 1e-10),
                       record=args.record, euler_step=args.euler_step)
    names = getattr(args, "plot_vars", None)
    missing = [n for n in names or () if n not in res.names]
    if missing:
        raise CosimError(f"--plot-vars: no numeric result variable {', '.join(missing)}")
    out = out_arg or _writable(f"{res.meta['model']}{suffix}.csv", "output file")
    assert out is not None
    _write_atomically(out, res.to_csv, "output file")
    meta = res.meta
    (kind,) = set(meta["interfaces"].values())
    print(f"{meta['model']}: {'Model Exchange' if kind == 'me' else 'Co-Simulation'}, "
          f"{len(res.time)} points to t = {float(res.time[-1]):g} s, run "
          f"{meta['run_seconds']:.3f} s -> {out}")
    if meta.get("events"):
        print(f"events: {len(meta['events'])} (first at t = {meta['events'][0]:.10g} s)")
    if meta.get("terminated"):
        print(f"note: {meta['terminated']['reason']} at t = {meta['terminated']['time']:g} s")
    if plot is not None:
        chosen = names or res.names[:6]
        _write_atomically(plot, lambda tmp: res.plot(chosen, tmp, title=meta["model"]), "plot")
        print(f"plot -> {plot}")
    return 0


def _steps(text: str) -> list[float]:
    try:
        steps = [float(s) for s in text.split(",") if s.strip()]
    except ValueError:
        raise ParameterError(f"--steps expects comma-separated numbers, got {text!r}") from None
    if not steps or any(not (math.isfinite(s) and s > 0) for s in steps):
        raise ParameterError(f"--steps: finite positive macro steps required, got {text!r}")
    return steps


def cmd_verify(args: argparse.Namespace) -> int:
    """``bgmodelica verify MODEL SSP``: monolithic model vs co-simulation of its parts;
    exit status 1 when ``--tolerance`` is exceeded."""
    from ..loader import load_model
    from .ssp_read import read_ssp
    from .verify import SCHEMES, verify_model

    def progress(msg: str) -> None:
        if not args.quiet:
            sys.stderr.write(f"  {msg}\n")
            sys.stderr.flush()

    steps = _steps(",".join(args.step)) if args.step else None
    if args.tolerance is not None and not (math.isfinite(args.tolerance)
                                           and args.tolerance >= 0):
        raise ParameterError(f"--tolerance must be a finite number >= 0, got {args.tolerance}")
    schemes = [(o, ex) for o, ex in SCHEMES
               if args.order in ("all", o) and args.extrapolation in (None, ex)]
    from ..cli import _model_kwargs

    model = load_model(args.model, **_model_kwargs(args.arg))
    system = read_ssp(args.ssp)
    vars_ = [v for item in args.vars or () for v in item.split(",") if v.strip()]
    report = verify_model(model, system, steps, args.stop_time, variables=vars_ or None,
                          schemes=schemes, interface=args.interface,
                          parameters=_sets(args.set), record=args.record or (),
                          simulate_options={"dynamic": False} if args.static_states else None,
                          progress=progress)
    failed = args.tolerance is not None and bool(report.failures(args.tolerance))
    if args.json:
        data = report.to_dict()
        if args.tolerance is not None:
            data["tolerance"] = {"value": args.tolerance, "passed": not failed,
                                 "verdict": report.verdict(args.tolerance)}
        print(json.dumps(data, indent=2))
        if failed:
            print(report.verdict(args.tolerance), file=sys.stderr)
    else:
        print(report.to_text())
        if args.tolerance is not None:
            print(report.verdict(args.tolerance))
    return 1 if failed else 0


def register(sub: Any, model_args: Any = None) -> None:
    """Add the ``cosim`` and ``verify`` subcommands to the ``bgmodelica`` parser (``sub``:
    its subparsers; ``model_args(parser)`` adds the MODEL argument and ``--arg``)."""
    cos = sub.add_parser("cosim", help="co-simulate an SSP set-up of FMUs, or one FMU "
                                       "(fixed-step master)")
    cos.add_argument("ssp", metavar="SSP|FMU",
                     help="the .ssp file (SystemStructure.ssd + FMUs in resources/), or one "
                          ".fmu")
    cos.add_argument("--step", type=float, default=None,
                     help="macro step [s] (default: the SSP's, else 1e-3; one FMU: its "
                          "step size, else 1/500 of the horizon)")
    cos.add_argument("--order", choices=["jacobi", "gauss-seidel"], default=None,
                     help="coupling order (default: the SSP's, else jacobi)")
    cos.add_argument("--stop-time", type=float, default=None,
                     help="[s] (default: the SSP DefaultExperiment)")
    cos.add_argument("--extrapolation", action=argparse.BooleanOptionalAction, default=None,
                     help="linear extrapolation (interpolation in Gauss-Seidel) of the inputs")
    cos.add_argument("--interface", choices=["cs", "me", "auto"], default=None,
                     help="Co-Simulation FMUs (own solvers) or Model Exchange (master's "
                          "integrator); default cs, for one FMU auto (CS when available)")
    cos.add_argument("--no-propagate", action="store_true",
                     help="read outputs right after doStep (no feedthrough evaluation at "
                          "communication points)")
    cos.add_argument("--set", action="append", default=[], metavar="ELEMENT.NAME=VALUE",
                     help="override a parameter of an element (one FMU: NAME=VALUE)")
    cos.add_argument("--record", nargs="+", metavar="ELEMENT.VAR",
                     help="record more variables (locals, states; one FMU: VAR)")
    cos.add_argument("--euler-step", type=float, default=None, metavar="H",
                     help="Model Exchange units: forward Euler at this fixed step (the FMI "
                          "example importer) instead of Radau")
    cos.add_argument("--input", metavar="CSV",
                     help="one FMU: input signals, a 'time' column then one per input")
    cos.add_argument("-o", "--output", help="CSV file (default <system>_cosim.csv, one FMU: "
                                            "<model>_cosim.csv)")
    cos.add_argument("--plot", help="PNG with the first element's connectors (or --plot-vars)")
    cos.add_argument("--plot-vars", nargs="+", help="variables to plot")
    cos.set_defaults(func=cmd_cosim)

    one = sub.add_parser("simulate-fmu", help="simulate one FMU (FMI 2.0/3.0, CS or ME with "
                                              "events) and write a CSV")
    one.add_argument("fmu", help="the .fmu file")
    one.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                     help="a parameter or input start value (any type)")
    one.add_argument("--input", metavar="CSV",
                     help="input signals: a 'time' column, then one column per input")
    one.add_argument("--stop-time", type=float, default=None,
                     help="[s] (default: the FMU's DefaultExperiment, else 1)")
    one.add_argument("--interval", type=float, default=None,
                     help="output and communication interval [s] (default: the FMU's step "
                          "size, else 1/500 of the horizon)")
    one.add_argument("--interface", choices=["cs", "me", "auto"], default="auto",
                     help="Co-Simulation (the FMU's solver) or Model Exchange (the master's "
                          "integrator with event location); auto: CS when available")
    one.add_argument("--rtol", type=float, default=1e-8,
                     help="Model Exchange rtol, and the FMU's experiment tolerance")
    one.add_argument("--atol", type=float, default=1e-10, help="Model Exchange atol")
    one.add_argument("--euler-step", type=float, default=None, metavar="H",
                     help="Model Exchange: forward Euler at this fixed step (the FMI example "
                          "importer) instead of Radau")
    one.add_argument("--record", nargs="+", metavar="VAR",
                     help="variables to record besides the outputs (default: the states)")
    one.add_argument("-o", "--output", help="CSV file (default <model>.csv)")
    one.set_defaults(func=cmd_simulate_fmu)

    ver = sub.add_parser("verify", help="a model vs the co-simulation of its parts (SSP): "
                                        "errors, convergence order, --tolerance check")
    if model_args is not None:
        model_args(ver)
    else:
        ver.add_argument("model", help="path/file.py:Name or package.module:Name")
        ver.add_argument("--arg", action="append", default=[], metavar="NAME=VALUE",
                         help="argument for a parameterized model constructor")
    ver.add_argument("ssp", help="the .ssp set-up of the model's parts")
    ver.add_argument("--step", "--steps", action="append", default=[],
                     help="macro steps [s], comma-separated or repeated (default: 4, 2 and 1 "
                          "times the SSP's step size)")
    ver.add_argument("--stop-time", type=float, default=None,
                     help="[s] (default: the SSP DefaultExperiment, else 1)")
    ver.add_argument("--tolerance", type=float, default=None,
                     help="largest allowed |cosim - model| of every compared variable in every "
                          "run; exceeded: exit status 1")
    ver.add_argument("--vars", action="append", metavar="ELEMENT.VAR",
                     help="co-simulation variables to compare (comma-separated or repeated; "
                          "default: every output whose name matches a model variable)")
    ver.add_argument("--order", choices=["jacobi", "gauss-seidel", "all"], default="all",
                     help="coupling orders to run (default both)")
    ver.add_argument("--extrapolation", action=argparse.BooleanOptionalAction, default=None,
                     help="only with (or without) input extrapolation (default both)")
    ver.add_argument("--interface", choices=["cs", "me"], default="cs",
                     help="Co-Simulation FMUs or Model Exchange (master's integrator)")
    ver.add_argument("--set", action="append", default=[], metavar="ELEMENT.NAME=VALUE",
                     help="override a parameter of an element")
    ver.add_argument("--record", nargs="+", metavar="ELEMENT.VAR",
                     help="also record and compare these variables (locals, states)")
    ver.add_argument("--static-states", action="store_true",
                     help="reference without dynamic state selection (dynamic=False)")
    ver.add_argument("--json", action="store_true", help="machine-readable report")
    ver.add_argument("--quiet", action="store_true", help="no progress on stderr")
    ver.set_defaults(func=cmd_verify)
