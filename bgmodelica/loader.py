"""Load a model from a ``path/file.py:Name`` or ``module:Name`` reference."""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import sys
from pathlib import Path
from typing import Any

from .core.component import Component
from .errors import ModelError, ModelLoadError


def load_model(ref: str, **kwargs: Any) -> Component:
    """Instantiate the model named by ``ref``.

    ``Name`` is a Component class or a function returning a Component; ``kwargs`` are passed
    to it (e.g. ``n=100`` for a parameterized example).
    """
    target, sep, name = ref.rpartition(":")
    if not sep or not target or not name:
        raise ModelLoadError(f"model reference {ref!r} must be 'path/file.py:Name' or "
                             "'package.module:Name'")
    module = _load_module(target)
    if not hasattr(module, name):
        public = [n for n, v in vars(module).items() if not n.startswith("_") and (
            inspect.isclass(v) and issubclass(v, Component) and v.__module__ == module.__name__
            or inspect.isfunction(v) and v.__module__ == module.__name__)]
        raise ModelLoadError(f"{target} has no model named {name!r}; it defines: "
                             f"{', '.join(sorted(public)) or 'no models'}")
    obj = getattr(module, name)
    if isinstance(obj, Component):
        return obj
    if not callable(obj):
        raise ModelLoadError(f"{ref}: {name} is neither a Component class nor a function")
    try:
        model = obj(**kwargs)
    except ModelError:
        raise
    except TypeError as err:
        raise ModelLoadError(f"{ref}: cannot build {name}: {err}") from None
    if not isinstance(model, Component):
        raise ModelLoadError(f"{ref}: {name}() returned {type(model).__name__}, not a Component")
    return model


def _load_module(target: str):
    if target.endswith(".py") or "/" in target or "\\" in target:
        path = Path(target)
        if not path.is_file():
            raise ModelLoadError(f"model file {target} does not exist")
        mod_name = f"_bgmodelica_user_{abs(hash(path.resolve()))}"
        spec = importlib.util.spec_from_file_location(mod_name, path)
        if spec is None or spec.loader is None:
            raise ModelLoadError(f"cannot import {target}")
        module = importlib.util.module_from_spec(spec)
        sys.modules[mod_name] = module
        parent = str(path.resolve().parent)
        if parent not in sys.path:
            sys.path.insert(0, parent)
        spec.loader.exec_module(module)
        return module
    if str(Path.cwd()) not in sys.path:
        sys.path.insert(0, str(Path.cwd()))
    try:
        return importlib.import_module(target)
    except ModuleNotFoundError as err:
        raise ModelLoadError(f"no module {target!r} ({err})") from None
