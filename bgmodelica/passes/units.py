"""Dimensional analysis of every equation, on the expression trees as the user wrote them.

Each declared scalar has the unit of its declaration (parsed with pint through
:mod:`bgmodelica.core.units`); ``""`` means *not declared*: such a symbol adapts to whatever
it meets, like a literal. The rules:

- ``a + b``, ``a - b``, ``a == b`` (an equation), relations, ``fmin``/``fmax``, ``atan2(y, x)``
  and the two branches of ``if_else`` need the same unit (same dimensions *and* scale: values
  are not converted, so ``km`` and ``m`` do not mix). A literal number takes the unit its
  context needs, as in Modelica tools: in a sum the unit of the other terms (``v == 0``,
  ``x + 1``); in a product or quotient it is a free factor, so the product adapts too
  (``sin(3.0*time)``, ``exp(-time/5)``, ``2*v == i``). Products without literals stay checked.
- ``*``, ``/`` multiply units; ``x**p`` with a literal ``p`` raises them to ``p``, ``sqrt``
  halves them; ``der(x)`` is ``unit(x)/s``; ``time`` is in s.
- ``sin, cos, tan, exp, log, asin, acos, atan, sinh, cosh, tanh`` need a dimensionless
  argument (``rad`` is 1) and return 1; so do ``and``, ``or``, ``not``; relations and ``sign``
  return 1. Boolean and Integer variables are dimensionless.
- Hybrid parts: relations compare equal units, ``reinit(x, v)`` needs ``v`` in the unit of
  ``x``, a when-assignment ``d == expr`` is an equation, ``sample(start, interval)`` is in s.
- Parameters bound to expressions, connected Input/Output signals and initial equations
  must agree with their declared units.

The check reads :class:`~bgmodelica.core.flatmodel.EquationSources`, which flattening fills
with the equations grouped by *shape*: within a group the verdict depends only on the units
of the leaves, so it is computed once per shape and tuple of leaf units (a 10,000-section RC
ladder has a handful of them). An array equation lowered as a block is checked once, on the
equation of its first elements, when each of its arrays holds one unit (element by element
otherwise).
"""

from __future__ import annotations

import warnings
from collections import Counter
from collections.abc import Callable
from typing import Any

import numpy as np

from ..core.array_marks import has_one_unit
from ..core.arrays import ArrayEquation, ArrayExpr, array_text
from ..core.expr import Equation, Expr, Leaf, Number, Op, to_text
from ..core.flatmodel import EquationSources, FlatModel
from ..core.hybrid import Reinit, RuntimeCall, SampleClock
from ..core.units import SECOND, UnitParseError, parse
from ..core.variables import (
    Boolean,
    Discrete,
    Flow,
    Input,
    Integer,
    Output,
    Parameter,
    Potential,
    Variable,
)
from ..errors import UnitError
from .unit_values import (
    DIMLESS,
    FREE,
    LIT,
    Adaptive,
    Known,
    Mismatch,
    combine,
    der_text,
    dimensionless,
    div,
    mul,
    power,
)

MODES = ("error", "warn", "off")


class UnitWarning(UserWarning):
    """A unit mismatch reported with ``units="warn"``."""


def check_units(flat: FlatModel, mode: str = "error") -> list[str]:
    """Check the units of every equation of ``flat`` (as flattened: ``flat.sources``).

    mode: ``"error"`` raises :class:`~bgmodelica.errors.UnitError` at the first mismatch,
    ``"warn"`` issues a :class:`UnitWarning` per mismatch, ``"off"`` checks nothing.
    Returns the messages of all mismatches (``"warn"``) or ``[]``.
    """
    if mode not in MODES:
        raise ValueError(f"units must be one of {', '.join(map(repr, MODES))}, got {mode!r}")
    if mode == "off" or flat.sources is None:
        return []
    return check_sources(flat.sources, mode)


def check_equations(equations: list[Any], where: str, mode: str = "error") -> list[str]:
    """:func:`check_units` of equations written at ``where`` (array equations lowered as
    blocks, and scalar equations), without a flat model."""
    if mode not in MODES:
        raise ValueError(f"units must be one of {', '.join(map(repr, MODES))}, got {mode!r}")
    if mode == "off":
        return []
    arrays = [(eq, where) for eq in equations if isinstance(eq, ArrayEquation)]
    scalars = [eq for eq in equations if not isinstance(eq, ArrayEquation)]
    return check_sources(EquationSources(groups=_scalar_groups(scalars, where), arrays=arrays),
                         mode)


def check_sources(sources: EquationSources, mode: str) -> list[str]:
    """:func:`check_units` of equations as the user wrote them (``mode`` "error" or
    "warn")."""
    problems = _Checker(mode == "error").run(sources)
    for msg in problems:
        warnings.warn(msg, UnitWarning, stacklevel=3)
    return problems


_TRANSCENDENTAL = frozenset(("sin", "cos", "tan", "exp", "log", "asin", "acos", "atan", "sinh",
                             "cosh", "tanh"))
_SAME = frozenset(("neg", "fabs", "noEvent", "floor", "ceil"))
_COMPARE = frozenset(("<", "<=", "!=", "=="))
_LOGIC = frozenset(("and", "or", "not"))


def _is_zero(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and x == 0


def _is_if_else(x: Any) -> bool:
    return isinstance(x, Op) and x.op == "if_else"


# -- the checker ------------------------------------------------------------------------------


class _Checker:
    def __init__(self, stop: bool) -> None:
        self.stop = stop
        self.problems: list[str] = []
        self.values: dict[Any, Any] = {}

    def report(self, msg: str) -> None:
        if self.stop:
            raise UnitError(msg)
        self.problems.append(msg)

    def run(self, src: EquationSources) -> list[str]:
        self._groups(src.groups)
        self._arrays(src.arrays)
        if src.draft is not None:
            self._hybrid(src.draft)
        for name, decl, where in src.bindings:
            self._guard(lambda n=name, d=decl, w=where: f"{w}: parameter {n} = "
                                                        f"{to_text(d.value)}",
                        lambda d=decl: combine(self.value(d.unit, None), self.infer(d.value),
                                                "declared in {0}, bound to a value in {1}"))
        for eq, where in src.initial:
            self._guard(lambda e=eq, w=where: f"{w}: initial equation {to_text(e.lhs)} == "
                                              f"{to_text(e.rhs)}",
                        lambda e=eq: self.equation(e))
        for a, b, where in src.links:
            if isinstance(a, Leaf) and isinstance(b, Leaf):
                self._guard(lambda a=a, b=b, w=where: f"{w}: connect({to_text(a)}, "
                                                       f"{to_text(b)})",
                            lambda a=a, b=b: combine(self.infer(a), self.infer(b),
                                                      "{0} connected to {1}"))
        return self.problems

    def _guard(self, context: Callable[[], str], fn: Callable[[], Any], count: int = 1) -> None:
        """Run ``fn``; report a mismatch with the text ``context()`` (built only then)."""
        try:
            fn()
        except Mismatch as m:
            more = (f" (and {count - 1} more equation{'s' if count > 2 else ''} of the same "
                    "form and units)") if count > 1 else ""
            self.report(f"{context()}: {m}{more}")

    # -- equations grouped by shape
    def _groups(self, groups: dict[Any, list]) -> None:
        key_of = _leaf_key
        for shape, members in groups.items():
            # one key per member: the leaf units (and the constants when one may be an
            # exponent), built column by column to keep the per-equation work in C loops
            cols = [list(map(key_of, col)) for col in zip(*[m[0] for m in members], strict=True)]
            if any(_has_pow(side) for side in shape):
                cols.append([tuple(m[1]) for m in members])
            keys = list(zip(*cols, strict=True)) if cols else [()] * len(members)
            counts = Counter(keys)
            first = dict(zip(reversed(keys), range(len(keys) - 1, -1, -1), strict=True))
            for k, n in counts.items():
                _, _, where, eq = members[first[k]]
                self._guard(lambda w=where, e=eq: f"{w}: {to_text(e.lhs)} == {to_text(e.rhs)}",
                            lambda e=eq: self.equation(e), n)

    def _arrays(self, arrays: list[tuple[Any, ...]]) -> None:
        one_unit: dict[int, tuple[Any, bool]] = {}
        for eq, where, *origins in arrays:
            try:
                first = Equation(_first(eq.lhs, one_unit), _first(eq.rhs, one_unit))
            except _Varies:                  # element by element, each under its origin
                self._groups(_scalar_groups(eq.equations(), (origins or [None])[0] or where))
                continue
            self._guard(lambda w=where, e=eq: f"{w}: {array_text(e.lhs)} == "
                                              f"{array_text(e.rhs)}",
                        lambda e=first: self.equation(e), len(eq))

    def equation(self, eq: Equation) -> Any:
        if _is_zero(eq.rhs) and _is_if_else(eq.lhs):
            return self._residual(eq.lhs)
        lhs, rhs = self.infer(eq.lhs), self.infer(eq.rhs)
        return combine(lhs, rhs, "left side is {0}, right side is {1}")

    def _residual(self, e: Any) -> Any:
        """``0 = if c then r1 else r2`` (an if-equation whose branches are different
        equations): each branch residual is checked on its own."""
        if _is_if_else(e):
            self.infer(e.args[0])
            self._residual(e.args[1])
            self._residual(e.args[2])
            return None
        return self.infer(e)

    # -- hybrid parts
    def _hybrid(self, draft: Any) -> None:
        for slot in draft.relations:
            self._guard(lambda s=slot: f"{s.where}: {to_text(s.a)} {s.op} {to_text(s.b)}",
                        lambda s=slot: combine(self.infer(s.a), self.infer(s.b),
                                                "cannot compare {0} and {1}"))
        for w, here in draft.whens:
            for cond, stmts in w.branches:
                self._guard(lambda h=here, c=cond: f"{h}: when {to_text(c)}",
                            lambda c=cond: self.infer(c))
                for s in stmts:
                    if isinstance(s, RuntimeCall):
                        continue            # numbers at events: no units to check
                    if isinstance(s, Reinit):
                        self._guard(
                            lambda h=here, s=s: f"{h}: reinit({s.target.name}, "
                                                f"{to_text(s.value)})",
                            lambda s=s: combine(self.infer(s.target.leaf), self.infer(s.value),
                                                 f"{s.target.name} is in {{0}}, the new value "
                                                 "in {1}"))
                    else:
                        self._guard(lambda h=here, c=cond, s=s: f"{h}: when {to_text(c)}: "
                                    f"{to_text(s.lhs)} == {to_text(s.rhs)}",
                                    lambda s=s: self.equation(s))
        second = Known("s", SECOND)
        for sym in draft.specials.values():
            if isinstance(sym, SampleClock):
                self._guard(lambda s=sym: f"sample({to_text(s.start)}, {to_text(s.interval)})",
                            lambda s=sym: (
                                combine(second, self.infer(s.start),
                                         "start must be in {0}, got {1}"),
                                combine(second, self.infer(s.interval),
                                         "interval must be in {0}, got {1}")))

    # -- units of expressions
    def value(self, key: Any, sym: Any) -> Any:
        """The unit value of a leaf key (see :func:`_leaf_key`)."""
        out = self.values.get(key)
        if out is not None:
            return out
        if key == "":
            out = FREE
        elif isinstance(key, tuple):              # ("der", n, key of the differentiated)
            base = self.value(key[2], sym)
            out = base if isinstance(base, Adaptive) else Known(
                der_text(base.text, key[1]), base.unit / SECOND ** key[1])
        else:
            try:
                out = Known(key, parse(key))
            except UnitParseError as err:
                name = getattr(sym, "name", "?")
                raise Mismatch(f"{name} is declared in an unknown unit: {err}") from None
        self.values[key] = out
        return out

    def infer(self, e: Any) -> Any:
        """The unit value of expression ``e``; iterative, each shared subexpression once
        (long sums and tables are deeper than Python's recursion limit)."""
        if not _is_op(e):
            return self._atom(e)
        memo: dict[int, Any] = {}
        stack = [(e, False)]
        while stack:
            node, ready = stack.pop()
            if id(node) in memo:
                continue
            if not ready:
                stack.append((node, True))
                stack.extend((a, False) for a in reversed(node.args)
                             if _is_op(a) and id(a) not in memo)
                continue
            values = [memo[id(a)] if _is_op(a) else self._atom(a) for a in node.args]
            memo[id(node)] = self._apply(node, values)
        return memo[id(e)]

    def _atom(self, e: Any) -> Any:
        if isinstance(e, Leaf):
            return self.value(_leaf_key(e.sym), e.sym)
        if isinstance(e, Number) or isinstance(e, bool):
            return LIT
        return FREE                           # CasADi SX inside an equation: not checked

    def _apply(self, e: Any, v: list) -> Any:
        """The unit value of operation ``e`` on its arguments' unit values ``v``."""
        op, args = e.op, e.args
        if op in ("+", "-"):
            a, b = v[0], v[1]
            verb = "add" if op == "+" else "subtract"
            return combine(a, b, f"cannot {verb} {{0}} and {{1}}")
        if op == "*":
            return mul(v[0], v[1])
        if op == "/":
            return div(v[0], v[1])
        if op in _SAME:
            return v[0]
        if op in _TRANSCENDENTAL:
            a = v[0]
            dimensionless(a, f"{op}()")
            return LIT if a is LIT else DIMLESS
        if op == "sqrt":
            return power(v[0], 0.5)
        if op == "**":
            base = v[0]
            if isinstance(args[1], float):
                return power(base, args[1])
            p = v[1]
            dimensionless(p, "an exponent")
            if isinstance(base, Adaptive):
                return base
            dimensionless(base, "a power with a variable exponent")
            return DIMLESS
        if op in _COMPARE:
            combine(v[0], v[1], "cannot compare {0} and {1}")
            return DIMLESS
        if op in _LOGIC:
            for a in v:
                dimensionless(a, f"'{op}'")
            return DIMLESS
        if op == "sign":
            v[0]
            return DIMLESS
        if op == "atan2":
            combine(v[0], v[1],
                     "atan2() needs arguments in one unit, got {0} and {1}")
            return DIMLESS
        if op in ("fmin", "fmax"):
            return combine(v[0], v[1],
                            f"{op}() needs arguments in one unit, got {{0}} and {{1}}")
        if op == "if_else":
            dimensionless(v[0], "an if_else condition")
            return combine(v[1], v[2],
                            "if_else branches differ: {0} and {1}")
        return FREE                           # an operation this check does not know




def _is_op(e: Any) -> bool:
    return isinstance(e, Expr) and not isinstance(e, Leaf)


def _leaf_key(sym: Any) -> Any:
    """What the unit of a leaf depends on: its unit string, ``("der", n, key)`` for the n-th
    derivative of a variable, ``"1"`` for Boolean/Integer, ``"s"`` for time."""
    decl = sym.decl
    if type(decl) in _PLAIN and sym.der_of is None and sym.pre_of is None:
        return decl.unit
    return _other_key(sym)


_PLAIN = frozenset((Parameter, Variable, Potential, Flow, Input, Output, Discrete))


def _other_key(sym: Any) -> Any:
    decl = sym.decl
    if decl is None:                          # time
        return "s"
    if sym.der_of is not None:
        n = 0
        while sym.der_of is not None:
            sym, n = sym.der_of, n + 1
        return ("der", n, _leaf_key(sym))
    if sym.pre_of is not None:
        return _leaf_key(sym.pre_of)
    if isinstance(decl, Boolean):
        return "1"
    if isinstance(decl, Integer):
        return decl.unit or "1"
    return decl.unit


class _Varies(Exception):
    """An array of an array equation holds leaves of different units."""


def _first(x: Any, one_unit: dict[int, tuple[Any, bool]]) -> Any:
    """The first element of an array expression whose arrays each hold one unit (raises
    :class:`_Varies` otherwise), for checking all elements at once. ``one_unit`` remembers
    per declared array (the numpy base of the slices) whether all its elements share one
    unit: then every slice of it does."""
    if isinstance(x, ArrayExpr):
        if x.node is None:
            items = x.items
            base = items.base if isinstance(items.base, np.ndarray) else items
            if id(base) not in one_unit:
                one_unit[id(base)] = (base, has_one_unit(base) or _single_unit(base))
            if not (one_unit[id(base)][1] or _single_unit(items)):
                raise _Varies
            return items.flat[0]
        op, args = x.node
        if op == "**" and isinstance(args[1], np.ndarray) and np.unique(args[1]).size > 1:
            raise _Varies
        return Op(op, tuple(_first(a, one_unit) for a in args))
    if isinstance(x, np.ndarray):
        return float(x.ravel()[0])
    return x


def _single_unit(leaves: np.ndarray) -> bool:
    """Whether an array of leaves has one unit key (:func:`_leaf_key`); False otherwise."""
    try:
        return len({_leaf_key(leaf.sym) for leaf in leaves.flat}) <= 1
    except AttributeError:
        return False


def _scalar_groups(equations: list[Equation], where: str | list[str]) -> dict[Any, list]:
    """Scalar equations grouped by shape, as flattening groups them (``where``: their
    origin, or the origin of each)."""
    from ..core.expr import shape_of

    out: dict[Any, list] = {}
    wheres = [where] * len(equations) if isinstance(where, str) else where
    for eq, where in zip(equations, wheres, strict=True):
        leaves: list = []
        consts: list = []
        shape = []
        for side in (eq.lhs, eq.rhs):
            if isinstance(side, Expr):
                shape.append(shape_of(side, leaves, consts))
            else:
                consts.append(float(side))
                shape.append("C")
        out.setdefault(tuple(shape), []).append((leaves, consts, where, eq))
    return out


def _has_pow(shape: Any) -> bool:
    if isinstance(shape, tuple):
        return shape[0] == "**" or any(_has_pow(a) for a in shape[1:])
    return False
