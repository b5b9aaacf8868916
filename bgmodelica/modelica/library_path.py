"""Modelica libraries on the library path (MODELICAPATH), loaded lazily.

The library path is a list of folders that hold top-level packages, as Modelica tools read
it (Modelica Language Specification, section 13.3): a package ``P`` is the folder ``P/``
holding ``package.mo`` (its classes one file ``X.mo`` or one folder ``X/package.mo`` each, in
the order of ``package.order``), the folder ``P VERSION/`` (``Modelica 4.1.0``), or the file
``P.mo``. Folders come from :func:`add_modelica_path` (the command line's
``--modelica-path``), then the ``MODELICAPATH`` environment variable (``os.pathsep``
separated).

Only what a model uses is read: a package folder's ``package.mo`` is parsed when the package
is first looked into, a class file when its name is first looked up (parsed files are cached
on disk by content, see :func:`~bgmodelica.modelica.parser.parse_file`).
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

from . import ast as A
from .errors import ModelicaError

_extra: list[Path] = []
_tops: dict[tuple[str, tuple[str, ...]], Any] = {}

_VERSIONED = re.compile(r"^(?P<name>[A-Za-z_][A-Za-z0-9_]*) (?P<version>[0-9][^/]*)$")


def add_modelica_path(*folders: str | os.PathLike) -> None:
    """Put ``folders`` (each holding top-level packages) first on the library path."""
    for folder in reversed(folders):
        p = Path(folder).expanduser()
        if not p.is_dir():
            raise ModelicaError(f"Modelica library path {folder}: no such folder")
        p = p.resolve()
        if p in _extra:
            _extra.remove(p)
        _extra.insert(0, p)


def modelica_path() -> list[Path]:
    """The folders searched for top-level packages, in order."""
    out = list(_extra)
    for entry in os.environ.get("MODELICAPATH", "").split(os.pathsep):
        if entry.strip():
            p = Path(entry.strip()).expanduser()
            if p.is_dir() and p.resolve() not in out:
                out.append(p.resolve())
    return out


def locate(name: str) -> Path | None:
    """The file or package folder of top-level package ``name`` on the library path."""
    for folder in modelica_path():
        hit = _in_folder(folder, name)
        if hit is not None:
            return hit
    return None


def _in_folder(folder: Path, name: str) -> Path | None:
    d = folder / name
    if (d / "package.mo").is_file():
        return d
    f = folder / f"{name}.mo"
    if f.is_file():
        return f
    try:
        versioned = sorted(e for e in os.listdir(folder) if e.startswith(name + " "))
    except OSError:
        return None
    for entry in reversed(versioned):                 # the highest version first
        m = _VERSIONED.match(entry)
        if m and m.group("name") == name and (folder / entry / "package.mo").is_file():
            return folder / entry
    return None


def top_package(name: str) -> Any:
    """The :class:`~bgmodelica.modelica.scope.ClassScope` of top-level package ``name`` found
    on the library path, or None."""
    key = (name, tuple(str(p) for p in modelica_path()))
    if key in _tops:
        return _tops[key]
    where = locate(name)
    scope = None if where is None else _load_top(name, where)
    _tops[key] = scope
    return scope


def _load_top(name: str, where: Path) -> Any:
    from .parser import parse_file
    from .scope import ClassScope, FileScope

    file = where / "package.mo" if where.is_dir() else where
    stored = parse_file(file)
    cdef = _the_class(stored, name, file)
    if stored.within:
        raise ModelicaError(f"{file}:1:1: within {stored.within}: a top-level package of the "
                            "library path must have an empty within clause")
    if where.is_dir():
        cdef.directory = str(where)
    return ClassScope(cdef, None, FileScope(A.StoredDefinition(str(file), None, [])))


def _the_class(stored: A.StoredDefinition, name: str, file: Path) -> A.ClassDef:
    for c in stored.classes:
        if c.name == name:
            return c
    found = ", ".join(c.name for c in stored.classes) or "nothing"
    raise ModelicaError(f"{file}:1:1: expected the class {name} in this file (it defines "
                        f"{found})")


def child_class(parent: Any, name: str) -> Any:
    """The class ``name`` stored in the package folder of ``parent`` (a ClassScope whose
    ``cdef.directory`` is set), parsed now; None if there is no such file or folder."""
    from .parser import parse_file
    from .scope import ClassScope, FileScope

    folder = Path(parent.cdef.directory)
    sub = folder / name
    if (sub / "package.mo").is_file():
        file, directory = sub / "package.mo", str(sub)
    elif (folder / f"{name}.mo").is_file():
        file, directory = folder / f"{name}.mo", ""
    else:
        return None
    stored = parse_file(file)
    cdef = _the_class(stored, name, file)
    expected = parent.full_name
    if (stored.within or "") != expected:
        raise ModelicaError(f"{file}:1:1: within {stored.within or '(empty)'} names another "
                            f"package than the folder it is stored in ({expected})")
    cdef.directory = directory
    cdef.parent = parent.cdef
    return ClassScope(cdef, parent, FileScope(A.StoredDefinition(str(file), None, [])))


def stored_names(cdef: A.ClassDef) -> list[str]:
    """The names of the classes stored in the package folder of ``cdef`` (files and
    folders), in ``package.order`` order, then the others alphabetically."""
    if not cdef.directory:
        return []
    folder = Path(cdef.directory)
    names: list[str] = []
    try:
        entries = sorted(os.listdir(folder))
    except OSError:
        return []
    for e in entries:
        if e.endswith(".mo") and e != "package.mo":
            names.append(e[:-3])
        elif (folder / e / "package.mo").is_file():
            names.append(e)
    order_file = folder / "package.order"
    if order_file.is_file():
        order = [ln.strip() for ln in order_file.read_text(errors="replace").splitlines()
                 if ln.strip()]
        rank = {n: k for k, n in enumerate(order)}
        names.sort(key=lambda n: (rank.get(n, len(rank)), n))
    return names


def resolve(dotted: str) -> Any:
    """The ClassScope of the fully qualified class ``dotted`` whose top package is on the
    library path, or None."""
    head, _, rest = dotted.partition(".")
    top = top_package(head)
    if top is None:
        return None
    return top.walk(rest.split(".")) if rest else top


def clear() -> None:
    """Forget the loaded packages (the next lookup reads the library path again)."""
    _tops.clear()
