# PYTHON_ARGCOMPLETE_OK
"""The ``bgmodelica`` command line: simulate, check (and the commands added by later stages)."""

from __future__ import annotations

import argparse
import json
import sys
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from .errors import ModelError, ModelLoadError, ParameterError


def _parse_sets(items: Sequence[str]) -> dict[str, float | str]:
    """``NAME=VALUE`` pairs; a value with a unit (``R.R="2 kOhm"``) stays a string, converted
    to the declared unit by ``simulate``."""
    from .core.units import split_quantity

    out: dict[str, float | str] = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep or not name:
            raise ParameterError(f"--set expects NAME=VALUE, got {item!r}")
        try:
            out[name.strip()] = float(value)
        except ValueError:
            quantity = split_quantity(value)
            if quantity is None or not quantity[1]:
                raise ParameterError(f"--set {name}: {value!r} is not a number") from None
            out[name.strip()] = value.strip()
    return out


def _model_kwargs(items: Sequence[str]) -> dict[str, Any]:
    from .validate import parse_model_args

    return parse_model_args(items)


#: the terminal's stderr while :func:`main` holds back the output of a command
_TERMINAL: Any = None


def _progress(frac: float) -> None:
    stream = _TERMINAL or sys.stderr
    bar = "#" * int(frac * 30)
    stream.write(f"\r  simulating [{bar:<30}] {frac * 100:5.1f}%")
    if frac >= 1:
        stream.write("\n")
    stream.flush()


def _check_simulate_args(args: argparse.Namespace) -> None:
    """Options and output files, before any model is loaded (nothing is written)."""
    from .errors import OptionError
    from .output_checks import check_distinct_outputs, check_output_file, check_plot_file
    from .result_files import format_of
    from .validate import check_run_options

    check_run_options(stop_time=args.stop_time, interval=args.interval, rtol=args.rtol,
                      atol=args.atol)
    if args.plot_vars and not args.plot:
        raise OptionError("--plot-vars needs --plot FILE to draw them in")
    if args.output:
        check_output_file(args.output, "-o")
        format_of(args.output)               # a known format whose package is installed
    if args.plot:
        check_plot_file(args.plot, "--plot")
    check_distinct_outputs(("-o", args.output), ("--plot", args.plot))
    if args.input and not Path(args.input).is_file():
        raise OptionError(f"--input {args.input}: no such file")


def cmd_simulate(args: argparse.Namespace) -> int:
    from .compiler import compile
    from .errors import SimulationError
    from .loader import load_model
    from .modelica.cli import apply_experiment_defaults
    from .output_checks import check_distinct_outputs, check_output_file, check_plot_vars
    from .result_files import save, write_progress
    from .simulate import simulate

    apply_experiment_defaults(args)        # .mo models: experiment annotation defaults
    _check_simulate_args(args)
    params = _parse_sets(args.set)
    model = load_model(args.model, **_model_kwargs(args.arg))
    compiled = compile(model, units=args.units, cache=args.cache)
    out = Path(args.output) if args.output else Path(f"{compiled.name}.csv")
    if not args.output:
        check_output_file(out, "-o (default)")
        check_distinct_outputs(("-o", out), ("--plot", args.plot))
    if args.plot_vars:
        check_plot_vars(args.plot_vars, compiled)
    from .output_checks import expand_outputs

    outputs = expand_outputs(args.outputs, compiled) if args.outputs else None
    if outputs is not None and args.plot_vars:
        outputs += [n for n in args.plot_vars if n not in outputs]
    show = args.progress if args.progress is not None else (_TERMINAL or sys.stderr).isatty()

    def writing():                          # a bar for a long write (from when it starts)
        return write_progress(show, _TERMINAL or sys.stderr, 0.0 if args.progress else 0.5)

    try:
        result = simulate(compiled, stop_time=args.stop_time, interval=args.interval,
                          params=params, rtol=args.rtol, atol=args.atol,
                          solver=args.solver, max_step=args.max_step,
                          progress=_progress if show else None, inputs=args.input,
                          init=args.init, outputs=outputs)
    except SimulationError as err:          # keep what was computed, and say so
        part = err.result
        if part is None or not len(part.time):
            raise SimulationError(f"{err} (nothing written to {out})", err.time_reached,
                                  part) from None
        save(part, out, outputs, progress=writing())
        raise SimulationError(f"{err} -- {len(part.time)} rows up to t = "
                              f"{float(part.time[-1]):g} s written to {out}",
                              err.time_reached, part) from None
    save(result, out, outputs, progress=writing())
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
    from .core.arrays import compact_names
    from .loader import load_model
    from .value_checks import check_values

    model = load_model(args.model, **_model_kwargs(args.arg))
    compiled = compile(model, units=args.units, cache=args.cache)
    check_values(compiled.dae, compiled.dae.p_default, compiled.declarations)
    summary = compiled.summary()
    extra = _bondgraph_report(model)
    if extra is not None:
        summary["bond_graph"] = extra.to_dict()
        beside = _structural_vs_numeric(model, compiled, extra)
        if beside is not None:
            summary["bond_graph"]["structural_vs_numeric"] = beside.to_dict()
    if args.json:
        print(json.dumps(summary, indent=2))
        return 0
    print(f"model {summary['model']}: {summary['equations']} equations, "
          f"{summary['unknowns']} unknowns: "
          + ("balanced" if summary["balanced"] else "UNBALANCED"))
    print(f"  flat equations {summary['flat_equations_before_alias_elimination']}, "
          f"aliases eliminated {summary['aliases_eliminated']}")
    print(f"  structural index: {summary['structural_index']}")
    print(f"  states ({len(summary['states'])}): {_listed(summary['states'])}")
    if summary["dummy_derivatives"]:
        print(f"  dummy derivatives: {', '.join(compact_names(summary['dummy_derivatives']))}")
    if summary["differentiated_equations"]:
        print(f"  differentiated equations ({len(summary['differentiated_equations'])}): "
              + "; ".join(summary["differentiated_equations"][:8]))
    print(f"  algebraic variables ({len(summary['algebraic_variables'])}): "
          + _listed(summary["algebraic_variables"], 20))
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
        if beside is not None:
            print(beside.to_text())
    return 0


def cmd_export(args: argparse.Namespace) -> int:
    from .compiler import compile
    from .fmi.from_model import export_model
    from .loader import load_model
    from .validate import check_export_args

    check_export_args(args)
    compiled = compile(load_model(args.model, **_model_kwargs(args.arg)), units=args.units,
                       cache=args.cache)
    path = export_model(compiled, args.output, fmi_version=args.fmi, fmu_type=args.type,
                        stop_time=args.stop_time, step_size=args.step,
                        static_states=args.static_states)
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
    from .output_checks import check_plot_file

    check_plot_file(args.output, "-o")
    model = load_model(args.model, **_model_kwargs(args.arg))
    if not isinstance(model, BondGraph):
        raise ModelLoadError(f"{args.model} is a {type(model).__name__}, not a BondGraph")
    path = draw(model, args.output)
    print(f"drawing -> {path}")
    return 0


def _listed(names: list[str], most: int = 40) -> str:
    """Names for a report line: runs collapsed, at most ``most`` items, then how many more."""
    from .core.arrays import compact_names

    items = compact_names(names)
    if len(items) <= most:
        return ", ".join(items) or "-"
    return ", ".join(items[:most]) + f", ... ({len(items) - most} more; --json lists all)"


def _structural_vs_numeric(model: Any, compiled: Any, report: Any) -> Any:
    """Numeric ranks beside the structural ones (:mod:`bgmodelica.analysis.compare`)."""
    from .analysis.compare import compare_bond_graph

    return compare_bond_graph(model, compiled, report)


def _bondgraph_report(model: Any) -> Any:
    try:
        from .bondgraph import BondGraph, analyze
    except ImportError:
        return None
    return analyze(model) if isinstance(model, BondGraph) else None


class _Parser(argparse.ArgumentParser):
    """Usage errors on one line (sub-parsers inherit the class)."""

    def error(self, message: str):  # type: ignore[override]
        sys.stderr.write(f"error: {self.prog}: {message} (see {self.prog} --help)\n")
        raise SystemExit(2)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="bgmodelica",
        description="Equation-based modeling with bond graphs: simulate, check, export.",
        epilog="MODEL is path/file.py:Name, package.module:Name, file.mo:Package.Model or a "
               "Modelica class on the library path (Modelica.Blocks.Examples.PID_Controller). "
               "The library path is MODELICAPATH plus --modelica-path DIR (repeatable, any "
               "command).")
    from . import __version__

    parser.add_argument("--version", action="version", version=f"bgmodelica {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    def model_args(p: argparse.ArgumentParser) -> None:
        p.add_argument("model", help="path/file.py:Name, package.module:Name, "
                                     "file.mo:Package.Model (Modelica text) or a Modelica "
                                     "class on the library path (MODELICAPATH, "
                                     "--modelica-path DIR)")
        p.add_argument("--arg", action="append", default=[], metavar="NAME=VALUE",
                       help="argument for a parameterized model constructor (e.g. n=100)")

    sim = sub.add_parser("simulate", help="simulate a model, write CSV (and a plot)")
    model_args(sim)
    sim.add_argument("--stop-time", type=float, default=None,
                     help="[s] (default: the experiment annotation of a Modelica model, "
                          "else 1)")
    sim.add_argument("--interval", type=float, default=None, help="output step [s]")
    sim.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                     help="override a parameter / input / start value by dotted name")
    sim.add_argument("--init", choices=("start", "steady-state"), default="start",
                     help="initial conditions: the start values and initial equations "
                          "(default), or the steady state der(x) = 0 with the given inputs "
                          "(start values as guesses)")
    sim.add_argument("--input", metavar="FILE.csv",
                     help="time-varying values of the model's inputs: first column 'time', "
                          "one column per input (linear; a repeated time is a jump)")
    sim.add_argument("-o", "--output", help="result file by extension: .csv, .parquet or .nc "
                     "(default <Model>.csv)")
    sim.add_argument("--outputs", action="append", default=[], metavar="PATTERN[,PATTERN]",
                     help="variables to write: names or globs (C*.v; * stays within a dotted "
                          "part, ** crosses dots: 'motor.**'); default all")
    sim.add_argument("--plot", help="PNG file with the states (or --plot-vars)")
    sim.add_argument("--plot-vars", nargs="+", help="variables to plot")
    sim.add_argument("--rtol", type=float, default=None,
                     help="relative tolerance (default: the experiment annotation's "
                          "Tolerance of a Modelica model, else 1e-6)")
    sim.add_argument("--atol", type=float, default=None,
                     help="absolute tolerance (default 1e-8, or rtol x the smallest nominal "
                          "value of a state when smaller)")
    sim.add_argument("--solver", choices=("idas", "cvodes", "auto"), default="auto",
                     help="integrator: auto (default: CVODES when no algebraic unknowns are "
                          "left, IDAS otherwise), IDAS (DAEs) or CVODES (explicit ODEs)")
    sim.add_argument("--max-step", type=float, default=None, metavar="SECONDS",
                     help="largest internal step of the integrator [s]")
    sim.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                     help="progress bars of the run and of long writes (default: when stderr "
                     "is a terminal)")
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
    exp.add_argument("--stop-time", type=float, default=None,
                     help="DefaultExperiment stop [s] (default: the experiment annotation, 1)")
    exp.add_argument("--step", type=float, default=None,
                     help="DefaultExperiment step [s] (default: the experiment annotation)")
    exp.add_argument("--validate", action="store_true", help="run fmpy's validate_fmu")
    exp.add_argument("--static-states", action="store_true",
                     help="export a model that needs dynamic state selection with its compiled "
                          "states (valid only where they do not degenerate)")
    exp.set_defaults(func=cmd_export)

    for p in (sim, chk, exp):
        p.add_argument("--units", choices=("error", "warn", "off"), default="error",
                       help="dimensional analysis of the equations: a mismatch is an error "
                            "(default), a warning, or not checked")
        p.add_argument("--cache", action="store_true",
                       help="keep the compiled model on disk and reuse it when the same model "
                            "is compiled again (folder: $BGMODELICA_CACHE or "
                            "~/.cache/bgmodelica)")

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

from .studies.cli import register as register_studies  # noqa: E402

_EXTENSIONS.append(register_studies)

from .analysis.cli import register as register_analysis  # noqa: E402

_EXTENSIONS.append(register_analysis)

from .cli_tools import register as register_tools  # noqa: E402

_EXTENSIONS.append(register_tools)

from .modelica.cli import register as register_modelica  # noqa: E402

_EXTENSIONS.append(register_modelica)

from .optimal.cli import register as register_optimal  # noqa: E402

_EXTENSIONS.append(register_optimal)


def _autocomplete(parser: argparse.ArgumentParser) -> None:
    from .cli_tools import autocomplete

    autocomplete(parser)


def _unit_warning() -> type:
    from .passes.units import UnitWarning

    return UnitWarning


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """Unit mismatches (``--units warn``) as one ``warning:`` line, others as usual."""
    if issubclass(category, _unit_warning()):
        print(f"warning: {message}", file=sys.stderr)
    else:
        sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))


#: commands whose stderr (solver chatter, warnings) is held back and shown only on success,
#: so that an error is the one line on stderr
_HOLD_STDERR = {"simulate", "check", "export", "draw", "linearize", "export-mo", "optimize"}


def _error_line(err: BaseException) -> str:
    from .validate import one_line

    return f"error: {type(err).__name__}: {one_line(str(err))}"


def main(argv: Sequence[str] | None = None) -> int:
    from .modelica.cli import modelica_path_options

    global _TERMINAL
    import contextlib
    import io

    parser = build_parser()
    _autocomplete(parser)
    if not (sys.argv[1:] if argv is None else list(argv)):     # alone: the commands
        parser.print_help()
        return 0
    try:
        argv = modelica_path_options(list(sys.argv[1:] if argv is None else argv))
    except ModelError as err:
        print(_error_line(err), file=sys.stderr)
        return 2
    try:
        args = parser.parse_args(argv)
    except SystemExit as done:            # usage error (one line) or --help
        return int(done.code or 0) if not isinstance(done.code, str) else 2
    held = io.StringIO() if args.command in _HOLD_STDERR else None
    terminal = sys.stderr
    _TERMINAL = terminal
    ok = False
    try:
        with warnings.catch_warnings(), (contextlib.redirect_stderr(held) if held is not None
                                         else contextlib.nullcontext()):
            warnings.showwarning = _show_warning
            warnings.simplefilter("always", _unit_warning())
            code = int(args.func(args) or 0)
        ok = True
        return code
    except ModelError as err:
        print(_error_line(err), file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("error: interrupted", file=sys.stderr)
        return 130
    except Exception as err:  # FMU build errors and the like: one line, not a traceback
        from .fmi import FmuExportError

        if not isinstance(err, FmuExportError):
            ok = True                       # an internal error: show everything
            raise
        print(_error_line(err), file=sys.stderr)
        return 2
    finally:
        _TERMINAL = None
        if held is not None and ok:
            terminal.write(held.getvalue())


if __name__ == "__main__":
    sys.exit(main())
