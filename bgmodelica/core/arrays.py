"""Arrays: array variables and parameters, vectorized equations, arrays of components.

An array declaration (``Variable(shape=n)``, ``Parameter(shape=n, value=...)``, also in
connectors) gives one scalar per element, named Modelica-style ``x[1] .. x[n]`` (1-based, as in
Modelica and FMI structured names); in ``equations()`` the attribute is an :class:`ArrayExpr`,
indexed and sliced 0-based like a numpy vector::

    yield der(self.v) == (self.i - self.i_next) / self.C        # n equations at once
    yield self.i[1:] == (self.v[:-1] - self.v[1:]) / self.R[1:]

Operators work elementwise with numpy broadcasting (scalars, numbers, numpy arrays of numbers
and other arrays) and are *lazy*: ``(self.v[:-1] - self.v[1:]) / self.R[1:]`` is one tree of
whole-array operations, not one expression per element. ``a == b`` is an
:class:`ArrayEquation`; flattening lowers it as one block (one CasADi operation per operator on
whole vectors), and the structural passes see its scalars. Indexing one element of a computed
array, iterating, ``sum``, ``@`` and functions other than the math functions build the
elements on demand.

``array_of(Resistor, n, R=values)`` builds ``n`` components named ``R[1] .. R[n]`` when added
to a model; ``arr.p`` is the array of their connectors and ``connect`` joins arrays of
connectors elementwise (a single connector is broadcast).
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from typing import Any

import numpy as np

from ..errors import ConnectError, DeclarationError, EquationError
from .array_marks import LEAVES, marked
from .expr import ArrayBase, Equation, Expr, Leaf, Number, to_text

#: math functions that stay whole-array operations (``sin(arr)``)
LAZY_FUNCTIONS = frozenset({"sin", "cos", "tan", "exp", "log", "sqrt", "asin", "acos", "atan",
                            "sinh", "cosh", "tanh", "fabs", "sign"})


def element_names(name: str, shape: tuple[int, ...]) -> list[str]:
    """Modelica names of the elements of an array ``name`` of ``shape``, in C order:
    ``x[1]``, ``x[2]``..., or ``A[1,1]``, ``A[1,2]``... for matrices."""
    if len(shape) == 1:
        return [f"{name}[{i}]" for i in range(1, shape[0] + 1)]
    return [f"{name}[{','.join(str(i + 1) for i in idx)}]" for idx in np.ndindex(*shape)]


def normalize_shape(shape: Any, owner: str) -> tuple[int, ...]:
    """``shape`` (an int or a tuple of ints, each >= 1) as a tuple; a clear error otherwise."""
    dims = (shape,) if isinstance(shape, (int, np.integer)) else tuple(shape)
    if not dims or not all(isinstance(d, (int, np.integer)) and not isinstance(d, bool)
                           and d >= 1 for d in dims):
        raise DeclarationError(f"{owner}: shape {shape!r} must be a positive integer or a "
                               "tuple of positive integers")
    return tuple(int(d) for d in dims)


def element_values(value: Any, shape: tuple[int, ...], what: str) -> list[Any]:
    """Per-element values of ``value`` (a scalar, broadcast, or an array of ``shape``)."""
    if isinstance(value, (dict, Expr)) or np.isscalar(value) or value is None:
        return [value] * int(np.prod(shape))
    if isinstance(value, ArrayExpr):
        arr = value.items
    else:
        arr = np.asarray(value, dtype=object)
    if arr.shape != shape:
        try:
            arr = np.broadcast_to(arr, shape)
        except ValueError:
            raise DeclarationError(f"{what}: value of shape {arr.shape} for an array of shape "
                                   f"{shape}") from None
    return list(arr.ravel())


def _items(x: Any) -> Any:
    """Operand of an elementwise operation: object arrays stay, numbers become floats."""
    if isinstance(x, ArrayExpr):
        return x.items
    if isinstance(x, np.ndarray):
        return x.astype(float) if x.dtype.kind in "biuf" else x
    if isinstance(x, (list, tuple)):
        return _items(np.asarray(x, dtype=object) if any(isinstance(v, Expr) for v in x)
                      else np.asarray(x, dtype=float))
    if isinstance(x, Number):
        return float(x)
    if isinstance(x, Expr):
        return x
    raise TypeError(f"cannot combine {x!r} with an array expression")


def _wrap(out: Any) -> Any:
    if isinstance(out, np.ndarray):
        return ArrayExpr(out) if out.ndim else out.item()
    return out


def _elementwise(fun: Any, *args: Any) -> Any:
    try:
        operands = np.broadcast_arrays(*[np.asarray(_items(a), dtype=object) for a in args])
    except ValueError:
        shapes = " and ".join(str(np.shape(_items(a))) for a in args)
        raise EquationError(f"array shapes {shapes} do not match") from None
    out = np.empty(operands[0].shape, dtype=object)
    flat = [op.ravel() for op in operands]
    out_flat = out.reshape(-1)
    for k in range(out_flat.size):
        out_flat[k] = fun(*[f[k] for f in flat])
    return _wrap(out)


_FUNCTIONS: dict[str, Any] = {
    "+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b,
    "/": lambda a, b: a / b, "**": lambda a, b: a ** b, "neg": lambda a: -a,
}


def _function(op: str) -> Any:
    if op in _FUNCTIONS:
        return _FUNCTIONS[op]
    from . import expr

    return getattr(expr, op)


def _lazy(op: str, *args: Any) -> Any:
    """``op`` over whole arrays as one node (shape by numpy broadcasting); operands other
    than arrays, numbers, numeric numpy arrays and scalar expressions go elementwise."""
    operands: list[Any] = []
    shapes: list[tuple[int, ...]] = []
    for x in args:
        if isinstance(x, ArrayExpr):
            shapes.append(x.shape)
        elif isinstance(x, Number):
            x = float(x)
        elif isinstance(x, np.ndarray) and x.dtype.kind in "biuf":
            x = x.astype(float)
            shapes.append(x.shape)
        elif not isinstance(x, Expr):
            return _elementwise(_function(op), *args)
        operands.append(x)
    try:
        shape = np.broadcast_shapes(*shapes)
    except ValueError:
        shown = " and ".join(str(s) for s in shapes)
        raise EquationError(f"array shapes {shown} do not match") from None
    return ArrayExpr(node=(op, tuple(operands)), shape=shape)


class ArrayExpr(ArrayBase):
    """An array of scalar expressions (0-based indexing and slicing, numpy broadcasting).

    Stored element by element (``items``, an object array of expressions), or lazy:
    ``node = (operator, operands)`` over whole arrays, numbers, numeric numpy arrays and
    scalar expressions, whose elements are built only when asked for."""

    __slots__ = ("_items", "node", "_shape")
    __array_priority__ = 2000        # numpy arrays defer to our operators
    __array_ufunc__ = None

    def __init__(self, items: Any = None, *, node: tuple[str, tuple] | None = None,
                 shape: tuple[int, ...] = ()) -> None:
        self.node = node
        if node is None:
            self._items: np.ndarray | None = np.asarray(items, dtype=object)
            self._shape = self._items.shape
        else:
            self._items = None
            self._shape = tuple(shape)

    @property
    def items(self) -> np.ndarray:
        """The elements (built on first use for a lazy array)."""
        if self._items is None:
            op, args = self.node                 # type: ignore[misc]
            out = _elementwise(_function(op), *args)
            self._items = out.items if isinstance(out, ArrayExpr) else \
                np.full(self._shape, out, dtype=object)
        return self._items

    # -- container -------------------------------------------------------------------------
    @property
    def shape(self) -> tuple[int, ...]:
        return self._shape

    @property
    def size(self) -> int:
        return int(np.prod(self._shape))

    def __len__(self) -> int:
        return self._shape[0]

    def __iter__(self) -> Iterator[Any]:
        for item in self.items:
            yield ArrayExpr(item) if isinstance(item, np.ndarray) else item

    def __getitem__(self, key: Any) -> Any:
        try:
            return _wrap(self.items[key])
        except IndexError:
            raise EquationError(f"index {key!r} out of range for an array of shape "
                                f"{self.shape}") from None

    def ravel(self) -> ArrayExpr:
        return ArrayExpr(self.items.ravel())

    # -- arithmetic ------------------------------------------------------------------------
    def __add__(self, o): return _lazy("+", self, o)
    def __radd__(self, o): return _lazy("+", o, self)
    def __sub__(self, o): return _lazy("-", self, o)
    def __rsub__(self, o): return _lazy("-", o, self)
    def __mul__(self, o): return _lazy("*", self, o)
    def __rmul__(self, o): return _lazy("*", o, self)
    def __truediv__(self, o): return _lazy("/", self, o)
    def __rtruediv__(self, o): return _lazy("/", o, self)
    def __pow__(self, o): return _lazy("**", self, o)
    def __rpow__(self, o): return _lazy("**", o, self)
    def __neg__(self): return _lazy("neg", self)
    def __pos__(self): return self
    def __lt__(self, o): return _elementwise(lambda a, b: a < b, self, o)
    def __le__(self, o): return _elementwise(lambda a, b: a <= b, self, o)
    def __gt__(self, o): return _elementwise(lambda a, b: a > b, self, o)
    def __ge__(self, o): return _elementwise(lambda a, b: a >= b, self, o)

    def __matmul__(self, o: Any) -> Any:
        """Matrix/vector product with numpy semantics (numbers or expressions)."""
        return _wrap(np.asarray(self.items, dtype=object) @ np.asarray(_items(o), dtype=object))

    def __rmatmul__(self, o: Any) -> Any:
        return _wrap(np.asarray(_items(o), dtype=object) @ self.items)

    def __eq__(self, o: Any) -> ArrayEquation:  # type: ignore[override]
        return ArrayEquation(self, o)

    __hash__ = object.__hash__

    def __bool__(self) -> bool:
        raise TypeError("an array expression has no truth value")

    def sum(self) -> Any:
        """Sum of all elements (a scalar expression)."""
        out: Any = 0.0
        for item in self.items.ravel():
            out = out + item
        return out

    def map(self, fun: Any) -> Any:
        """``fun`` applied to every element (the math functions of :mod:`bgmodelica` stay
        one lazy whole-array operation)."""
        name = getattr(fun, "__name__", "")
        if name in LAZY_FUNCTIONS and fun is _function(name):
            return _lazy(name, self)
        return _elementwise(fun, self)

    def __repr__(self) -> str:
        if self._items is None:
            return f"ArrayExpr(shape={self.shape}: {array_text(self)})"
        shown = ", ".join(repr(x) for x in self.items.ravel()[:4])
        more = ", ..." if self.size > 4 else ""
        return f"ArrayExpr(shape={self.shape}: {shown}{more})"


class ArrayEquation:
    """``lhs == rhs`` between arrays (broadcast): iterates over the scalar equations."""

    __slots__ = ("lhs", "rhs")

    def __init__(self, lhs: Any, rhs: Any) -> None:
        self.lhs, self.rhs = lhs, rhs

    @property
    def shape(self) -> tuple[int, ...]:
        """The broadcast shape of the two sides (the shape of the scalar equations)."""
        try:
            return np.broadcast_shapes(_shape(self.lhs), _shape(self.rhs))
        except ValueError:
            raise EquationError(
                f"array equation sides have shapes {_shape(self.lhs)} and "
                f"{_shape(self.rhs)}, which do not match") from None

    def is_block(self) -> bool:
        """Whether flattening lowers this equation as one block: its sides are built from
        arrays of declared scalars, whole-array arithmetic and math functions, numbers,
        numeric arrays and scalar expressions without relations or events."""
        return _block_operand(self.lhs) and _block_operand(self.rhs)

    def equations(self) -> list[Equation]:
        try:
            left, right = np.broadcast_arrays(np.asarray(_items(self.lhs), dtype=object),
                                              np.asarray(_items(self.rhs), dtype=object))
        except ValueError:
            raise EquationError(
                f"array equation sides have shapes {np.shape(_items(self.lhs))} and "
                f"{np.shape(_items(self.rhs))}, which do not match") from None
        return [Equation(a, b) for a, b in zip(left.ravel(), right.ravel(), strict=True)]

    def __iter__(self) -> Iterator[Equation]:
        return iter(self.equations())

    def __len__(self) -> int:
        return int(np.prod(self.shape))

    def __bool__(self) -> bool:
        raise TypeError("an equation 'a == b' has no truth value; yield it from equations()")

    def __repr__(self) -> str:
        return f"{array_text(self.lhs)} == {array_text(self.rhs)}"


def _shape(x: Any) -> tuple[int, ...]:
    if isinstance(x, ArrayExpr):
        return x.shape
    return np.shape(_items(x))


_SMOOTH_OPS = frozenset(_FUNCTIONS) | LAZY_FUNCTIONS | {"atan2", "fmin", "fmax"}


def _block_operand(x: Any) -> bool:
    if isinstance(x, ArrayExpr):
        if x.node is None:                 # one type test per distinct element type
            return marked(x.items, LEAVES) or \
                all(issubclass(t, Leaf) for t in set(map(type, x.items.flat)))
        return all(_block_operand(a) for a in x.node[1])
    if isinstance(x, (Number, float)):
        return True
    if isinstance(x, np.ndarray):
        return x.dtype.kind in "biuf"
    if isinstance(x, Leaf):
        return True
    if isinstance(x, Expr):
        return getattr(x, "op", None) in _SMOOTH_OPS and all(_block_operand(a) for a in x.args)
    return False


def array_text(x: Any) -> str:
    """Readable text of an array expression: ``(v[1:4] - v[2:5])/R[2:5]``."""
    if isinstance(x, ArrayExpr):
        if x.node is None:
            items = list(x.items.flat)
            if items and all(isinstance(i, Leaf) for i in items):
                parts = compact_names([to_text(i) for i in items])
                if len(set(parts)) == 1:       # the same name in each element of a group
                    return parts[0]
            else:
                parts = [to_text(i) for i in items[:3]] + (["..."] if len(items) > 3 else [])
            return parts[0] if len(parts) == 1 else "{" + ", ".join(parts) + "}"
        op, args = x.node
        texts = [array_text(a) for a in args]
        if op in _INFIX:
            return f"({texts[0]}{_INFIX[op]}{texts[1]})"
        if op == "neg":
            return f"-{texts[0]}"
        return f"{op}({', '.join(texts)})"
    if isinstance(x, np.ndarray):
        shown = ", ".join(f"{v:g}" for v in x.ravel()[:3])
        return "{" + shown + (", ..." if x.size > 3 else "") + "}"
    return to_text(x)


_INFIX = {"+": " + ", "-": " - ", "*": "*", "/": "/", "**": "^"}


class ElementArray:
    """An array of components or connectors (:func:`array_of`): indexable, iterable, and
    ``arr.name`` gives the array of the elements' ``name`` (connectors, or an
    :class:`ArrayExpr` of variables)."""

    __slots__ = ("elements",)

    def __init__(self, elements: list[Any]) -> None:
        object.__setattr__(self, "elements", list(elements))

    def __len__(self) -> int:
        return len(self.elements)

    def __iter__(self) -> Iterator[Any]:
        return iter(self.elements)

    def __getitem__(self, key: Any) -> Any:
        if isinstance(key, slice):
            return ElementArray(self.elements[key])
        return self.elements[key]

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(name)
        parts = [getattr(e, name) for e in self.elements]
        if parts and all(isinstance(p, Expr) for p in parts):
            items = np.empty(len(parts), dtype=object)
            items[:] = parts
            return ArrayExpr(items)
        return ElementArray(parts)

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError("set values on the elements, or give them to array_of()")

    def __repr__(self) -> str:
        return f"ElementArray({len(self)} x {type(self.elements[0]).__name__ if self else '-'})"


class ComponentArray(ElementArray):
    """``n`` components of one class, not yet part of a model; adding it under ``name``
    names them ``name[1] .. name[n]``."""

    __slots__ = ()


def array_of(cls: type, n: int, **modifiers: Any) -> ComponentArray:
    """``n`` instances of component class ``cls``; a modifier that is a sequence of length
    ``n`` gives element k its k-th value, any other modifier is shared::

        self.R = array_of(Resistor, n, R=1.0 / np.arange(1, n + 1))
    """
    if not isinstance(n, (int, np.integer)) or n < 1:
        raise DeclarationError(f"array_of({cls.__name__}, {n!r}): n must be a positive integer")
    per: list[dict[str, Any]] = [{} for _ in range(n)]
    for key, value in modifiers.items():
        if isinstance(value, (list, tuple, np.ndarray)) and not isinstance(value, str):
            if len(value) != n:
                raise DeclarationError(f"array_of({cls.__name__}, {n}): modifier {key} has "
                                       f"{len(value)} values for {n} components")
            for k in range(n):
                per[k][key] = value[k].item() if isinstance(value[k], np.generic) else value[k]
        else:
            for k in range(n):
                per[k][key] = value
    return ComponentArray([cls(**per[k]) for k in range(n)])


def connect_arrays(a: Any, b: Any, make: Any) -> list[Any]:
    """Elementwise ``make(a[k], b[k])`` of two connector arrays (or one array and one
    connector, broadcast)."""
    left = list(a) if isinstance(a, ElementArray) else None
    right = list(b) if isinstance(b, ElementArray) else None
    if left is not None and right is not None and len(left) != len(right):
        raise ConnectError(f"connect() of arrays of {len(left)} and {len(right)} connectors: "
                           "sizes differ (slice them to match)")
    n = len(left) if left is not None else len(right)   # type: ignore[arg-type]
    return [make(left[k] if left is not None else a, right[k] if right is not None else b)
            for k in range(n)]


def compact_names(names: list[str]) -> list[str]:
    """``x[1], x[2], x[3]`` -> ``x[1:3]``, and ``C1.v, C2.v, ..., C9.v`` -> ``C1.v .. C9.v``
    (three or more components numbered in a row, as a ladder's sections are named): runs
    of consecutive elements collapsed (order kept), for reports."""
    out: list[str] = []
    run: list[Any] = []         # [kind, base, tail, first, last]: kind "[" or "#"

    def flush() -> None:
        if not run:
            return
        kind, base, tail, first, last = run
        if kind == "[":
            out.append(f"{base}[{first}:{last}]{tail}" if last > first
                       else f"{base}[{first}]{tail}")
        elif last - first >= 2:
            out.append(f"{base}{first}{tail} .. {base}{last}{tail}")
        else:
            out.extend(f"{base}{k}{tail}" for k in range(first, last + 1))
        run.clear()

    for name in names:
        head, tail = _split_index(name)
        kind = "["
        if head is None:
            m = _NUMBERED.match(name)
            if m is not None:
                head, tail, kind = (m.group(1), int(m.group(2))), m.group(3), "#"
        if head is not None:
            base, index = head
            if run and run[:3] == [kind, base, tail] and index == run[4] + 1:
                run[4] = index
                continue
            flush()
            run.extend([kind, base, tail, index, index])
            continue
        flush()
        out.append(name)
    flush()
    return out


#: ``C12.v`` -> (``C``, 12, ``.v``): a component numbered at the end of its name
_NUMBERED = re.compile(r"^(.*?[A-Za-z_])(\d+)((?:\.[^\[\]]*)?)$")
_LAST_INDEX = re.compile(r"^(.*?)\[(\d+)\]([^\[]*)$")


def _split_index(name: str) -> tuple[tuple[str, int] | None, str]:
    """``a.R[12].p.v`` -> ((``a.R``, 12), ``.p.v``); names without a 1-D index: (None, "")."""
    m = _LAST_INDEX.match(name)
    if not m:
        return None, ""
    return (m.group(1), int(m.group(2))), m.group(3)
