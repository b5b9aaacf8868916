"""The syntax tree of the Modelica subset (what :mod:`.parser` produces from lark's tree).

Every node records ``pos = (line, column)`` of its first token; the file name lives on the
:class:`StoredDefinition` and on each :class:`ClassDef` (``file``), so messages can say
``file.mo:12:5``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

Pos = tuple[int, int]


# -- expressions ---------------------------------------------------------------------------------


@dataclass(slots=True)
class Num:
    value: int | float
    pos: Pos = (0, 0)


@dataclass(slots=True)
class Str:
    value: str
    pos: Pos = (0, 0)


@dataclass(slots=True)
class Bool:
    value: bool
    pos: Pos = (0, 0)


@dataclass(slots=True)
class Ref:
    """A component reference ``a[i].b.c``: ``parts`` is a tuple of ``(name, subscripts)``
    with ``subscripts`` None or a tuple of expressions (:class:`Colon` for ``:``)."""

    parts: tuple[tuple[str, tuple | None], ...]
    pos: Pos = (0, 0)
    global_: bool = False

    @property
    def dotted(self) -> str:
        return ".".join(n for n, _ in self.parts)

    def text(self) -> str:
        return ".".join(n + ("[...]" if s else "") for n, s in self.parts)


@dataclass(slots=True)
class Colon:
    pos: Pos = (0, 0)


@dataclass(slots=True)
class Call:
    """``f(args, name=value)``; ``iterator`` is ``(expr, indices)`` for ``f(e for i in r)``."""

    func: Ref
    args: tuple
    kwargs: dict[str, Any]
    pos: Pos = (0, 0)
    iterator: tuple | None = None


@dataclass(slots=True)
class BinOp:
    op: str          # + - * / ^ .+ .- .* ./ .^ and or < <= > >= == <>
    a: Any
    b: Any
    pos: Pos = (0, 0)


@dataclass(slots=True)
class Unary:
    op: str          # - + not
    a: Any
    pos: Pos = (0, 0)


@dataclass(slots=True)
class IfExpr:
    branches: tuple[tuple[Any, Any], ...]
    otherwise: Any
    pos: Pos = (0, 0)


@dataclass(slots=True)
class Range:
    start: Any
    step: Any | None
    stop: Any
    pos: Pos = (0, 0)


@dataclass(slots=True)
class ArrayLit:
    items: tuple
    pos: Pos = (0, 0)


@dataclass(slots=True)
class ArrayComp:
    expr: Any
    indices: tuple[tuple[str, Any], ...]
    pos: Pos = (0, 0)


@dataclass(slots=True)
class PartialFunction:
    """``function f(a=1)`` passed as a call argument: ``f`` with some inputs bound."""

    func: str
    kwargs: dict[str, Any]
    pos: Pos = (0, 0)


@dataclass(slots=True)
class Matrix:
    rows: tuple[tuple, ...]
    pos: Pos = (0, 0)


# -- modifications -------------------------------------------------------------------------------


@dataclass(slots=True)
class Modification:
    """``(args) = binding``; ``args``: :class:`ElementMod` / :class:`Redeclare` entries."""

    args: tuple = ()
    binding: Any = None
    pos: Pos = (0, 0)


@dataclass(slots=True)
class ElementMod:
    name: str                  # dotted: "v", "p.v", "transformation"
    mod: Modification | None
    each: bool = False
    final: bool = False
    pos: Pos = (0, 0)


@dataclass(slots=True)
class Redeclare:
    element: Any               # Component or ClassDef (short)
    each: bool = False
    pos: Pos = (0, 0)


# -- equations -----------------------------------------------------------------------------------


@dataclass(slots=True)
class EqSimple:
    lhs: Any
    rhs: Any
    pos: Pos = (0, 0)


@dataclass(slots=True)
class EqCall:
    call: Call
    pos: Pos = (0, 0)


@dataclass(slots=True)
class EqIf:
    branches: tuple[tuple[Any, tuple], ...]
    otherwise: tuple
    pos: Pos = (0, 0)


@dataclass(slots=True)
class EqFor:
    indices: tuple[tuple[str, Any], ...]
    body: tuple
    pos: Pos = (0, 0)


@dataclass(slots=True)
class EqWhen:
    branches: tuple[tuple[Any, tuple], ...]
    pos: Pos = (0, 0)


@dataclass(slots=True)
class TupleExpr:
    """The left side ``(a, , b)`` of a tuple equation or assignment (None for an omitted
    output)."""

    items: tuple
    pos: Pos = (0, 0)


# -- algorithms ----------------------------------------------------------------------------------


class Statements(tuple):
    """The statements of one algorithm section (a tuple); ``pos`` is the section's keyword."""

    pos: Pos

    def __new__(cls, items=(), pos: Pos = (0, 0)) -> Statements:
        self = super().__new__(cls, items)
        self.pos = pos
        return self

    def __reduce__(self):
        return (Statements, (tuple(self), self.pos))


@dataclass(slots=True)
class Assign:
    """``target := value``; ``target`` a :class:`Ref` or a :class:`TupleExpr` of them."""

    target: Any
    value: Any
    pos: Pos = (0, 0)


@dataclass(slots=True)
class StmtCall:
    """A call statement: ``assert(...)``, ``terminate(...)``, ``reinit(...)``, ``f(...)``."""

    call: Call
    pos: Pos = (0, 0)


@dataclass(slots=True)
class StmtIf:
    branches: tuple[tuple[Any, tuple], ...]     # (condition, statements)
    otherwise: tuple
    pos: Pos = (0, 0)


@dataclass(slots=True)
class StmtFor:
    indices: tuple[tuple[str, Any], ...]        # (name, range expression or None)
    body: tuple
    pos: Pos = (0, 0)


@dataclass(slots=True)
class StmtWhile:
    condition: Any
    body: tuple
    pos: Pos = (0, 0)


@dataclass(slots=True)
class StmtWhen:
    branches: tuple[tuple[Any, tuple], ...]     # (condition, statements); elsewhen follow
    pos: Pos = (0, 0)


@dataclass(slots=True)
class Return:
    pos: Pos = (0, 0)


@dataclass(slots=True)
class Break:
    pos: Pos = (0, 0)


@dataclass(slots=True)
class External:
    """``external "C" out = fname(args) annotation(...)``; ``function`` None when the clause
    names no call (the default: the Modelica name, inputs then outputs)."""

    language: str = "C"
    output: Any = None                          # Ref or None
    function: str | None = None
    args: tuple = ()
    annotation: Modification | None = None
    pos: Pos = (0, 0)


# -- declarations --------------------------------------------------------------------------------


@dataclass(slots=True)
class Component:
    """One declared component ``prefixes Type name[dims](mod) = binding if cond "desc"``."""

    name: str
    type_name: str
    prefixes: frozenset[str]
    dims: tuple                # type dims then declaration dims
    mod: Modification | None
    condition: Any = None
    description: str = ""
    annotation: Modification | None = None
    pos: Pos = (0, 0)
    element_prefixes: frozenset[str] = frozenset()
    constrainedby: str | None = None


@dataclass(slots=True)
class Extends:
    type_name: str
    mod: Modification | None
    pos: Pos = (0, 0)


@dataclass(slots=True)
class Import:
    alias: str | None          # import A = B.C  -> alias "A"
    name: str                  # "B.C"
    wildcard: bool = False     # import B.C.*
    pos: Pos = (0, 0)


@dataclass(slots=True)
class Unsupported:
    """A construct the builder refuses, with its position (see ``builder.classes.refused``)."""

    what: str
    pos: Pos = (0, 0)


@dataclass(slots=True, eq=False)
class ClassDef:
    name: str
    kind: str                  # model block connector expandable record type package function class
    pos: Pos = (0, 0)
    partial: bool = False
    description: str = ""
    elements: list = field(default_factory=list)      # Component / Extends / Import / ClassDef
    equations: list = field(default_factory=list)
    initial_equations: list = field(default_factory=list)
    annotation: Modification | None = None
    unsupported: list = field(default_factory=list)    # Unsupported entries
    # short class  ``type T = prefix Base[dims](mod)``
    short: tuple | None = None    # (base_prefix, type_name, dims, Modification|None)
    enum: tuple | None = None     # enumeration literals
    parent: ClassDef | None = None
    file: str = ""
    element_prefixes: frozenset[str] = frozenset()
    algorithms: list = field(default_factory=list)          # one tuple of statements a section
    initial_algorithms: list = field(default_factory=list)
    external: External | None = None
    purity: str = ""              # "pure" / "impure" / ""
    encapsulated: bool = False
    protected: frozenset[str] = frozenset()   # names of the elements declared protected
    directory: str = ""           # a package stored as a folder: its path (library loading)
    # ``redeclare model extends B(mod)``: the modification of the inherited ``B`` (an empty
    # Modification when none); None for an ordinary class
    class_extends: Modification | None = None

    @property
    def full_name(self) -> str:
        parts = []
        c: ClassDef | None = self
        while c is not None and c.kind != "<file>":
            parts.append(c.name)
            c = c.parent
        return ".".join(reversed(parts))

    def __repr__(self) -> str:
        return f"ClassDef({self.kind} {self.full_name})"


@dataclass(slots=True)
class StoredDefinition:
    file: str
    within: str | None
    classes: list[ClassDef]
