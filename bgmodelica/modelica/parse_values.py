"""Values the parser's rules pass between them: tagged tuples and names that carry a source
position (told apart from plain tuples and strings by their type)."""

from __future__ import annotations

from . import ast as A


class ClassMod(tuple):
    """The argument list of a class modification (distinguished from other tuples); ``pos``
    is its opening parenthesis."""

    pos: A.Pos


class Section(tuple):
    """``(kind, items)`` of a composition."""


class Prefixes(tuple):
    """``(partial, purity, kind)`` of a class definition; ``pos`` its first keyword."""

    pos: A.Pos


class Name(str):
    """A dotted name with the position ``pos`` of its first identifier."""

    pos: A.Pos
