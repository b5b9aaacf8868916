"""Disk cache of parsed Modelica files: a file parsed once (by any process) is a load after.

An entry is a pickle of the :class:`~.ast.StoredDefinition` and of the list of its
:class:`~.ast.ClassDef` nodes, under ``$BGMODELICA_CACHE/modelica-ast/`` (see
:func:`bgmodelica.cache.default_dir`). Its key is a digest of the file's bytes and of the
parser's own source (grammar, rules, syntax tree), so an edited file or parser never meets a
stale entry. Positions in the tree are ``(line, column)`` only; the file name is set again on
load to the path the file was read from this time. Entries are written atomically (temporary
file, then rename); an unreadable entry is ignored (and rewritten), and a folder that cannot
be written simply leaves the cache unused.
"""

from __future__ import annotations

import gc
import hashlib
import os
import pickle
import tempfile
from contextlib import contextmanager
from functools import lru_cache
from pathlib import Path

from . import ast as A

FORMAT = 1
_SOURCES = ("grammar.lark", "parser.py", "parse_values.py", "expression_rules.py",
            "statement_rules.py", "ast.py", "ast_cache.py")


@lru_cache(maxsize=1)
def parser_version() -> str:
    """A digest of the parser's source files (a new parser never reads old entries)."""
    h = hashlib.sha256(str(FORMAT).encode())
    here = Path(__file__).parent
    for name in _SOURCES:
        h.update(name.encode() + b"\0" + (here / name).read_bytes())
    return h.hexdigest()


@contextmanager
def paused_gc():
    """Pause the cyclic garbage collector while a syntax tree is built or loaded: its millions
    of small objects would otherwise trigger full collections again and again (loading the
    whole MSL took 5x longer)."""
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.enable()


def folder() -> Path:
    """``$BGMODELICA_CACHE/modelica-ast`` (default ``~/.cache/bgmodelica/modelica-ast``)."""
    from ..cache import default_dir
    return default_dir() / "modelica-ast"


def entry_path(data: bytes) -> Path:
    """Where the parse of a file whose content is ``data`` is stored."""
    key = hashlib.sha256(parser_version().encode() + b"\0" + data).hexdigest()
    return folder() / key[:2] / f"{key}.pickle"


def load(data: bytes, file: str) -> A.StoredDefinition | None:
    """The cached parse of ``data`` with its file names set to ``file``, or None."""
    try:
        with open(entry_path(data), "rb") as fh, paused_gc():
            tree, classes = pickle.load(fh)
    except Exception:                     # missing, truncated, corrupt or from elsewhere
        return None
    if not isinstance(tree, A.StoredDefinition):
        return None
    tree.file = file
    for cdef in classes:
        cdef.file = file
    return tree


def store(data: bytes, tree: A.StoredDefinition, classes: list[A.ClassDef]) -> None:
    """Store the parse of ``data`` (silently nothing when the folder cannot be written)."""
    path = entry_path(data)
    tmp = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=".tmp-", dir=path.parent)
        with os.fdopen(fd, "wb") as fh:
            pickle.dump((tree, classes), fh, protocol=pickle.HIGHEST_PROTOCOL)
        os.replace(tmp, path)
        tmp = None
    except (OSError, pickle.PicklingError, RecursionError):
        pass
    finally:
        if tmp is not None:
            try:
                os.unlink(tmp)
            except OSError:
                pass
