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

from .errors import ModelicaError, ModelicaExportError, ModelicaSyntaxError

__all__ = ["load_modelica", "load_modelica_text", "export_modelica", "experiment_of",
           "list_models", "ModelicaError", "ModelicaSyntaxError", "ModelicaExportError"]


def _load(stored: Any, name: str | None, kwargs: dict[str, Any]):
    from ..errors import ModelError
    from ..structure.graph import gc_paused
    from . import builder as B
    from .scope import FileScope

    file = FileScope(stored)
    if name is None:
        models = B.list_models(file)
        if len(models) != 1:
            raise ModelicaError(f"{stored.file}: name the model to load (it defines "
                                f"{', '.join(models) or 'no models'})")
        name = models[0]
    scope = B.find_class(file, name)
    view = B.class_view(scope)
    if view.kind not in ("model", "block", "class"):
        raise ModelicaError(f"{stored.file}: {name} is a {view.kind}, not a model")
    try:
        with gc_paused():                      # as a Python model's constructor is
            model = B.instantiate(view, B.top_mods(kwargs), None, "", scope, scope.cdef.pos)
    except RecursionError:
        raise ModelicaError(f"{stored.file}: {name}: the class hierarchy is too deep or "
                            "recursive") from None
    except ModelError:
        raise
    exp = B.experiment(scope)
    object.__setattr__(model, "_mo_experiment", exp)
    if "experiment" not in model._symbols and "experiment" not in model._children:
        object.__setattr__(model, "experiment", exp)
    object.__setattr__(model, "_mo_source", (stored.file, name))
    return model


def load_modelica(path: str | Path, name: str | None = None, **modifiers: Any):
    """Instantiate class ``name`` (dotted, e.g. ``"Circuits.RC"``) of the Modelica file
    ``path`` as a :class:`~bgmodelica.Component`.

    ``modifiers`` modify the top-level class like Modelica modifiers: ``n=100`` (a parameter,
    also a structural one such as an array size), ``**{"R1.R": 2.0}``. Without ``name`` the
    file must define exactly one model. The model's ``experiment`` attribute holds the
    ``experiment`` annotation (``StartTime``, ``StopTime``, ``Interval``, ``Tolerance``).
    """
    from .parser import parse_file

    stored = parse_file(path)
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
    """Whether a MODEL reference names a Modelica file (``file.mo:Package.Model`` or
    ``file.mo``)."""
    path, sep, _ = ref.rpartition(":")
    return ref.lower().endswith(".mo") or bool(sep) and path.lower().endswith(".mo")


def load_reference(ref: str, **modifiers: Any):
    """Load ``file.mo:Package.Model`` (or ``file.mo`` defining one model); ``modifiers`` as
    in :func:`load_modelica` (``--arg n=100`` on the command line)."""
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
