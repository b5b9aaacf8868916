"""Load a model from a ``path/file.py:Name`` or ``module:Name`` reference."""

from __future__ import annotations

import difflib
import importlib
import importlib.util
import inspect
import sys
from pathlib import Path
from typing import Any

from .core.component import Component, Connector
from .errors import ModelError, ModelLoadError, OptionError, UserCodeError
from .validate import check_model_args, user_error, user_location


def load_model(ref: str, **kwargs: Any) -> Component:
    """Instantiate the model named by ``ref``.

    ``Name`` is a Component class or a function returning a Component; ``kwargs`` are passed
    to it (e.g. ``n=100`` for a parameterized example).
    """
    from .modelica import is_reference, load_reference

    if is_reference(ref):                  # Modelica text: file.mo:Package.Model
        return load_reference(ref, **kwargs)
    target, sep, name = ref.rpartition(":")
    if not sep or not target or not name:
        raise ModelLoadError(f"model reference {ref!r} must be 'path/file.py:Name', "
                             "'package.module:Name' or 'file.mo:Package.Model'")
    module = _load_module(target)
    if not hasattr(module, name):
        raise ModelLoadError(_missing(target, name, module_models(module)))
    obj = getattr(module, name)
    if isinstance(obj, Component):
        if kwargs:
            raise OptionError(f"--arg {', '.join(kwargs)}: {ref} is a model instance, which "
                              "takes no arguments")
        return obj
    if not callable(obj):
        raise ModelLoadError(f"{ref}: {name} is neither a Component class nor a function")
    kwargs = check_model_args(obj, kwargs, name)
    try:
        model = obj(**kwargs)
    except UserCodeError as err:       # raised while building a subcomponent: add the model
        raise UserCodeError(f"building {name}: {err}", err.path, err.location) from err.__cause__
    except ModelError:
        raise
    except RecursionError as err:
        raise user_error(err, f"building {name}", name) from err
    except Exception as err:  # noqa: BLE001 -- user code: say where, no traceback
        args = ", ".join(f"{k}={v!r}" for k, v in kwargs.items())
        raise user_error(err, f"building {name}({args})", name) from err
    if not isinstance(model, Component):
        raise ModelLoadError(f"{ref}: {name}() returned {type(model).__name__}, not a Component")
    return model


def _load_module(target: str):
    if target.endswith(".py") or "/" in target or "\\" in target:
        path = Path(target)
        if path.is_dir():
            raise ModelLoadError(f"model file {target} is a directory; name a .py file")
        if not path.is_file():
            raise ModelLoadError(f"model file {target} does not exist")
        if path.suffix != ".py":
            raise ModelLoadError(f"model file {target} is not a Python file (.py)")
        package = _package_of(path)
        if package is not None:               # a module of a package: relative imports work
            return _import_package_module(target, path, *package)
        mod_name = f"_bgmodelica_user_{abs(hash(path.resolve()))}"
        spec = importlib.util.spec_from_file_location(mod_name, path)
        if spec is None or spec.loader is None:
            raise ModelLoadError(f"cannot import {target}")
        module = importlib.util.module_from_spec(spec)
        sys.modules[mod_name] = module
        parent = str(path.resolve().parent)
        if parent not in sys.path:
            sys.path.insert(0, parent)
        try:
            spec.loader.exec_module(module)
        except ModelError:
            sys.modules.pop(mod_name, None)
            raise
        except (KeyboardInterrupt, GeneratorExit):
            sys.modules.pop(mod_name, None)
            raise
        except BaseException as err:  # noqa: BLE001 -- user module code: say where
            sys.modules.pop(mod_name, None)
            raise _import_failure(target, err) from None
        return module
    if str(Path.cwd()) not in sys.path:
        sys.path.insert(0, str(Path.cwd()))
    try:
        return importlib.import_module(target)
    except ModuleNotFoundError as err:
        if err.name and (target == err.name or target.startswith(err.name + ".")):
            raise ModelLoadError(f"no module {target!r} ({err})") from None
        raise _import_failure(target, err) from None
    except ModelError:
        raise
    except (KeyboardInterrupt, GeneratorExit):
        raise
    except BaseException as err:  # noqa: BLE001 -- user module code: say where
        raise _import_failure(target, err) from None


def _package_of(path: Path) -> tuple[Path, str] | None:
    """``(directory to import from, dotted module name)`` of a file inside a package (its
    directory has an ``__init__.py``), else None."""
    path = path.resolve()
    here = path.parent
    if not (here / "__init__.py").is_file():
        return None
    parts = [] if path.stem == "__init__" else [path.stem]
    while (here / "__init__.py").is_file() and here.parent != here:
        parts.insert(0, here.name)
        here = here.parent
    if not parts or not all(p.isidentifier() for p in parts):
        return None
    return here, ".".join(parts)


def _import_package_module(target: str, path: Path, root: Path, dotted: str):
    top = dotted.split(".")[0]
    loaded = sys.modules.get(top)
    if loaded is not None:
        where = [str(Path(p).resolve()) for p in getattr(loaded, "__path__", [])]
        if str((root / top).resolve()) not in where:
            raise ModelLoadError(
                f"model file {target} belongs to package {top!r} in {root}, but another "
                f"package {top!r} is already imported from {', '.join(where) or '?'}")
    if str(root) not in sys.path:
        sys.path.insert(0, str(root))
    try:
        module = importlib.import_module(dotted)
    except ModelError:
        raise
    except (KeyboardInterrupt, GeneratorExit):
        raise
    except BaseException as err:  # noqa: BLE001 -- user module code: say where
        raise _import_failure(target, err) from None
    if Path(getattr(module, "__file__", "") or "").resolve() != path.resolve():
        raise ModelLoadError(f"model file {target}: importing it as {dotted} found "
                             f"{getattr(module, '__file__', '?')} instead")
    return module


def _import_failure(target: str, err: BaseException) -> ModelLoadError:
    """A one-line :class:`ModelLoadError` for an exception raised while importing ``target``
    (syntax errors with their line, other errors with the user's file and line)."""
    if isinstance(err, SyntaxError):
        where = f"{err.filename}:{err.lineno}" if err.filename else f"line {err.lineno}"
        return ModelLoadError(f"model file {target} does not parse: {err.msg} at {where}")
    loc = user_location(err)
    text = str(err).strip().splitlines()[0] if str(err).strip() else ""
    return ModelLoadError(f"cannot import {target}: {type(err).__name__}"
                          + (f": {text}" if text else "") + (f" at {loc}" if loc else ""))


def module_models(module) -> list[str]:
    """Names of the models ``module`` offers, sorted: Component classes (not connectors) and
    public functions defined in it, re-exported from its own submodules, or listed in its
    ``__all__``."""
    own = module.__name__
    listed = set(getattr(module, "__all__", ()) or ())
    package = own + "." if hasattr(module, "__path__") else None

    def offered(value) -> bool:
        where = getattr(value, "__module__", "") or ""
        return (where == own or bool(package) and where.startswith(package))

    names = []
    for key, value in vars(module).items():
        if key.startswith("_"):
            continue
        if inspect.isclass(value):
            if not issubclass(value, Component) or issubclass(value, Connector):
                continue
            if value is Component or value.__module__.startswith("bgmodelica.core"):
                continue
        elif not inspect.isfunction(value):
            continue
        if key in listed or offered(value):
            names.append(key)
    return sorted(names)


def _missing(target: str, name: str, models: list[str]) -> str:
    """One line: ``target`` has no model ``name``; the close spellings, then what it offers."""
    text = f"{target} has no model named {name!r}"
    by_case = {m.lower(): m for m in models}
    close = difflib.get_close_matches(name, models, n=3, cutoff=0.6)
    if name.lower() in by_case and by_case[name.lower()] not in close:
        close.insert(0, by_case[name.lower()])
    if close:
        text += f"; did you mean {', '.join(close)}?"
    if not models:
        return text + " (it offers no models: Component classes or functions)"
    shown = ", ".join(models[:20]) + (f", ... ({len(models)} in all)" if len(models) > 20 else "")
    return text + f" (it offers: {shown})"
