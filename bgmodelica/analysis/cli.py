"""``bgmodelica linearize MODEL ...``: the linear model at an operating point, its poles,
numeric controllability/observability ranks, and Bode / step / pole-zero figures."""

from __future__ import annotations

import argparse
import json
from typing import Any

import numpy as np


def register(sub: Any, model_args: Any) -> None:
    """Add the ``linearize`` subcommand to the ``bgmodelica`` parser."""
    lin = sub.add_parser(
        "linearize", help="linear model (A, B, C, D) at an operating point, poles, ranks")
    model_args(lin)
    lin.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                     help="parameter / input (the operating input) / start value by name")
    lin.add_argument("--steady-state", action="store_true",
                     help="linearize at the steady state der(x) = 0 (start values are guesses)")
    lin.add_argument("--at-time", type=float, default=None, metavar="T",
                     help="linearize at time T [s] of a simulation from the start values")
    lin.add_argument("--exclude", nargs="+", default=[], metavar="STATE",
                     help="states that need not be stationary in --steady-state")
    lin.add_argument("--inputs", nargs="+", default=None, metavar="NAME",
                     help="inputs (model inputs or free parameters; default: top-level Inputs)")
    lin.add_argument("--outputs", nargs="+", default=None, metavar="NAME",
                     help="outputs (any variables; default: top-level Outputs, else the states)")
    lin.add_argument("--tol", type=float, default=None,
                     help="relative tolerance of the rank decisions (default 1e-10)")
    lin.add_argument("--json", action="store_true", help="machine-readable output")
    lin.add_argument("--bode", metavar="FILE.png", help="Bode plot of every input -> output")
    lin.add_argument("--step", metavar="FILE.png", help="step responses")
    lin.add_argument("--pzmap", metavar="FILE.png", help="poles and zeros")
    lin.add_argument("--units", choices=("error", "warn", "off"), default="error",
                     help="dimensional analysis of the equations")
    lin.set_defaults(func=cmd_linearize)


def _check_args(args: argparse.Namespace) -> None:
    from ..errors import OptionError
    from ..output_checks import check_distinct_outputs, check_plot_file

    if args.steady_state and args.at_time is not None:
        raise OptionError("--steady-state and --at-time exclude each other")
    if args.exclude and not args.steady_state:
        raise OptionError("--exclude applies to --steady-state only")
    if args.at_time is not None and not np.isfinite(args.at_time):
        raise OptionError(f"--at-time {args.at_time}: not a finite time")
    if args.tol is not None and not (0 < args.tol < 1):
        raise OptionError(f"--tol {args.tol}: must be between 0 and 1")
    for opt in ("bode", "step", "pzmap"):
        path = getattr(args, opt)
        if path:
            check_plot_file(path, f"--{opt}")
    check_distinct_outputs(("--bode", args.bode), ("--step", args.step),
                           ("--pzmap", args.pzmap))


def cmd_linearize(args: argparse.Namespace) -> int:
    from ..cli import _model_kwargs, _parse_sets
    from ..compiler import compile
    from ..loader import load_model
    from .controllability import DEFAULT_TOL, controllability, observability
    from .linearize import linearization
    from .plots import bode_plot, pzmap_plot, step_plot

    _check_args(args)
    params = _parse_sets(args.set)
    model = load_model(args.model, **_model_kwargs(args.arg))
    compiled = compile(model, units=args.units)
    lin = linearization(compiled, params, steady_state=args.steady_state,
                        at_time=args.at_time, inputs=args.inputs, outputs=args.outputs,
                        exclude=args.exclude)
    written = []
    if args.bode:
        written.append(bode_plot(lin, args.bode))
    if args.step:
        written.append(step_plot(lin, args.step))
    if args.pzmap:
        written.append(pzmap_plot(lin, args.pzmap))
    if args.json:
        print(json.dumps(lin.to_dict(tol=args.tol), indent=2))
        return 0
    tol = DEFAULT_TOL if args.tol is None else args.tol
    ctrb = controllability(lin.A, lin.B, tol=tol, states=lin.states)
    obsv = observability(lin.A, lin.C, tol=tol, states=lin.states)
    pt = lin.point
    print(f"model {lin.name}: linearized at the {pt.kind}"
          + (f" (max |der(x)| = {pt.residual:.3g})" if pt.kind == "steady state" else ""))
    for note in pt.notes:
        print(f"  note: {note}")
    if pt.inputs:
        print("  operating inputs: " + ", ".join(f"{k} = {v:.6g}"
                                                 for k, v in pt.inputs.items()))
    print("  operating states: " + (", ".join(f"{k} = {v:.10g}" for k, v in pt.states.items())
                                    or "-"))
    print(f"  states ({len(lin.states)}): {', '.join(lin.states) or '-'}")
    print(f"  inputs ({len(lin.inputs)}): {', '.join(lin.inputs) or '-'}")
    print(f"  outputs ({len(lin.outputs)}): {', '.join(lin.outputs) or '-'}")
    print("  eigenvalues of A:")
    for v in lin.eigenvalues:
        extra = ""
        if abs(v) > 0:
            wn = abs(v)
            extra = f"   (|s| = {wn:.6g} rad/s, damping {-v.real / wn:.4g})"
        print(f"    {v.real: .10g} {v.imag:+.10g}j{extra}")
    for res, what in ((ctrb, "controllability"), (obsv, "observability")):
        margin = "" if res.margin == float("inf") else f", margin {res.margin:.3g}"
        print(f"  numeric {what} rank: {res.rank}/{res.n} (staircase, tol {tol:g}{margin})")
        if res.modes:
            word = "uncontrollable" if what == "controllability" else "unobservable"
            print(f"    {word} modes: " + ", ".join(f"{m.real:.6g}{m.imag:+.6g}j"
                                                    for m in res.modes))
            weak = res.weakest_states()
            if weak:
                print(f"    mostly in: {', '.join(weak)}")
    with np.printoptions(precision=6, suppress=False, linewidth=100):
        for name, M in (("A", lin.A), ("B", lin.B), ("C", lin.C), ("D", lin.D)):
            print(f"  {name} =\n" + "\n".join("    " + row for row in
                                               str(np.asarray(M)).splitlines()))
    for path in written:
        print(f"figure -> {path}")
    return 0
