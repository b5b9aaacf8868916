"""Name lookup in Modelica class scopes: nested classes, imports, package constants, the
predefined types and the Modelica Standard Library subset (:mod:`.msl`).

A :class:`ClassScope` is a class definition placed in its enclosing classes (lexical scope).
Type and constant names are looked up from the innermost class outwards, then among the
file's top-level classes, then among the predefined names (``Real``, ``StateSelect``,
``Modelica``...).
"""

from __future__ import annotations

from typing import Any

from . import ast as A
from .errors import ModelicaError

#: the predefined types
BUILTIN_TYPES = ("Real", "Integer", "Boolean", "String")


class Builtin:
    """A predefined type (Real, Integer, Boolean, String) or enumeration (StateSelect)."""

    def __init__(self, name: str, literals: tuple[str, ...] = ()) -> None:
        self.name = name
        self.literals = literals

    def __repr__(self) -> str:
        return f"Builtin({self.name})"


BUILTINS: dict[str, Builtin] = {n: Builtin(n) for n in BUILTIN_TYPES}
BUILTINS["StateSelect"] = Builtin("StateSelect", ("never", "avoid", "default", "prefer",
                                                   "always"))


class EnumValue:
    """A literal of an enumeration type; its numeric value is its 1-based index."""

    __slots__ = ("type_name", "literal", "index")

    def __init__(self, type_name: str, literal: str, index: int) -> None:
        self.type_name = type_name
        self.literal = literal
        self.index = index

    def __repr__(self) -> str:
        return f"{self.type_name}.{self.literal}"

    def __eq__(self, other: Any) -> bool:
        if isinstance(other, EnumValue):
            return self.type_name.rpartition(".")[2] == other.type_name.rpartition(".")[2] \
                and self.literal == other.literal
        return NotImplemented

    def __hash__(self) -> int:
        return hash(self.literal)


class MslNamespace:
    """A package path of the Modelica Standard Library subset (``Modelica.Electrical``)."""

    def __init__(self, path: str) -> None:
        self.path = path

    def __repr__(self) -> str:
        return f"MslNamespace({self.path})"


class MslClass:
    """A Modelica Standard Library class that maps onto a class of ``library/``."""

    def __init__(self, path: str, entry: Any) -> None:
        self.path = path
        self.entry = entry

    def __repr__(self) -> str:
        return f"MslClass({self.path})"


class ConstRef:
    """A constant (or parameter) declared in a package or class, read through its scope."""

    def __init__(self, scope: ClassScope, name: str) -> None:
        self.scope = scope
        self.name = name


class FileScope:
    """The top-level classes of one stored definition (a file or the MSL stub)."""

    def __init__(self, stored: A.StoredDefinition, fallback: FileScope | None = None,
                 msl: bool = False) -> None:
        self.stored = stored
        self.file = stored.file
        self.classes: dict[str, ClassScope] = {}
        self.fallback = fallback
        self.msl = msl
        within = stored.within or ""
        for c in stored.classes:
            self.classes[c.name] = ClassScope(c, None, self)
        self.within = within

    def find_full(self, dotted: str) -> Any:
        """Resolve a fully qualified name from the top (with or without the within prefix)."""
        parts = dotted.split(".")
        if self.within and dotted.startswith(self.within + "."):
            rest = dotted[len(self.within) + 1:].split(".")
            if rest[0] in self.classes:
                parts = rest
        head = self.classes.get(parts[0])
        if head is None:
            return None
        return head.walk(parts[1:])


class ClassScope:
    """A class definition in its lexical context."""

    __slots__ = ("cdef", "parent", "file", "_classes", "_consts", "_imports", "_cache",
                 "__weakref__", "_view", "_static")

    def __init__(self, cdef: A.ClassDef, parent: ClassScope | None, file: FileScope) -> None:
        self.cdef = cdef
        self.parent = parent
        self.file = file
        self._classes: dict[str, A.ClassDef] = {}
        self._consts: set[str] = set()
        self._imports: list[A.Import] = []
        self._cache: dict[str, Any] = {}
        self._view = None
        self._static = None
        for el in cdef.elements:
            if isinstance(el, A.ClassDef):
                self._classes[el.name] = el
            elif isinstance(el, A.Component) and "constant" in el.prefixes:
                self._consts.add(el.name)
            elif isinstance(el, A.Import):
                self._imports.append(el)

    @property
    def name(self) -> str:
        return self.cdef.name

    @property
    def full_name(self) -> str:
        parts = []
        s: ClassScope | None = self
        while s is not None:
            parts.append(s.cdef.name)
            s = s.parent
        if self.file.within:
            parts.append(self.file.within)
        return ".".join(reversed(parts))

    def nested(self, name: str) -> ClassScope | None:
        """The class ``name`` defined directly in this class (or inherited through a local
        ``extends`` of a package)."""
        hit = self._cache.get(name)
        if hit is not None:
            return hit
        cdef = self._classes.get(name)
        if cdef is None:
            if not self.cdef.directory:
                return None
            from .library_path import child_class
            scope = child_class(self, name)
            if scope is not None:
                self._cache[name] = scope
            return scope
        scope = ClassScope(cdef, self, self.file)
        self._cache[name] = scope
        return scope

    def walk(self, parts: list[str]) -> Any:
        """Resolve ``parts`` inside this class: nested classes, then a constant, then
        enumeration literals."""
        cur: Any = self
        for k, part in enumerate(parts):
            if isinstance(cur, ClassScope):
                nxt = cur.nested(part)
                if nxt is None and part in cur._consts:
                    if k != len(parts) - 1:
                        return None
                    return ConstRef(cur, part)
                if nxt is None and cur.cdef.enum is not None and part in cur.cdef.enum:
                    if k != len(parts) - 1:
                        return None
                    return EnumValue(cur.full_name, part, cur.cdef.enum.index(part) + 1)
                if nxt is None:
                    return None
                cur = nxt
            else:
                return None
        return cur

    def position(self, pos: A.Pos) -> str:
        return f"{self.cdef.file or self.file.file}:{pos[0]}:{pos[1]}"


def lookup(scope: ClassScope | None, name: str, file: FileScope | None = None) -> Any:
    """Look ``name`` (one identifier) up from ``scope`` outwards: nested classes, constants,
    imports, then the file's classes and the predefined names. None if not found."""
    s = scope
    if file is None and scope is not None:
        file = scope.file
    while s is not None:
        hit = s.nested(name)
        if hit is not None:
            return hit
        if name in s._consts:
            return ConstRef(s, name)
        if s.cdef.enum is not None and name in s.cdef.enum:
            return None
        for imp in s._imports:
            got = _import(s, imp, name)
            if got is not None:
                return got
        s = s.parent
    if file is not None:
        return lookup_top(file, name)
    return None


def lookup_top(file: FileScope, name: str) -> Any:
    hit = file.classes.get(name)
    if hit is not None:
        return hit
    if file.fallback is not None:
        hit = file.fallback.classes.get(name)
        if hit is not None:
            return hit
    if name in BUILTINS:
        return BUILTINS[name]
    from .library_path import top_package
    hit = top_package(name)
    if hit is not None:
        return hit
    if name == "Modelica":
        from . import msl
        return msl.resolve("Modelica")
    return None


def resolve_path(file: FileScope, dotted: str) -> Any:
    """A fully qualified name (``Modelica.Units.SI.Voltage``, ``P.Q.Model``)."""
    parts = dotted.split(".")
    head = lookup_top(file, parts[0])
    if head is None and file.within:
        head = file.find_full(dotted)
        return head
    return walk(head, parts[1:])


def walk(cur: Any, parts: list[str]) -> Any:
    """Continue a lookup through the remaining ``parts`` of a dotted name."""
    if not parts:
        return cur
    if isinstance(cur, ClassScope):
        return cur.walk(parts)
    if isinstance(cur, MslNamespace):
        from . import msl
        return msl.resolve(cur.path + "." + ".".join(parts))
    if isinstance(cur, Builtin) and cur.literals and len(parts) == 1 and parts[0] in cur.literals:
        return EnumValue(cur.name, parts[0], cur.literals.index(parts[0]) + 1)
    return None


def _import(scope: ClassScope, imp: A.Import, name: str) -> Any:
    file = scope.file
    if imp.alias is not None:
        if imp.alias == name:
            return _resolve_import(file, imp, imp.name)
        return None
    if imp.wildcard:
        got = _resolve_import(file, imp, imp.name, quiet=True)
        if got is None:
            return None
        return walk(got, [name])
    if imp.name.rpartition(".")[2] == name:
        return _resolve_import(file, imp, imp.name)
    return None


def _resolve_import(file: FileScope, imp: A.Import, dotted: str, quiet: bool = False) -> Any:
    got = resolve_path(file, dotted)
    if got is None and not quiet:
        raise ModelicaError(f"{file.file}:{imp.pos[0]}:{imp.pos[1]}: import {dotted}: no such "
                            "class or package")
    return got
