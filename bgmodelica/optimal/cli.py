"""``bgmodelica optimize MODEL ...``: optimal controls of a compiled model (see
:func:`bgmodelica.optimal.optimize`)."""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Callable
from typing import Any

import numpy as np


def register(sub: Any, model_args: Callable[[argparse.ArgumentParser], None]) -> None:
    """Add the ``optimize`` subcommand to the ``bgmodelica`` parser."""
    opt = sub.add_parser("optimize", help="optimal control: the inputs that steer the model "
                                          "between conditions at least cost")
    model_args(opt)
    opt.add_argument("--control", action="append", default=[], metavar="NAME=LOW:HIGH,...",
                     help="top-level inputs to optimize and their bounds (NAME alone: "
                          "unbounded)")
    opt.add_argument("--initial", action="append", default=[], metavar="NAME=VALUE,...",
                     help="initial values (other states: the model's start values)")
    opt.add_argument("--final", action="append", default=[], metavar="NAME=VALUE,...",
                     help="values at the final time (other states free)")
    opt.add_argument("--stop-time", type=float, default=None, metavar="T",
                     help="the horizon [s] (with --minimize time: its first guess)")
    opt.add_argument("--minimize", choices=("time",), default=None,
                     help="minimize the final time (bounded controls)")
    opt.add_argument("--lagrange", metavar="EXPR", default=None,
                     help="running cost integrated over the horizon, e.g. \"U1^2+U2^2\"")
    opt.add_argument("--mayer", metavar="EXPR", default=None,
                     help="cost at the final time")
    opt.add_argument("--path", action="append", default=[], metavar="EXPR=LOW:HIGH,...",
                     help="bounds held along the trajectory, e.g. \"motor1.i=-5:5\"")
    opt.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                     help="parameter / other input by dotted name")
    opt.add_argument("--intervals", type=int, default=40, metavar="N",
                     help="collocation intervals of the first mesh (default 40)")
    opt.add_argument("--tol", type=float, default=1e-4,
                     help="largest state deviation allowed between the optimal trajectory and "
                          "its re-simulation; the mesh is refined until it holds "
                          "(default 1e-4)")
    opt.add_argument("--json", action="store_true", help="machine-readable output")
    opt.add_argument("-o", "--output", metavar="FILE.csv",
                     help="the re-simulated trajectories (as simulate writes them)")
    opt.add_argument("--plot", metavar="FILE.png", help="states and controls")
    opt.add_argument("--units", choices=("error", "warn", "off"), default="error",
                     help="dimensional analysis of the equations")
    opt.set_defaults(func=cmd_optimize)


def _pairs(items: list[str], option: str) -> list[tuple[str, str]]:
    """``["a=1,b=2", "c=3"]`` -> ``[("a", "1"), ("b", "2"), ("c", "3")]`` (a bare ``NAME``
    gives ``(NAME, "")``)."""
    from ..errors import OptionError
    from .expression import split_items

    out = []
    for item in items:
        for part in split_items(item):
            name, _, value = part.partition("=")
            if not name.strip():
                raise OptionError(f"{option}: expected NAME=VALUE, got {part!r}")
            out.append((name.strip(), value.strip()))
    return out


def _values(items: list[str], option: str) -> dict[str, float]:
    from ..errors import OptionError

    out = {}
    for name, value in _pairs(items, option):
        try:
            out[name] = float(value)
        except ValueError:
            raise OptionError(f"{option} {name}: {value!r} is not a number") from None
        if not math.isfinite(out[name]):
            raise OptionError(f"{option} {name}: {value!r} is not finite")
    return out


def _check_args(args: argparse.Namespace) -> None:
    from ..errors import OptionError
    from ..output_checks import check_distinct_outputs, check_output_file, check_plot_file

    if not args.control:
        raise OptionError("--control: name the inputs to optimize (--control U=-1:1)")
    if args.minimize is None and args.stop_time is None:
        raise OptionError("give --stop-time T (fixed horizon) or --minimize time")
    if args.intervals < 1:
        raise OptionError(f"--intervals {args.intervals}: need at least 1")
    if not (0 < args.tol < math.inf):
        raise OptionError(f"--tol {args.tol}: must be positive")
    if args.output:
        check_output_file(args.output, "-o")
    if args.plot:
        check_plot_file(args.plot, "--plot")
    check_distinct_outputs(("-o", args.output), ("--plot", args.plot))


def cmd_optimize(args: argparse.Namespace) -> int:
    from ..cli import _model_kwargs, _parse_sets
    from ..compiler import compile
    from ..loader import load_model
    from .problem import parse_bounds
    from .solve import optimize

    _check_args(args)
    controls = {n: parse_bounds(v, f"--control {n}") for n, v in _pairs(args.control,
                                                                          "--control")}
    path = {n: parse_bounds(v, f"--path {n}") for n, v in _pairs(args.path, "--path")}
    model = load_model(args.model, **_model_kwargs(args.arg))
    compiled = compile(model, units=args.units)
    result = optimize(compiled, controls, initial=_values(args.initial, "--initial"),
                      final=_values(args.final, "--final"), stop_time=args.stop_time,
                      minimize_time=args.minimize == "time", lagrange=args.lagrange,
                      mayer=args.mayer, path=path, params=_parse_sets(args.set),
                      intervals=args.intervals, tol=args.tol)
    if args.output:
        result.to_csv(args.output)
    if args.plot:
        result.plot(args.plot)
    if args.json:
        print(json.dumps(result.to_dict(), indent=2))
        return 0
    sol = result.solution
    print(f"model {compiled.name}: optimum (IPOPT {sol.status}, {sol.iterations} iterations, "
          f"{len(sol.trajectory.mesh) - 1} intervals, {result.seconds:.2f} s)")
    print(f"  stop time: {result.stop_time:.9g} s")
    print(f"  objective: {result.objective:.9g}")
    print(f"  re-simulation error: {result.resimulation_error:.3g} (largest state deviation)")
    final = result.final_values()
    if final:
        print("  final (re-simulated): " + ", ".join(f"{k} = {v:.6g}" for k, v in final.items()))
    for name, (_, v) in result.controls.items():
        print(f"  control {name}: from {v[0]:.6g} to {v[-1]:.6g}, range "
              f"[{np.min(v):.6g}, {np.max(v):.6g}]")
    if args.output:
        print(f"trajectories -> {args.output}")
    if args.plot:
        print(f"plot -> {args.plot}")
    return 0
