"""Shared pieces of the Modelica builder: error helpers, the evaluation context and
numeric values of evaluated expressions.
"""

from __future__ import annotations

import math
import re
from typing import TYPE_CHECKING, Any

from ...core.component import Component, Element
from ...core.expr import Expr, Leaf, Op
from ...core.variables import (
    KIND_PARAMETER,
    TIME,
)
from .. import ast as A
from .. import scope as S
from ..errors import ModelicaError, internal_text

if TYPE_CHECKING:
    from .env import Env

SELF = "<self>"


_NAME = re.compile(r"^(.*)\[([0-9,]+)\]$")


_RESERVED = {n for n in dir(Component) if not n.startswith("__")} | {"name"}


class NotConstant(Exception):
    """A structural expression (array size, range, parameter-only condition) uses a value that
    is not known when the model is built."""

    def __init__(self, what: str) -> None:
        super().__init__(what)
        self.what = what


class _Disabled(Exception):
    """A reference to a conditional component that is switched off."""


def _where(lex: S.ClassScope | None, pos: A.Pos) -> str:
    if lex is None:
        return "<modifier>"
    return f"{lex.cdef.file or lex.file.file}:{pos[0]}:{pos[1]}"


#: the most elements an array (a declaration, fill()/zeros()/ones(), a range) may have: the
#: builder makes a Python object per element, so a larger array would exhaust time and memory
#: before any message; it is refused when its size is known, before anything is allocated
MAX_ARRAY_ELEMENTS = 10**6


def check_array_size(count: int, lex: S.ClassScope | None, node: Any, what: str) -> None:
    """Refuse an array of more than :data:`MAX_ARRAY_ELEMENTS` elements."""
    if count > MAX_ARRAY_ELEMENTS:
        raise fail(lex, node, f"array too large: {what} would have {count:,} elements (the "
                   f"limit is {MAX_ARRAY_ELEMENTS:,})")


#: exceptions of Python, CasADi or the builder itself that a construct the builder does not
#: handle can raise; where the construct is known they become a :class:`ModelicaError` with
#: its position (a traceback is never the answer to a Modelica text)
INTERNAL_ERRORS = (RecursionError, KeyError, IndexError, TypeError, ValueError,
                   AttributeError, ZeroDivisionError, OverflowError, RuntimeError)


def describe_internal(err: BaseException) -> str:
    """One line for an internal exception: what failed, in the builder's words."""
    if isinstance(err, NotConstant):
        return f"a value is not known when the model is built: {err.what}"
    return internal_text(err)


def fail(lex: S.ClassScope | None, node: Any, message: str) -> ModelicaError:
    pos = getattr(node, "pos", None)
    if pos is None:
        pos = node if isinstance(node, tuple) and len(node) == 2 else (0, 0)
    return ModelicaError(f"{_where(lex, pos)}: {message}")


class TimeVarying(ModelicaError):
    """A construct of a function body that needs values known when the model is built got
    time-varying ones (a while-loop condition, an external function's arguments...); inside
    a when-clause the call then runs on numbers at events (:mod:`.runtime`)."""


def varying(lex: S.ClassScope | None, node: Any, message: str) -> TimeVarying:
    """:class:`TimeVarying` at ``node``'s position (as :func:`fail`)."""
    err = fail(lex, node, message)
    return TimeVarying(str(err))


class Ctx:
    """Evaluation context: the instance environment (or None for static values), the lexical
    class scope, loop variables, and whether values must be known numbers."""

    __slots__ = ("env", "lex", "loops", "numeric")

    def __init__(self, env: Env | None, lex: S.ClassScope | None, loops: dict,
                 numeric: bool) -> None:
        self.env = env
        self.lex = lex
        self.loops = loops
        self.numeric = numeric


_NUM_OPS = {
    "+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b,
    "/": lambda a, b: a / b, "**": lambda a, b: a ** b, "<": lambda a, b: a < b,
    "<=": lambda a, b: a <= b, "!=": lambda a, b: a != b, "==": lambda a, b: a == b,
    "and": lambda a, b: bool(a) and bool(b), "or": lambda a, b: bool(a) or bool(b),
    "neg": lambda a: -a, "not": lambda a: not a, "noEvent": lambda a: a,
    "fabs": abs, "sign": lambda a: (a > 0) - (a < 0), "floor": math.floor, "ceil": math.ceil,
    "atan2": math.atan2, "fmin": min, "fmax": max,
    "if_else": lambda c, a, b: a if c else b,
    **{n: getattr(math, n) for n in ("sin", "cos", "tan", "exp", "log", "sqrt", "asin", "acos",
                                     "atan", "sinh", "cosh", "tanh")},
}


def numeric_value(v: Any, lex: Any = None, node: Any = None, _memo: dict | None = None) -> Any:
    """``v`` with parameters replaced by their values (raises :class:`NotConstant` if it
    depends on variables or time). Shared subexpressions are evaluated once."""
    if isinstance(v, (bool, int, float, str, S.EnumValue)):
        return v
    if isinstance(v, list):
        if _memo is None:
            _memo = {}
        return [numeric_value(x, lex, node, _memo) for x in v]
    if isinstance(v, Op):
        if _memo is None:
            _memo = {}
        hit = _memo.get(id(v))
        if hit is not None:
            return hit[1]
        args = [numeric_value(a, lex, node, _memo) for a in v.args]
        fn = _NUM_OPS.get(v.op)
        if fn is None:
            raise NotConstant(f"operation {v.op}")
        out = fn(*args)
        _memo[id(v)] = (v, out)
        return out
    if isinstance(v, Leaf):
        sym = v.sym
        if sym is TIME:
            if _memo is not None and "time" in _memo:
                return _memo["time"]
            raise NotConstant("time")
        decl = getattr(sym, "decl", None)
        if decl is not None and decl.kind != KIND_PARAMETER and _memo is not None \
                and _memo.get("fixed starts") and getattr(decl, "fixed", False) \
                and isinstance(getattr(decl, "start", None), (int, float)):
            return decl.start         # at initialization a fixed variable is its start value
        if decl is None or decl.kind != KIND_PARAMETER:
            raise NotConstant(f"{getattr(sym, 'name', sym)} is not a parameter")
        owner = getattr(sym, "owner", None)
        env = owner.__dict__.get("_mo_env") if owner is not None else None
        if env is not None:
            if sym.name in env.view.elements:
                return env.numeric(sym.name)
            m = _NAME.match(sym.name)
            if m is not None and m.group(1) in env.view.elements:
                whole = env.numeric(m.group(1))
                for i in (int(x) for x in m.group(2).split(",")):
                    whole = whole[i - 1] if isinstance(whole, list) else whole
                return whole
        return numeric_value(decl.value, lex, node)
    if isinstance(v, Op):
        args = [numeric_value(a, lex, node) for a in v.args]
        fn = _NUM_OPS.get(v.op)
        if fn is None:
            raise NotConstant(f"operation {v.op}")
        return fn(*args)
    if isinstance(v, Element):
        raise NotConstant(f"component {v.name}")
    if not isinstance(v, Expr) and getattr(v, "external_object", False):
        return v                    # a table or other ExternalObject made when built
    raise NotConstant(repr(v))


def _is_number(v: Any) -> bool:
    return isinstance(v, (bool, int, float)) and not isinstance(v, Expr)
