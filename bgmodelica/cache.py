"""Disk cache of compiled models: the second compilation of the same model is a load.

The key is a digest of the model's *structure and code*: the component tree (paths, classes,
declarations with their units, shapes and start values, connections, imperative equations,
plain instance attributes such as a section count) and the source of every Python module the
classes come from, plus the compiler's own source. Parameter *values* are not part of it: a
loaded model takes the values of the component it is asked for, so a parameter study reuses
one entry. A model with anything the key cannot describe (an attribute of unknown type,
CasADi expressions written directly in an imperative equation) is compiled without the cache.

Entries are a pickle of the :class:`~bgmodelica.compiler.CompiledModel` whose CasADi
expressions are stored together in one CasADi serialization (so the expressions keep sharing
their symbols). ``compile(model, cache=True)`` uses :func:`default_dir` (``$BGMODELICA_CACHE``
or ``~/.cache/bgmodelica``); ``cache="path"`` another folder; :func:`clear` empties it.

An entry that does not pay is dropped: when loading it (its key included) took longer than
compiling the model had taken (and more than :data:`MIN_LOSS` seconds), it is replaced by a
small note (``KEY.nocache``, the two times in JSON) and later compilations of that model
skip the cache. Large models made of array equations are the usual case: they compile
about as fast as they load.
"""

from __future__ import annotations

import copyreg
import functools
import hashlib
import io
import json
import os
import pickle
import sys
import threading
from dataclasses import is_dataclass, replace
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np

from .core.component import Component, Connection, Connector, Element
from .core.expr import Equation, Expr, Leaf, Op
from .core.variables import KIND_PARAMETER

FORMAT = 1
#: a load slower than compiling is ignored below this many seconds [s] (noise, small models)
MIN_LOSS = 0.5
_FILE_DIGESTS: dict[tuple[str, int, int], str] = {}


class Uncacheable(Exception):
    """The model holds something the cache key cannot describe."""


def default_dir() -> Path:
    """``$BGMODELICA_CACHE`` or ``~/.cache/bgmodelica`` (``$XDG_CACHE_HOME`` respected)."""
    env = os.environ.get("BGMODELICA_CACHE")
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "bgmodelica"


def clear(folder: str | Path | None = None) -> int:
    """Delete every cached model in ``folder`` (default :func:`default_dir`); returns the
    number of entries removed."""
    root = Path(folder) if folder is not None else default_dir()
    n = 0
    for entry in root.glob("*/*.bgmc"):
        entry.unlink()
        n += 1
    for note in root.glob("*/*.nocache"):
        note.unlink()
    return n


# -- the key --------------------------------------------------------------------------------

def _file_digest(path: str) -> str:
    """SHA-256 of a file's content (memoized while its size and mtime stay the same)."""
    try:
        st = os.stat(path)
    except OSError:
        return "missing"
    memo = (path, st.st_mtime_ns, st.st_size)
    if memo not in _FILE_DIGESTS:
        _FILE_DIGESTS[memo] = hashlib.sha256(Path(path).read_bytes()).hexdigest()
    return _FILE_DIGESTS[memo]


@functools.lru_cache(maxsize=256)
def _package_files(module_name: str) -> tuple[str, ...]:
    """The source files of the top-level package of ``module_name`` (or its one file)."""
    if "." in module_name:
        return _package_files(module_name.partition(".")[0])
    top = sys.modules.get(module_name)
    mod = sys.modules.get(module_name)
    if top is not None and getattr(top, "__path__", None):
        root = Path(list(top.__path__)[0])
        return tuple(sorted(str(p) for p in root.rglob("*.py")))
    src = getattr(mod, "__file__", None)
    return (src,) if src else ()


def _code_digest(classes: set[type]) -> str:
    """Digest of the source of the packages that define ``classes``, and of bgmodelica."""
    files = set(_package_files(__name__))
    for cls in classes:
        for base in cls.__mro__:
            if base.__module__ not in ("builtins", "__main__"):
                files.update(_package_files(base.__module__))
            elif base.__module__ == "__main__":
                main = getattr(sys.modules.get("__main__"), "__file__", None)
                if not main:
                    raise Uncacheable(f"{cls.__name__} is defined interactively")
                files.add(main)
    h = hashlib.sha256()
    for path in sorted(files):
        h.update(f"{path}:{_file_digest(path)}\n".encode())
    return h.hexdigest()


def _value_key(value: Any, where: str) -> str:
    """Text of a plain attribute value; :class:`Uncacheable` for anything else."""
    if value is None or isinstance(value, (bool, int, float, str, complex)):
        text = repr(value)
        if isinstance(value, str) and len(value) < 4096 and os.path.isfile(value):
            st = os.stat(value)                         # a data file: its content counts
            text += f"@{_file_digest(os.path.abspath(value))}:{st.st_size}"
        return text
    if isinstance(value, (np.integer, np.floating, np.bool_)):
        return repr(value.item())
    if isinstance(value, np.ndarray) and value.dtype.kind in "biuf":
        return f"array{value.shape}:{hashlib.sha256(value.tobytes()).hexdigest()}"
    if isinstance(value, (list, tuple)):
        return "[" + ",".join(_value_key(v, where) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ",".join(f"{_value_key(k, where)}:{_value_key(v, where)}"
                              for k, v in sorted(value.items(), key=lambda kv: repr(kv[0])))
    if isinstance(value, Path):
        return _value_key(str(value), where)
    raise Uncacheable(f"{where}: attribute of type {type(value).__name__}")


_PLAIN = (str, float, int, bool, type(None), tuple)


class _KeyWriter:
    """Text of the parts of one model: element paths and dotted symbol names resolved."""

    def __init__(self, paths: dict[int, str]) -> None:
        self.paths = paths

    def name(self, sym: Any) -> str | None:
        """Dotted name of a symbol of the model (``der(...)`` for a derivative), None for a
        symbol that is not part of it."""
        base = getattr(sym, "der_of", None)
        if base is not None:
            inner = self.name(base) if base.der is sym else None
            return None if inner is None else f"der({inner})"
        owner = getattr(sym, "owner", None)
        path = self.paths.get(id(owner))
        if path is None or owner._symbols.get(sym.name) is not sym:
            return None
        return f"{path}.{sym.name}" if path else sym.name

    def decl(self, decl: Any, where: str) -> str:
        """Every field of a declaration but its description, and the value of a numeric
        parameter left out."""
        fields_ = dict(vars(decl))
        fields_.pop("description", None)
        if decl.kind == KIND_PARAMETER and not isinstance(fields_.get("value"), Expr):
            fields_.pop("value", None)
        for name, v in fields_.items():
            if not isinstance(v, _PLAIN):
                fields_[name] = self.expr_or_value(v, where)
        return f"{type(decl).__name__}{fields_!r}"

    def expr_or_value(self, v: Any, where: str) -> str:
        if isinstance(v, Expr):
            return self.expr(v)
        if isinstance(v, (ca.SX, ca.MX)):
            raise Uncacheable(f"{where}: a CasADi expression")
        return _value_key(v, where)

    def expr(self, e: Any) -> str:
        if isinstance(e, float):
            return repr(e)
        if isinstance(e, Leaf):
            name = self.name(e.sym)
            if name is None:
                name = getattr(e.sym, "name", "?")
                if name != "time":
                    raise Uncacheable(f"an expression uses {name}, which is not part of the "
                                      "model")
            return name
        if isinstance(e, Op):
            return f"{e.op}(" + ",".join(self.expr(a) for a in e.args) + ")"
        raise Uncacheable(f"an expression node {type(e).__name__}")

    def item(self, item: Any) -> str:
        """An imperative equation or connection."""
        if isinstance(item, Connection):
            return "connect(" + ",".join(self.end(x) for x in (item.a, item.b)) + ")"
        if isinstance(item, Equation):
            return (f"{self.expr_or_value(item.lhs, 'equation')}=="
                    f"{self.expr_or_value(item.rhs, 'equation')}")
        raise Uncacheable(f"an imperative equation of type {type(item).__name__}")

    def end(self, x: Any) -> str:
        if isinstance(x, Connector) and id(x) in self.paths:
            return self.paths[id(x)]
        if isinstance(x, Expr):
            return self.expr(x)
        raise Uncacheable(f"connect() of {x!r}")


def _first_item(pair: tuple[str, Any]) -> str:
    return pair[0]


def walk(model: Component) -> list[tuple[Element, str]]:
    """Every element of the tree with its dotted path, parents first."""
    order: list[tuple[Element, str]] = []
    stack: list[tuple[Element, str]] = [(model, "")]
    while stack:
        elem, path = stack.pop()
        order.append((elem, path))
        children = elem._children
        if children:
            prefix = f"{path}." if path else ""
            stack.extend((child, prefix + child_name)
                         for child_name, child in reversed(children.items()))
    return order


def model_key(model: Component, order: list[tuple[Element, str]] | None = None) -> str:
    """The cache key of ``model``: a hex digest of its structure and code (see the module
    docstring); raises :class:`Uncacheable` for models the key cannot describe. ``order``:
    :func:`walk` of the model, if already made."""
    from .core.arrays import ArrayExpr, ElementArray

    order = walk(model) if order is None else order
    writer = _KeyWriter({id(elem): path for elem, path in order})
    lines: list[str] = []
    add = lines.append
    classes: set[type] = set()
    decl_memo: dict[int, str] = {}
    skip = (Element, Expr, ArrayExpr, ElementArray)
    for elem, path in order:                   # pass 2: what each element holds
        cls = type(elem)
        classes.add(cls)
        add(f"E {path} {cls.__module__}.{cls.__qualname__}")
        for name, sym in elem._symbols.items():
            text = decl_memo.get(id(sym.decl))
            if text is None:
                text = decl_memo[id(sym.decl)] = " " + writer.decl(sym.decl, path or "top")
            add("D " + name + text)
        attrs = vars(elem)
        other = attrs.keys() - elem._symbols.keys() - elem._children.keys()
        plain = [(key, attrs[key]) for key in other
                 if key[0] != "_" and not isinstance(attrs[key], skip)]
        for key, value in sorted(plain, key=_first_item):
            add(f"A {key}={_value_key(value, f'{path or cls.__name__}.{key}')}")
        for item in attrs.get("_equations", ()):
            add("Q " + writer.item(item))
        for item in attrs.get("_initial_equations", ()):
            add("I " + writer.item(item))
    h = hashlib.sha256()
    h.update(f"format {FORMAT}\ncode {_code_digest(classes)}\n".encode())
    h.update("\n".join(lines).encode())
    return h.hexdigest()


# -- storing and loading --------------------------------------------------------------------

class _Pickler(pickle.Pickler):
    """Pickles a compiled model with its SX expressions set aside (stored together, one
    CasADi serialization of their shared graph). SX objects are found through the
    dispatch table (looked up in C per object type) rather than a per-object hook."""

    def __init__(self, f: Any) -> None:
        super().__init__(f, protocol=pickle.HIGHEST_PROTOCOL)
        self.sx: list[ca.SX] = []
        self.dispatch_table = {**copyreg.dispatch_table,
                               **{cls: _refuse for cls in _subclasses(Element)},
                               ca.SX: self._set_aside, ca.Function: _refuse, ca.MX: _refuse}

    def _set_aside(self, obj: ca.SX) -> tuple:
        self.sx.append(obj)                       # the pickle memo sees each object once
        return (_stored_sx, (len(self.sx) - 1,))


def _subclasses(cls: type) -> set[type]:
    """``cls`` and every class derived from it (the dispatch table matches exact types)."""
    out, todo = {cls}, [cls]
    while todo:
        for sub in todo.pop().__subclasses__():
            if sub not in out:
                out.add(sub)
                todo.append(sub)
    return out


def _refuse(obj: Any) -> tuple:
    raise Uncacheable(f"the compiled model refers to a {type(obj).__name__}")


_LOADING = threading.local()


def _stored_sx(index: int) -> ca.SX:
    """The ``index``-th SX of the entry being loaded (see :func:`load`)."""
    return _LOADING.sx[index]


def _entry(folder: Path, key: str) -> Path:
    return folder / key[:2] / f"{key}.bgmc"


def _note(folder: Path, key: str) -> Path:
    return folder / key[:2] / f"{key}.nocache"


def pays(compile_seconds: float, load_seconds: float) -> bool:
    """Whether an entry that loaded in ``load_seconds`` is worth keeping for a model that
    compiled in ``compile_seconds``."""
    return load_seconds <= max(compile_seconds, MIN_LOSS)


def skipped(folder: Path, key: str) -> bool:
    """Whether an earlier load found that the entry of ``key`` does not pay."""
    return _note(folder, key).is_file()


def drop(folder: Path, key: str, compile_seconds: float, load_seconds: float) -> None:
    """Replace the entry of ``key`` by a note that it does not pay (see the module docs)."""
    note = _note(folder, key)
    note.parent.mkdir(parents=True, exist_ok=True)
    note.write_text(json.dumps({"compile_s": compile_seconds, "load_s": load_seconds}))
    _entry(folder, key).unlink(missing_ok=True)


def _compact_rows(compiled: Any) -> None:
    """Point the symbols of the flat models at rows of their models' own columns: flattening
    left them rows of one vector of every symbol of the tree, aliases eliminated since
    included, which would otherwise be stored whole (about half the symbols of a network)."""
    models = {id(m): m for m in (compiled.flat, compiled.reduced.model, compiled.sorted.model)}
    for model in models.values():
        for items, stacked in ((model.variables, model.stacked_variables),
                               (model.parameters, model.stacked_parameters)):
            if any(v.at is not None for v in items):
                column = stacked()
                for k, v in enumerate(items):
                    if v.at is not None:
                        v.at = (column, k)


def store(compiled: Any, folder: Path, key: str) -> Path | None:
    """Write ``compiled`` under ``key``; None (and nothing written) if it cannot be."""
    _compact_rows(compiled)
    source, cache = compiled.source, compiled.dae.cache
    compiled.source, compiled.dae.cache = None, {}
    try:
        buf = io.BytesIO()
        p = _Pickler(buf)
        p.dump(compiled)
        ser = ca.StringSerializer()
        ser.pack(p.sx)
        blob = pickle.dumps((FORMAT, ser.encode(), buf.getvalue()),
                            protocol=pickle.HIGHEST_PROTOCOL)
    except (Uncacheable, pickle.PicklingError, TypeError, RuntimeError):
        return None
    finally:
        compiled.source, compiled.dae.cache = source, cache
    path = _entry(folder, key)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(f".tmp{os.getpid()}")
    tmp.write_bytes(blob)
    os.replace(tmp, path)                       # atomic: readers never see half a file
    return path


def load(folder: Path, key: str, model: Component,
         order: list[tuple[Element, str]] | None = None) -> Any | None:
    """The compiled model stored under ``key`` with ``model``'s parameter values, or None
    (no entry, or an unreadable one, which is removed). ``order``: :func:`walk` of the
    model, if already made."""
    path = _entry(folder, key)
    if not path.is_file():
        return None
    try:
        fmt, text, body = pickle.loads(path.read_bytes())
        if fmt != FORMAT:
            raise ValueError("format")
        _LOADING.sx = ca.StringDeserializer(text).unpack()
        try:
            compiled = pickle.loads(body)
        finally:
            _LOADING.sx = None
    except Exception:  # noqa: BLE001 -- a damaged entry is recompiled, not an error
        path.unlink(missing_ok=True)
        return None
    values = _parameter_values(walk(model) if order is None else order)
    if not all(isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, bool)
               for v in values.values()):
        return None                      # compiling names the bad value
    evaluated = getattr(compiled, "evaluated", None) or {}
    if any(values.get(name, value) != value for name, value in evaluated.items()):
        return None                      # a parameter that changed the structure changed
    compiled.source = model
    _set_parameter_values(compiled, values)
    return compiled


def _parameter_values(order: list[tuple[Element, str]]) -> dict[str, Any]:
    """Numeric parameter values by dotted name (``order``: :func:`walk` of the model)."""
    out: dict[str, Any] = {}
    for elem, path in order:
        prefix = f"{path}." if path else ""
        for name, sym in elem._symbols.items():
            decl = sym.decl
            if decl.kind == KIND_PARAMETER and not isinstance(decl.value, Expr):
                out[prefix + name] = decl.value
    return out


def _set_parameter_values(compiled: Any, values: dict[str, Any]) -> None:
    seen: set[int] = set()
    for group in (compiled.flat.parameters, compiled.reduced.model.parameters,
                  compiled.sorted.model.parameters, compiled.dae.parameters):
        for p in group:
            if id(p) in seen or p.name not in values or isinstance(p.decl.value, ca.SX) \
                    or p.decl.value == values[p.name]:
                continue
            seen.add(id(p))
            if is_dataclass(p.decl):
                p.decl = replace(p.decl, value=values[p.name])
