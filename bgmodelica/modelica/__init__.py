"""Modelica text in and out.

Import: :func:`load_modelica` reads a practical subset of Modelica (packages, ``within``,
models, blocks, connectors, records, types, ``extends`` with modifiers, parameters, constants,
discrete/Integer/Boolean variables with attributes, ``input``/``output``/``flow``, modifiers
and simple ``redeclare``, equations with ``der`` of any expression, if-, for- and
when-equations, ``connect`` with component arrays and subscripts, ``initial equation``,
``reinit``/``pre``/``sample``, arrays with sizes from parameters, the built-in functions,
``annotation(experiment(...))``) and builds a :class:`~bgmodelica.Component` tree. A subset of
the Modelica Standard Library maps onto the project's ``library`` classes
(:mod:`.msl`). Errors name ``file:line:column`` and the construct.

Export: :func:`export_modelica` writes any model as self-contained Modelica text (one class
per distinct component, units, start/fixed attributes, the experiment annotation) that loads
back with :func:`load_modelica` and reproduces the model's results.

    import bgmodelica as bg
    model = bg.load_modelica("rc.mo", "Circuits.RC")
    bg.simulate(model, **bg.modelica.experiment_of(model))
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from . import ast as A
from .errors import ModelicaError, ModelicaExportError, ModelicaSyntaxError
from .library_path import add_modelica_path, modelica_path

__all__ = ["load_modelica", "load_modelica_text", "load_class", "add_modelica_path",
           "modelica_path", "export_modelica", "experiment_of",
           "list_models", "ModelicaError", "ModelicaSyntaxError", "ModelicaExportError"]


def _load(stored: Any, name: str | None, kwargs: dict[str, Any]):
    from . import builder as B
    from .scope import FileScope

    file = FileScope(stored)
    if name is None:
        models = B.list_models(file)
        if len(models) != 1:
            raise ModelicaError(f"{stored.file}: name the model to load (it defines "
                                f"{', '.join(models) or 'no models'})")
        name = models[0]
    return _instantiate(B.find_class(file, name), name, stored.file, kwargs)


def _instantiate(scope: Any, name: str, where: str, kwargs: dict[str, Any]):
    from ..errors import ModelError
    from ..structure.graph import gc_paused
    from . import builder as B

    view = B.class_view(scope)
    if view.kind not in ("model", "block", "class"):
        raise ModelicaError(f"{where}: {name} is a {view.kind}, not a model")
    try:
        with gc_paused():                      # as a Python model's constructor is
            model = B.instantiate(view, B.top_mods(kwargs), None, "", scope, scope.cdef.pos)
    except RecursionError:
        raise ModelicaError(f"{where}: {name}: the class hierarchy is too deep or "
                            "recursive") from None
    except ModelError:
        raise
    except B.NotConstant as err:
        raise ModelicaError(f"{where}: {name}: cannot evaluate when built: {err.what}") \
            from None
    exp = B.experiment(scope)
    object.__setattr__(model, "_mo_experiment", exp)
    if "experiment" not in model._symbols and "experiment" not in model._children:
        object.__setattr__(model, "experiment", exp)
    object.__setattr__(model, "_mo_source", (scope.cdef.file or where, scope.full_name))
    return model


def load_class(name: str, **modifiers: Any):
    """Instantiate the class ``name`` (fully qualified, e.g.
    ``"Modelica.Mechanics.Rotational.Examples.First"``) of a library on the library path
    (:func:`add_modelica_path`, ``MODELICAPATH``); ``modifiers`` as in :func:`load_modelica`."""
    from .library_path import locate, modelica_path, resolve

    head = name.partition(".")[0]
    if locate(head) is None:
        where = ", ".join(str(p) for p in modelica_path()) or "empty: set MODELICAPATH or " \
            "use --modelica-path DIR"
        raise ModelicaError(f"{name}: no package {head} on the Modelica library path "
                            f"({where})")
    scope = resolve(name)
    if scope is None or not hasattr(scope, "cdef"):
        raise ModelicaError(f"{name}: no such class in the library {head}"
                            f"{_did_you_mean(name)}")
    return _instantiate(scope, name, scope.cdef.file, modifiers)


def _did_you_mean(name: str) -> str:
    import difflib

    from .library_path import resolve, stored_names

    parent, _, last = name.rpartition(".")
    scope = resolve(parent) if parent else None
    if scope is None or not hasattr(scope, "cdef"):
        return ""
    names = [e.name for e in scope.cdef.elements if isinstance(e, A.ClassDef)]
    names += stored_names(scope.cdef)
    close = difflib.get_close_matches(last, names, n=3, cutoff=0.6)
    return f"; did you mean {' or '.join(parent + '.' + c for c in close)}?" if close else ""


def _file_in_library(stored: Any, path: Path) -> str | None:
    """The library root of a file stored in a package folder (``DIR/P/package.mo`` or a
    file with a ``within`` clause whose folders match), else None."""
    within = [w for w in (stored.within or "").split(".") if w]
    folder = path.resolve().parent
    if path.name == "package.mo":
        folder = folder.parent
    for part in reversed(within):
        if folder.name != part and not folder.name.startswith(part + " "):
            return None
        folder = folder.parent
    if path.name != "package.mo" and not within:
        return None
    return str(folder)


def load_modelica(path: str | Path, name: str | None = None, **modifiers: Any):
    """Instantiate class ``name`` (dotted, e.g. ``"Circuits.RC"``) of the Modelica file
    ``path`` as a :class:`~bgmodelica.Component`.

    ``modifiers`` modify the top-level class like Modelica modifiers: ``n=100`` (a parameter,
    also a structural one such as an array size), ``**{"R1.R": 2.0}``. Without ``name`` the
    file must define exactly one model. The model's ``experiment`` attribute holds the
    ``experiment`` annotation (``StartTime``, ``StopTime``, ``Interval``, ``Tolerance``).
    """
    from .library_path import add_modelica_path
    from .parser import parse_file

    p = Path(path)
    if not p.exists() and name is None and not str(path).lower().endswith(".mo"):
        return load_class(str(path), **modifiers)      # a class name on the library path
    stored = parse_file(path)
    root = _file_in_library(stored, p)
    if root is not None:               # a file of a package folder: load through the library
        add_modelica_path(root)
        within = stored.within or ""
        if name is None:
            name = ".".join(x for x in (within, stored.classes[0].name) if x) \
                if len(stored.classes) == 1 else None
        if name is not None:
            full = name if within and name.startswith(within.split(".")[0] + ".") or \
                not within else f"{within}.{name}"
            return load_class(full, **modifiers)
    return _load(stored, name, modifiers)


def load_modelica_text(text: str, name: str | None = None, *, file: str = "<string>",
                       **modifiers: Any):
    """:func:`load_modelica` for Modelica source text (``file`` names it in messages)."""
    from .parser import parse_text

    return _load(parse_text(text, file), name, modifiers)


def list_models(path: str | Path) -> list[str]:
    """The dotted names of the (non-partial) models and blocks of a Modelica file."""
    from .builder import list_models as _list
    from .parser import parse_file
    from .scope import FileScope

    return _list(FileScope(parse_file(path)))


def experiment_of(model: Any) -> dict[str, float]:
    """Keyword arguments for :func:`bgmodelica.simulate` from a loaded model's experiment
    annotation: ``stop_time``, ``start_time``, ``interval``, ``rtol`` (those given)."""
    exp = model.__dict__.get("_mo_experiment") or getattr(model, "experiment", None) or {}
    if not isinstance(exp, dict):
        exp = {}
    out: dict[str, float] = {}
    for key, arg in (("StartTime", "start_time"), ("StopTime", "stop_time"),
                     ("Interval", "interval"), ("Tolerance", "rtol")):
        if key in exp:
            out[arg] = exp[key]
    return out


def export_modelica(model: Any, path: str | Path | None = None, **options: Any) -> str:
    """Modelica text of ``model`` (written to ``path`` when given); see
    :func:`bgmodelica.modelica.export.export_modelica`."""
    from .export import export_modelica as _export

    return _export(model, path, **options)


def is_reference(ref: str) -> bool:
    """Whether a MODEL reference names Modelica: a file (``file.mo:Package.Model`` or
    ``file.mo``) or a class of a library on the library path (``Modelica.Blocks.X``)."""
    path, sep, _ = ref.rpartition(":")
    if ref.lower().endswith(".mo") or bool(sep) and path.lower().endswith(".mo"):
        return True
    return is_library_class(ref)


def is_library_class(ref: str) -> bool:
    """Whether ``ref`` is a dotted class name whose top package is on the library path."""
    from .library_path import locate

    if ":" in ref or "/" in ref or not all(p.isidentifier() for p in ref.split(".")):
        return False
    return locate(ref.partition(".")[0]) is not None


def load_reference(ref: str, **modifiers: Any):
    """Load ``file.mo:Package.Model`` (or ``file.mo`` defining one model); ``modifiers`` as
    in :func:`load_modelica` (``--arg n=100`` on the command line)."""
    if is_library_class(ref):
        return load_class(ref, **modifiers)
    if ref.lower().endswith(".mo"):
        path, name = ref, None
    else:
        path, _, name = ref.rpartition(":")
    p = Path(path)
    if p.is_dir():
        raise ModelicaError(f"Modelica file {path} is a directory; name a .mo file")
    if not p.is_file():
        raise ModelicaError(f"Modelica file {path} does not exist")
    return load_modelica(p, name or None, **modifiers)
