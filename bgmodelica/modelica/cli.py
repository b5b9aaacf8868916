"""Command line of the Modelica reader/writer (wired into ``bgmodelica`` through
``bgmodelica.cli._EXTENSIONS``):

``bgmodelica export-mo MODEL [-o model.mo] [--name NAME] [--stop-time T] [--interval DT]
[--tolerance TOL] [--verify]``
    write MODEL (any model reference, Python or Modelica) as self-contained Modelica text;
    ``--verify`` loads the written file back and checks that it compiles to the same
    variables and equations.

Every command that takes a MODEL accepts ``file.mo:Package.Model`` (see
:func:`bgmodelica.modelica.load_reference`); ``simulate`` takes its default stop time, output
interval and tolerance from the model's ``experiment`` annotation.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any


def experiment_of_reference(ref: str) -> dict[str, float]:
    """The experiment annotation of ``file.mo:Package.Model`` without building the model
    ({} when the reference is not Modelica or cannot be read: loading reports that)."""
    from . import _file_in_library, is_library_class, is_reference

    if not is_reference(ref):
        return {}
    try:
        from .builder import experiment, find_class, list_models
        from .parser import parse_file
        from .scope import FileScope

        if is_library_class(ref):
            from .library_path import resolve

            scope = resolve(ref)
            return experiment(scope) if scope is not None else {}
        if ref.lower().endswith(".mo"):
            path, name = ref, None
        else:
            path, _, name = ref.rpartition(":")
        stored = parse_file(path)
        root = _file_in_library(stored, Path(path))
        if root is not None and name:           # a file of a package folder
            from .library_path import add_modelica_path, resolve

            add_modelica_path(root)
            within = stored.within or ""
            full = name if not within or name.startswith(within.split(".")[0] + ".") \
                else f"{within}.{name}"
            scope = resolve(full)
            return experiment(scope) if scope is not None else {}
        file = FileScope(stored)
        if not name:
            models = list_models(file)
            if len(models) != 1:
                return {}
            name = models[0]
        return experiment(find_class(file, name))
    except Exception:  # noqa: BLE001 -- the model load that follows reports the problem
        return {}


def apply_experiment_defaults(args: argparse.Namespace) -> None:
    """Fill ``--stop-time`` / ``--interval`` / ``--rtol`` left unset from the model's
    experiment annotation (else 1 s, the default grid, 1e-6)."""
    exp = experiment_of_reference(getattr(args, "model", "") or "")
    if getattr(args, "stop_time", None) is None:
        args.stop_time = exp.get("StopTime", 1.0)
    if getattr(args, "interval", None) is None and "Interval" in exp:
        args.interval = exp["Interval"]
    if hasattr(args, "rtol") and args.rtol is None:
        args.rtol = exp.get("Tolerance", 1e-6)


def cmd_export_mo(args: argparse.Namespace) -> int:
    from ..cli import _model_kwargs
    from ..errors import OptionError
    from ..loader import load_model
    from . import export_modelica

    out = Path(args.output) if args.output else None
    if out is not None:
        if out.is_dir():
            raise OptionError(f"-o {out}: is a directory; name a .mo file")
        if not out.parent.exists():
            raise OptionError(f"-o {out}: the folder {out.parent} does not exist")
    experiment: dict[str, Any] = dict(getattr_experiment(args.model))
    for key, value in (("StartTime", args.start_time), ("StopTime", args.stop_time),
                       ("Interval", args.interval), ("Tolerance", args.tolerance)):
        if value is not None:
            experiment[key] = value
    model = load_model(args.model, **_model_kwargs(args.arg))
    if not experiment:
        experiment = dict(model.__dict__.get("_mo_experiment") or {})
    name = args.name
    text = export_modelica(model, None, name=name, experiment=experiment or None)
    if out is None:
        from .export import Exporter

        out = Path(f"{name or Exporter(model).name}.mo")
    out.write_text(text, encoding="utf-8")
    model_name = text.split("\nmodel ", 1)[1].split()[0]
    print(f"{model_name}: {text.count(chr(10))} lines of Modelica -> {out} "
          f"(load it as {out}:{model_name})")
    if args.verify:
        _verify(model, out, model_name)
    return 0


def getattr_experiment(ref: str) -> dict[str, float]:
    return experiment_of_reference(ref)


def _verify(model: Any, path: Path, name: str) -> None:
    from ..compiler import compile
    from . import load_modelica
    from .errors import ModelicaExportError

    back = load_modelica(path, name)
    a, b = compile(model), compile(back)
    fa, fb = a.flat, b.flat
    names_a = [v.name for v in fa.variables]
    names_b = [v.name for v in fb.variables]
    if names_a != names_b or len(fa.equations) != len(fb.equations):
        raise ModelicaExportError(
            f"--verify: {path} loads back with {len(names_b)} variables and "
            f"{len(fb.equations)} equations, the model has {len(names_a)} and "
            f"{len(fa.equations)}")
    print(f"verify: {path} loads back: {len(names_b)} variables, {len(fb.equations)} "
          f"equations, states {', '.join(b.dae.state_names) or '-'}")


def register(sub: Any, model_args: Any) -> None:
    """Add ``export-mo`` to the ``bgmodelica`` parser."""
    p = sub.add_parser("export-mo", help="write a model as self-contained Modelica text")
    model_args(p)
    p.add_argument("-o", "--output", help="the .mo file (default <Model>.mo)")
    p.add_argument("--name", help="Modelica model name (default: the model's class name)")
    p.add_argument("--start-time", type=float, default=None,
                   help="experiment StartTime [s] (default: the model's, if any)")
    p.add_argument("--stop-time", type=float, default=None,
                   help="experiment StopTime [s] (default: the model's, if any)")
    p.add_argument("--interval", type=float, default=None, help="experiment Interval [s]")
    p.add_argument("--tolerance", type=float, default=None, help="experiment Tolerance")
    p.add_argument("--verify", action="store_true",
                   help="load the file back and check it compiles to the same variables and "
                        "equations")
    p.set_defaults(func=cmd_export_mo)


def modelica_path_options(argv: list[str]) -> list[str]:
    """Take ``--modelica-path DIR`` (any number, anywhere on the line) out of ``argv`` and
    put the folders on the Modelica library path."""
    from .errors import ModelicaError
    from .library_path import add_modelica_path

    rest: list[str] = []
    folders: list[str] = []
    k = 0
    while k < len(argv):
        a = argv[k]
        if a == "--modelica-path":
            if k + 1 >= len(argv):
                raise ModelicaError("--modelica-path needs a folder")
            folders.append(argv[k + 1])
            k += 2
            continue
        if a.startswith("--modelica-path="):
            folders.append(a.partition("=")[2])
        else:
            rest.append(a)
        k += 1
    if folders:
        add_modelica_path(*folders)
        # worker processes (sweeps on Dask, cosim) read the same libraries
        import os

        os.environ["MODELICAPATH"] = os.pathsep.join(
            [str(Path(f).resolve()) for f in folders]
            + [e for e in os.environ.get("MODELICAPATH", "").split(os.pathsep) if e])
    return rest
