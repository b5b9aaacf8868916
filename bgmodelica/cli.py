"""The ``bgmodelica`` command line: simulate, check (and the commands added by later stages)."""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from .errors import ModelError, ModelLoadError, ParameterError


def _parse_sets(items: Sequence[str]) -> dict[str, float]:
    out: dict[str, float] = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep or not name:
            raise ParameterError(f"--set expects NAME=VALUE, got {item!r}")
        try:
            out[name.strip()] = float(value)
        except ValueError:
            raise ParameterError(f"--set {name}: {value!r} is not a number") from None
    return out


def _model_kwargs(items: Sequence[str]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for item in items:
        name, _, value = item.partition("=")
        try:
            out[name] = json.loads(value)
        except json.JSONDecodeError:
            out[name] = value
    return out


def _progress(frac: float) -> None:
    bar = "#" * int(frac * 30)
    sys.stderr.write(f"\r  simulating [{bar:<30}] {frac * 100:5.1f}%")
    if frac >= 1:
        sys.stderr.write("\n")
    sys.stderr.flush()


def cmd_simulate(args: argparse.Namespace) -> int:
    from .compiler import compile
    from .loader import load_model
    from .simulate import simulate

    model = load_model(args.model, **_model_kwargs(args.arg))
    params = _parse_sets(args.set)
    compiled = compile(model)
    show = args.progress if args.progress is not None else sys.stderr.isatty()
    result = simulate(compiled, stop_time=args.stop_time, interval=args.interval,
                      params=params, rtol=args.rtol, atol=args.atol,
                      progress=_progress if show else None, inputs=args.input)
    out = Path(args.output) if args.output else Path(f"{compiled.name}.csv")
    result.to_csv(out)
    print(f"{compiled.name}: {len(result.time)} points, compile {compiled.compile_time:.3f} s, "
          f"run {result.meta['run_seconds']:.3f} s -> {out}")
    for note in result.meta.get("init_notes", []):
        print(f"note: {note}")
    if result.meta.get("n_events"):
        print(f"events: {result.meta['n_events']} (two rows, left and right limit, at each)")
    if args.plot:
        names = args.plot_vars or result.meta["states"][:6] or result.names[:6]
        result.plot(names, args.plot, title=compiled.name)
        print(f"plot -> {args.plot}")
    return 0


def cmd_check(args: argparse.Namespace) -> int:
    from .compiler import compile
    from .loader import load_model

    model = load_model(args.model, **_model_kwargs(args.arg))
    summary = compile(model).summary()
    extra = _bondgraph_report(model)
    if extra is not None:
        summary["bond_graph"] = extra.to_dict()
    if args.json:
        print(json.dumps(summary, indent=2))
        return 0
    print(f"model {summary['model']}: {summary['equations']} equations, "
          f"{summary['unknowns']} unknowns: "
          + ("balanced" if summary["balanced"] else "UNBALANCED"))
    print(f"  flat equations {summary['flat_equations_before_alias_elimination']}, "
          f"aliases eliminated {summary['aliases_eliminated']}")
    print(f"  structural index: {summary['structural_index']}")
    print(f"  states ({len(summary['states'])}): {', '.join(summary['states']) or '-'}")
    if summary["dummy_derivatives"]:
        print(f"  dummy derivatives: {', '.join(summary['dummy_derivatives'])}")
    if summary["differentiated_equations"]:
        print(f"  differentiated equations ({len(summary['differentiated_equations'])}): "
              + "; ".join(summary["differentiated_equations"][:8]))
    print(f"  algebraic variables ({len(summary['algebraic_variables'])}): "
          + (", ".join(summary["algebraic_variables"][:20]) or "-"))
    loops = summary["algebraic_loops"]
    print(f"  algebraic loops: {len(loops)}"
          + "".join(f"\n    size {lp['size']} ({lp['kind']}), tearing: "
                    f"{', '.join(lp['tearing']) or '-'}" for lp in loops))
    ev = summary.get("events")
    if ev:
        print(f"  discrete variables ({len(ev['discrete_variables'])}): "
              + (", ".join(f"{d['name']} ({d['type']})" for d in ev["discrete_variables"])
                 or "-"))
        print(f"  event conditions ({len(ev['conditions'])}):"
              + "".join(f"\n    {c['relation']}  [{c['kind']}, {c['in']}]"
                        for c in ev["conditions"]))
        print(f"  when-clauses: {len(ev['when_clauses'])}"
              + "".join(f"\n    when {b['condition']}: "
                        + ", ".join(b["assigns"] + [f"reinit({r})" for r in b["reinits"]])
                        for w in ev["when_clauses"] for b in w["branches"]))
        if ev["clocks"]:
            print("  clocks: " + ", ".join(f"sample({c['start']:g}, {c['interval']:g})"
                                           for c in ev["clocks"]))
        if ev["tables"]:
            print(f"  time tables: {len(ev['tables'])}")
    if summary["dynamic_state_selection"]:
        print("  state selection may change during simulation (dynamic state selection)")
    if summary["inputs"]:
        print(f"  inputs: {', '.join(summary['inputs'])}")
    if extra is not None:
        print(extra.to_text())
    return 0


def cmd_export(args: argparse.Namespace) -> int:
    from .compiler import compile
    from .fmi.from_model import export_model
    from .loader import load_model

    compiled = compile(load_model(args.model, **_model_kwargs(args.arg)))
    path = export_model(compiled, args.output, fmi_version=args.fmi, fmu_type=args.type,
                        stop_time=args.stop_time, step_size=args.step)
    print(f"{compiled.name}: FMI {args.fmi}.0 {args.type.upper()} -> {path}")
    if args.validate:
        from fmpy.validation import validate_fmu

        problems = validate_fmu(str(path))
        print("fmpy validate_fmu: " + ("OK" if not problems else "; ".join(problems)))
        return 1 if problems else 0
    return 0


def cmd_draw(args: argparse.Namespace) -> int:
    from .bondgraph import BondGraph, draw
    from .loader import load_model

    model = load_model(args.model, **_model_kwargs(args.arg))
    if not isinstance(model, BondGraph):
        raise ModelLoadError(f"{args.model} is a {type(model).__name__}, not a BondGraph")
    path = draw(model, args.output)
    print(f"drawing -> {path}")
    return 0


def _bondgraph_report(model: Any) -> Any:
    try:
        from .bondgraph import BondGraph, analyze
    except ImportError:
        return None
    return analyze(model) if isinstance(model, BondGraph) else None


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="bgmodelica",
        description="Equation-based modeling with bond graphs: simulate, check, export.")
    sub = parser.add_subparsers(dest="command", required=True)

    def model_args(p: argparse.ArgumentParser) -> None:
        p.add_argument("model", help="path/file.py:Name or package.module:Name")
        p.add_argument("--arg", action="append", default=[], metavar="NAME=VALUE",
                       help="argument for a parameterized model constructor (e.g. n=100)")

    sim = sub.add_parser("simulate", help="simulate a model, write CSV (and a plot)")
    model_args(sim)
    sim.add_argument("--stop-time", type=float, default=1.0, help="[s] (default 1)")
    sim.add_argument("--interval", type=float, default=None, help="output step [s]")
    sim.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                     help="override a parameter / input / start value by dotted name")
    sim.add_argument("--input", metavar="FILE.csv",
                     help="time-varying values of the model's inputs: first column 'time', "
                          "one column per input (linear; a repeated time is a jump)")
    sim.add_argument("-o", "--output", help="CSV file (default <Model>.csv)")
    sim.add_argument("--plot", help="PNG file with the states (or --plot-vars)")
    sim.add_argument("--plot-vars", nargs="+", help="variables to plot")
    sim.add_argument("--rtol", type=float, default=1e-6)
    sim.add_argument("--atol", type=float, default=1e-8)
    sim.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                     help="progress bar (default: when stderr is a terminal)")
    sim.set_defaults(func=cmd_simulate)

    chk = sub.add_parser("check", help="balance, structural index, states, loops")
    model_args(chk)
    chk.add_argument("--json", action="store_true", help="machine-readable output")
    chk.set_defaults(func=cmd_check)
    exp = sub.add_parser("export", help="export an FMU (FMI 2.0/3.0, ME/CS)")
    model_args(exp)
    exp.add_argument("--fmi", type=int, choices=(2, 3), default=2, help="FMI version")
    exp.add_argument("--type", choices=("me", "cs", "both"), default="me",
                     help="Model Exchange, Co-Simulation or both")
    exp.add_argument("-o", "--output", default="fmus", help="output directory (default fmus)")
    exp.add_argument("--stop-time", type=float, default=1.0, help="DefaultExperiment stop [s]")
    exp.add_argument("--step", type=float, default=None, help="DefaultExperiment step [s]")
    exp.add_argument("--validate", action="store_true", help="run fmpy's validate_fmu")
    exp.set_defaults(func=cmd_export)

    drw = sub.add_parser("draw", help="draw a bond graph with causal strokes (SVG/PNG)")
    model_args(drw)
    drw.add_argument("-o", "--output", required=True, help="file.svg or file.png")
    drw.set_defaults(func=cmd_draw)
    for register in _EXTENSIONS:
        register(sub, model_args)
    return parser


_EXTENSIONS: list = []

from .cosim.cli import register as register_cosim  # noqa: E402

_EXTENSIONS.append(register_cosim)


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except ModelError as err:
        print(f"error: {type(err).__name__}: {err}", file=sys.stderr)
        return 2
    except Exception as err:  # FMU build errors and the like: one line, not a traceback
        from .fmi import FmuExportError

        if not isinstance(err, FmuExportError):
            raise
        print(f"error: {type(err).__name__}: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
