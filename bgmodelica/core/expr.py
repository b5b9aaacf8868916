"""A light expression layer for equations, lowered to CasADi SX in vectorized groups.

Component equations are written with plain Python operators on :class:`Expr` trees (about a
microsecond per operation). Flattening groups the equations of identical *shape* (a resistor's
``v == R*i`` is one shape for all resistors) and lowers each group with one CasADi operation
per tree node on stacked vectors, instead of one SWIG call per node per equation.

Expressions interoperate with CasADi: ``casadi.sin(expr)``, ``expr + sx`` and
``casadi.vertcat(expr, ...)`` work (through ``__SX__``) and give SX results, which equations
accept too (lowered one by one).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import casadi as ca
import numpy as np

Number = (int, float, np.integer, np.floating)


class Expr:
    """Base of expression nodes. ``a == b`` builds an :class:`Equation`."""

    __slots__ = ()
    __array_priority__ = 1000          # numpy scalars defer to our operators

    def __add__(self, o): return _binary("+", self, o)
    def __radd__(self, o): return _binary("+", o, self)
    def __sub__(self, o): return _binary("-", self, o)
    def __rsub__(self, o): return _binary("-", o, self)
    def __mul__(self, o): return _binary("*", self, o)
    def __rmul__(self, o): return _binary("*", o, self)
    def __truediv__(self, o): return _binary("/", self, o)
    def __rtruediv__(self, o): return _binary("/", o, self)
    def __pow__(self, o): return _binary("**", self, o)
    def __rpow__(self, o): return _binary("**", o, self)
    def __neg__(self): return Op("neg", (self,))
    def __pos__(self): return self
    def __lt__(self, o): return _binary("<", self, o)
    def __le__(self, o): return _binary("<=", self, o)
    def __gt__(self, o): return _binary("<", o, self)
    def __ge__(self, o): return _binary("<=", o, self)

    def __eq__(self, o):  # type: ignore[override]
        if isinstance(o, (ca.SX, ca.MX)):
            return to_sx(self) == o
        return Equation(self, o)

    def __ne__(self, o):  # type: ignore[override]
        return _binary("!=", self, o)

    def __and__(self, o): return _binary("and", self, o)
    def __rand__(self, o): return _binary("and", o, self)
    def __or__(self, o): return _binary("or", self, o)
    def __ror__(self, o): return _binary("or", o, self)
    def __invert__(self): return Op("not", (self,))

    __hash__ = object.__hash__

    def __bool__(self) -> bool:
        raise TypeError("a symbolic expression has no truth value: use if_else() or when() "
                        "for conditions, '&', '|', '~' instead of 'and', 'or', 'not', eq(a, b) "
                        "to compare, and '==' only to write equations")

    def __SX__(self) -> ca.SX:
        return to_sx(self)

    def __repr__(self) -> str:
        return to_text(self)


class ArrayBase:
    """Base of array expressions (:class:`bgmodelica.core.arrays.ArrayExpr`): math functions
    and ``der`` apply elementwise through :meth:`map`."""

    __slots__ = ()

    def map(self, fun: Callable[[Any], Any]) -> Any:
        raise NotImplementedError


class Leaf(Expr):
    """A declared scalar (variable, parameter, derivative) or ``time``."""

    __slots__ = ("sym",)

    def __init__(self, sym: Any) -> None:
        self.sym = sym


class Op(Expr):
    """An operation; ``args`` are Expr nodes or Python floats."""

    __slots__ = ("op", "args")

    def __init__(self, op: str, args: tuple) -> None:
        self.op = op
        self.args = args


class Equation:
    """``lhs == rhs``; sides are Expr, numbers or CasADi SX."""

    __slots__ = ("lhs", "rhs")

    def __init__(self, lhs: Any, rhs: Any) -> None:
        self.lhs = lhs
        self.rhs = rhs

    def __bool__(self) -> bool:
        raise TypeError("an equation 'a == b' has no truth value; yield it from equations()")

    def __repr__(self) -> str:
        return f"{to_text(self.lhs)} == {to_text(self.rhs)}"


#: relation operators; outside ``no_event`` they become zero-crossing functions
RELATIONS = ("<", "<=")
#: operators whose value is Boolean
BOOLEAN_OPS = ("<", "<=", "!=", "==", "and", "or", "not")
#: number of relation and hybrid nodes ever created (0: no model can contain any)
HYBRID_NODES = [0]


def _binary(op: str, a: Any, b: Any) -> Any:
    if op in BOOLEAN_OPS:
        HYBRID_NODES[0] += 1
    if isinstance(a, (ca.SX, ca.MX)) or isinstance(b, (ca.SX, ca.MX)):
        return _SX_BINARY[op](to_sx(a), to_sx(b))
    if isinstance(a, Number):
        a = float(a)
    elif not isinstance(a, Expr):
        return NotImplemented
    if isinstance(b, Number):
        b = float(b)
    elif not isinstance(b, Expr):
        return NotImplemented
    return Op(op, (a, b))


def _unary(name: str) -> Callable[[Any], Any]:
    sx_fun = getattr(ca, name)
    np_fun = getattr(math, name, None) or getattr(np, name)

    def fun(x: Any) -> Any:
        if isinstance(x, Expr):
            return Op(name, (x,))
        if isinstance(x, ArrayBase):
            return x.map(fun)
        if isinstance(x, Number):
            return float(np_fun(x))
        return sx_fun(x)

    fun.__name__ = name
    fun.__doc__ = f"Elementwise {name} of a number, an expression or a CasADi SX."
    return fun


sin, cos, tan, exp, log, sqrt = (_unary(n) for n in ("sin", "cos", "tan", "exp", "log", "sqrt"))
asin, acos, atan, sinh, cosh, tanh = (_unary(n) for n in
                                      ("asin", "acos", "atan", "sinh", "cosh", "tanh"))


def fabs(x: Any) -> Any:
    """Absolute value."""
    if isinstance(x, Expr):
        return Op("fabs", (x,))
    if isinstance(x, ArrayBase):
        return x.map(fabs)
    return abs(float(x)) if isinstance(x, Number) else ca.fabs(x)


def sign(x: Any) -> Any:
    """Sign (-1, 0, 1)."""
    if isinstance(x, Expr):
        return Op("sign", (x,))
    if isinstance(x, ArrayBase):
        return x.map(sign)
    return float(np.sign(x)) if isinstance(x, Number) else ca.sign(x)


def _nary(name: str, sx_fun: Callable, args: tuple) -> Any:
    if any(isinstance(a, (ca.SX, ca.MX)) for a in args):
        return sx_fun(*[to_sx(a) for a in args])
    if any(isinstance(a, Expr) for a in args):
        return Op(name, tuple(a if isinstance(a, Expr) else float(a) for a in args))
    return None


def atan2(y: Any, x: Any) -> Any:
    """Four-quadrant arctangent of y/x [rad]."""
    out = _nary("atan2", ca.atan2, (y, x))
    return math.atan2(y, x) if out is None else out


def fmin(a: Any, b: Any) -> Any:
    """Smaller of two values (no event)."""
    out = _nary("fmin", ca.fmin, (a, b))
    return min(a, b) if out is None else out


def fmax(a: Any, b: Any) -> Any:
    """Larger of two values (no event)."""
    out = _nary("fmax", ca.fmax, (a, b))
    return max(a, b) if out is None else out


def if_else(condition: Any, then: Any, otherwise: Any) -> Any:
    """``then`` where ``condition`` holds, else ``otherwise`` (no event handling)."""
    out = _nary("if_else", ca.if_else, (condition, then, otherwise))
    if out is None:
        return then if condition else otherwise
    return out


# -- lowering -----------------------------------------------------------------------------------

_SX_BINARY: dict[str, Callable[[Any, Any], Any]] = {
    "+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b,
    "/": lambda a, b: a / b, "**": lambda a, b: a ** b, "<": lambda a, b: a < b,
    "<=": lambda a, b: a <= b, "!=": lambda a, b: a != b, "==": ca.eq,
    "and": ca.logic_and, "or": ca.logic_or,
    "atan2": ca.atan2, "fmin": ca.fmin, "fmax": ca.fmax,
}
_SX_UNARY: dict[str, Callable[[Any], Any]] = {
    "neg": lambda a: -a, "fabs": ca.fabs, "sign": ca.sign, "not": ca.logic_not,
    "noEvent": lambda a: a, "floor": ca.floor, "ceil": ca.ceil,
    **{n: getattr(ca, n) for n in ("sin", "cos", "tan", "exp", "log", "sqrt", "asin", "acos",
                                   "atan", "sinh", "cosh", "tanh")},
}


def apply_op(op: str, args: list) -> Any:
    """Apply operation ``op`` to lowered (SX / DM / float) arguments."""
    if op in _SX_UNARY:
        return _SX_UNARY[op](args[0])
    if op == "if_else":
        return ca.if_else(args[0], args[1], args[2])
    if op == "**" and isinstance(args[1], float) and args[1] == 2.0:
        return args[0] * args[0]
    return _SX_BINARY[op](args[0], args[1])


def to_sx(e: Any, leaf_sx: Callable[[Any], ca.SX] | None = None) -> Any:
    """Lower one expression to CasADi SX (the slow path, used for scalars and interop)."""
    if isinstance(e, (ca.SX, ca.MX, ca.DM)):
        return e
    if isinstance(e, Number):
        return ca.SX(float(e))
    if not isinstance(e, Expr):
        raise TypeError(f"cannot use {e!r} in an expression")
    return ca.SX(lower_tree(e, leaf_sx or (lambda sym: sym.sx)))


def lower_tree(e: Any, leaf: Callable[[Any], Any]) -> Any:
    """An expression tree as CasADi operations on what ``leaf(symbol)`` gives for its leaves
    (SX or MX); shared subtrees are lowered once, numbers stay floats."""
    if isinstance(e, (float, int)):
        return float(e)
    memo: dict[int, Any] = {}
    stack = [(e, False)]
    while stack:                     # post-order without recursion (deep sums and tables)
        node, ready = stack.pop()
        key = id(node)
        if key in memo:
            continue
        if isinstance(node, Leaf):
            memo[key] = leaf(node.sym)
        elif not isinstance(node, Expr):
            memo[key] = ca.SX(node)
        elif not ready:
            stack.append((node, True))
            stack.extend((a, False) for a in reversed(node.args)
                         if not isinstance(a, (float, int)) and id(a) not in memo)
        else:
            memo[key] = apply_op(node.op, [float(a) if isinstance(a, (float, int))
                                           else memo[id(a)] for a in node.args])
    return memo[id(e)]


def shape_of(e: Any, leaves: list, consts: list) -> Any:
    """Structural signature of ``e``; appends its leaves' symbols and constants in order."""
    if isinstance(e, Leaf):
        leaves.append(e.sym)
        return "L"
    if isinstance(e, float):
        consts.append(e)
        return "C"
    return (e.op, *[shape_of(a, leaves, consts) for a in e.args])


def lower_group(shape: Any, leaf_vectors: list, const_vectors: list) -> Any:
    """Lower one signature on stacked operands (SX vectors for leaves, DM for constants)."""
    li, ci = iter(leaf_vectors), iter(const_vectors)

    def go(s: Any) -> Any:
        if s == "L":
            return next(li)
        if s == "C":
            return next(ci)
        return apply_op(s[0], [go(a) for a in s[1:]])

    return go(shape)


def alias_signs(shape_l: Any, shape_r: Any) -> tuple[float, ...]:
    """For an equation shape ``lhs == rhs`` made of sums and negations of two leaves and
    constants: the signs ``(sa, sb)`` of the leaves (the equation is the alias link
    ``sa*a + sb*b = 0`` when its constants are all 0); ``()`` for any other shape."""
    signs: list[float] = []

    def walk(s: Any, sign: float) -> bool:
        if s == "L":
            signs.append(sign)
            return len(signs) <= 2
        if s == "C":
            return True
        if s[0] == "neg":
            return walk(s[1], -sign)
        if s[0] in ("+", "-"):
            return walk(s[1], sign) and walk(s[2], sign if s[0] == "+" else -sign)
        return False

    if walk(shape_l, 1.0) and walk(shape_r, -1.0) and len(signs) == 2:
        return (signs[0], signs[1])
    return ()


# -- symbolic time derivative -------------------------------------------------------------------


def differentiate(e: Any, rate: Callable[[Any], Any]) -> Any:
    """d/dt of ``e``, with ``rate(sym)`` giving the time derivative of a leaf's symbol
    (an Expr or 0.0)."""
    if isinstance(e, float):
        return 0.0
    if isinstance(e, Leaf):
        return rate(e.sym)
    a = e.args
    d = [differentiate(x, rate) for x in a]
    op = e.op
    if op == "+":
        return d[0] + d[1]
    if op == "-":
        return d[0] - d[1]
    if op == "neg":
        return -d[0]
    if op == "*":
        return d[0] * a[1] + a[0] * d[1]
    if op == "/":
        return d[0] / a[1] - a[0] * d[1] / a[1] ** 2
    if op == "**":
        if isinstance(a[1], float):
            return a[1] * a[0] ** (a[1] - 1.0) * d[0]
        return e * (d[1] * log(a[0]) + a[1] * d[0] / a[0])
    chain = {
        "sin": lambda: cos(a[0]) * d[0], "cos": lambda: -sin(a[0]) * d[0],
        "tan": lambda: d[0] / cos(a[0]) ** 2, "exp": lambda: e * d[0],
        "log": lambda: d[0] / a[0], "sqrt": lambda: d[0] / (2.0 * e),
        "asin": lambda: d[0] / sqrt(1.0 - a[0] ** 2),
        "acos": lambda: -d[0] / sqrt(1.0 - a[0] ** 2),
        "atan": lambda: d[0] / (1.0 + a[0] ** 2), "sinh": lambda: cosh(a[0]) * d[0],
        "cosh": lambda: sinh(a[0]) * d[0], "tanh": lambda: (1.0 - e ** 2) * d[0],
        "fabs": lambda: sign(a[0]) * d[0], "sign": lambda: 0.0,
        "atan2": lambda: (a[1] * d[0] - a[0] * d[1]) / (a[0] ** 2 + a[1] ** 2),
        "fmin": lambda: if_else(a[0] <= a[1], d[0], d[1]),
        "fmax": lambda: if_else(a[1] <= a[0], d[0], d[1]),
        "if_else": lambda: if_else(a[0], d[1], d[2]),
        "noEvent": lambda: d[0],
    }
    if op in chain:
        return chain[op]()
    return 0.0   # comparisons are piecewise constant


# -- printing -----------------------------------------------------------------------------------

_INFIX = {"+": " + ", "-": " - ", "*": "*", "/": "/", "**": "^", "<": " < ", "<=": " <= ",
          "!=": " <> ", "==": " == ", "and": " and ", "or": " or "}


def to_text(e: Any, name: Callable[[Any], str] | None = None) -> str:
    """Readable text of an expression; ``name(symbol)`` names the variables (default: their
    local names)."""
    if isinstance(e, float):
        return f"{e:g}"
    if isinstance(e, Leaf):
        return name(e.sym) if name is not None else getattr(e.sym, "name", "time")
    if isinstance(e, Op):
        args = [to_text(a, name) for a in e.args]
        if e.op in _INFIX:
            return f"({args[0]}{_INFIX[e.op]}{args[1]})"
        if e.op == "neg":
            return f"-{args[0]}"
        if e.op == "not":
            return f"not {args[0]}"
        return f"{e.op}({', '.join(args)})"
    return str(e)
