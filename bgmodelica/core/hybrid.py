"""Hybrid constructs with Modelica's names and meaning: ``when``, ``reinit``, ``pre``, ``edge``,
``change``, ``initial``, ``terminal``, ``sample``, ``no_event``, if-equations and time tables.

Semantics (Modelica Language Specification 3.6, sections 3.7.5, 8.3.4-8.3.6 and 8.5):

- A relation (``a < b``, ``a >= b``...) on continuous quantities is *frozen* during
  integration; its value changes only at an event, found as a zero crossing of ``b - a``.
  Relations on ``time`` alone are *time events*, hit exactly. ``no_event(expr)`` keeps the
  relations inside ``expr`` live (no event, evaluated at every call).
- Discrete variables (:class:`~bgmodelica.core.variables.Discrete`, ``Integer``, ``Boolean``)
  change only at events: inside ``when`` (``self.d == expr`` assigns) or through an ordinary
  equation of frozen relations and ``pre()`` values.
- ``when(c, ...)`` is active at the instant its Boolean condition ``c`` becomes true (a rising
  edge; a condition already true at the start does not fire, ``initial()`` does). ``elsewhen``
  branches are tried in order. ``reinit(x, v)`` restarts the continuous variable ``x`` at ``v``.
- At an event the discrete equations are iterated to a fixed point: ``pre(v)`` is the value of
  ``v`` before the current iteration (its left limit at the first).

Example (a bouncing ball)::

    class Ball(Component):
        h = Variable(start=1.0, fixed=True)
        v = Variable(start=0.0, fixed=True)

        def equations(self):
            yield der(self.h) == self.v
            yield der(self.v) == -9.81
            yield when(self.h < 0, reinit(self.v, -0.7 * pre(self.v)))
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import EquationError
from .expr import BOOLEAN_OPS, HYBRID_NODES, Equation, Expr, Leaf, Number, Op
from .variables import Boolean, Discrete, Symbol


class _Special(Symbol):
    """A hidden discrete symbol the flattening gives a slot (initial(), a sample, a table)."""

    __slots__ = ()


_INITIAL = _Special("initial()", Boolean(), None)
_TERMINAL = _Special("terminal()", Boolean(), None)


def initial() -> Expr:
    """True during the initialization at the start time, false afterwards."""
    HYBRID_NODES[0] += 1
    return _INITIAL.leaf


def terminal() -> Expr:
    """True at the final event at the stop time of a successful simulation."""
    HYBRID_NODES[0] += 1
    return _TERMINAL.leaf


def _symbol(x: Any, what: str) -> Symbol:
    if isinstance(x, Leaf) and isinstance(x.sym, Symbol) and not isinstance(x.sym, _Special):
        return x.sym
    raise EquationError(f"{what} takes a declared variable, got {x!r}")


def pre(x: Any) -> Expr:
    """Left limit of ``x`` at an event instant (its value before the current event
    iteration); equals ``x`` between events."""
    HYBRID_NODES[0] += 1
    return _symbol(x, "pre()").previous().leaf


def edge(b: Any) -> Expr:
    """``b and not pre(b)``: true at the instant the Boolean ``b`` becomes true."""
    return b & ~pre(b)


def change(v: Any) -> Expr:
    """``v <> pre(v)``: true at the instant the discrete ``v`` changes."""
    return v != pre(v)


def no_event(expr: Any) -> Any:
    """``expr`` with its relations evaluated literally (no zero crossings, no events)."""
    if isinstance(expr, Expr):
        return Op("noEvent", (expr,))
    return expr


noEvent = no_event  # noqa: N816 -- the Modelica spelling


def eq(a: Any, b: Any) -> Any:
    """``a == b`` as a Boolean expression (for Integer and Boolean values; ``==`` itself writes
    an equation)."""
    if isinstance(a, Expr) or isinstance(b, Expr):
        HYBRID_NODES[0] += 1
        return Op("==", (a if isinstance(a, Expr) else float(a),
                         b if isinstance(b, Expr) else float(b)))
    return float(a == b)


def and_(*args: Any) -> Any:
    """Logical and of Boolean expressions."""
    out = args[0]
    for a in args[1:]:
        out = out & a
    return out


def or_(*args: Any) -> Any:
    """Logical or of Boolean expressions."""
    out = args[0]
    for a in args[1:]:
        out = out | a
    return out


def not_(a: Any) -> Any:
    """Logical not of a Boolean expression."""
    return ~a if isinstance(a, Expr) else float(not a)


def is_boolean(e: Any) -> bool:
    """Whether ``e`` is a Boolean-valued expression (relation, logic, Boolean variable,
    ``initial()``, ``sample()``)."""
    if isinstance(e, Leaf):
        if isinstance(e.sym, Symbol) and e.sym.pre_of is not None:
            return is_boolean(e.sym.pre_of.leaf)
        return isinstance(e.sym, Symbol) and (
            isinstance(e.sym.decl, Boolean) or getattr(e.sym.decl, "type_name", "") == "Boolean")
    if isinstance(e, Op):
        if e.op in BOOLEAN_OPS:
            return True
        if e.op == "noEvent":
            return is_boolean(e.args[0])
        if e.op == "if_else":
            return all(is_boolean(a) or isinstance(a, float) and a in (0.0, 1.0)
                       for a in e.args[1:])
    return False


# -- sample -------------------------------------------------------------------------------------


class SampleClock(_Special):
    """``sample(start, interval)``: true at ``start + k*interval`` (k = 0, 1, ...)."""

    __slots__ = ("start", "interval")

    def __init__(self, start: Any, interval: Any) -> None:
        super().__init__("sample", Boolean(), None)
        self.start = start
        self.interval = interval


def sample(start: Any, interval: Any) -> Expr:
    """True at the time events ``start + k*interval`` [s], k = 0, 1, ... (Modelica's
    ``sample``); ``start`` and ``interval`` are numbers or expressions of parameters."""
    if isinstance(interval, Number) and not interval > 0:
        raise EquationError(f"sample(start, interval) needs interval > 0, got {interval!r}")
    HYBRID_NODES[0] += 1
    return SampleClock(start, interval).leaf


# -- time tables --------------------------------------------------------------------------------


INTERPOLATIONS = ("linear", "hold")
EXTRAPOLATIONS = ("hold", "periodic", "linear")


class TimeTable(_Special):
    """A table of ``values`` against ``times``: the expression ``c0 + c1*time`` whose
    coefficients change at the breakpoints (time events). See :func:`time_table`."""

    __slots__ = ("times", "values", "interpolation", "extrapolation", "c1", "source")

    def __init__(self, times: np.ndarray, values: np.ndarray, interpolation: str,
                 extrapolation: str, source: tuple[str, str] | None = None) -> None:
        super().__init__("table.c0", Discrete(), None)
        self.c1 = _Special("table.c1", Discrete(), None)
        self.times = times
        self.values = values
        self.interpolation = interpolation
        self.extrapolation = extrapolation
        self.source = source          # (file path, column) of a table read from a file


def read_table_file(file: str | Path, column: str | None) -> tuple[np.ndarray, np.ndarray]:
    """(times, values) of ``column`` in the CSV ``file`` (first column ``time``)."""
    import csv

    path = Path(file)
    if not column:
        raise EquationError(f"time_table: file={str(path)!r} needs column=<name>")
    if not path.is_file():
        raise EquationError(f"time_table: the file {path} does not exist")
    with path.open(newline="") as fh:
        rows = [r for r in csv.reader(fh) if r and any(c.strip() for c in r)]
    if len(rows) < 2:
        raise EquationError(f"time_table: {path} needs a header row and data rows")
    head = [h.strip().strip('"') for h in rows[0]]
    if head[0] != "time":
        raise EquationError(f"time_table: {path}: the first column must be 'time', got "
                            f"{head[0]!r}")
    if column not in head[1:]:
        raise EquationError(f"time_table: {path} has no column {column!r} (columns: "
                            f"{', '.join(head[1:])})")
    k = head.index(column)
    t, v = [], []
    for n, row in enumerate(rows[1:], start=2):
        try:
            t.append(float(row[0]))
            v.append(float(row[k]))
        except (ValueError, IndexError):
            raise EquationError(f"time_table: {path} row {n}: time and {column} must be "
                                "numbers") from None
    return np.array(t), np.array(v)


def time_table(times: Sequence[float] | None = None, values: Sequence[float] | None = None,
               interpolation: str = "linear", extrapolation: str = "hold", *,
               file: str | Path | None = None, column: str | None = None) -> Expr:
    """A function of ``time`` given by a table, like Modelica's CombiTimeTable.

    times: breakpoints [s], non-decreasing; a repeated time is a jump (the later row holds
    from that instant). interpolation: "linear" or "hold" (constant from each breakpoint to
    the next). extrapolation: "hold" (first/last value), "periodic" (the table repeats with
    period ``times[-1] - times[0]``) or "linear" (first/last segment continued).
    Breakpoints are time events, so jumps and kinks are hit exactly.

    From a file: ``time_table(file="profile.csv", column="u")`` reads a CSV whose first
    column is ``time`` (header row, then numbers). An exported FMU carries the file in its
    resources and reads it when instantiated, so the table can be changed without
    re-exporting (the number of rows may change too).
    """
    source = None
    if file is not None:
        if times is not None or values is not None:
            raise EquationError("time_table: give either times and values or file=")
        times, values = read_table_file(file, column)
        source = (str(Path(file).resolve()), str(column))
    elif times is None or values is None:
        raise EquationError("time_table: needs times and values, or file= and column=")
    t = np.asarray(times, dtype=float).ravel()
    v = np.asarray(values, dtype=float).ravel()
    if t.size == 0 or t.size != v.size:
        raise EquationError(f"time_table: {t.size} times for {v.size} values")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(v))):
        raise EquationError("time_table: times and values must be finite numbers")
    if np.any(np.diff(t) < 0):
        k = int(np.argmax(np.diff(t) < 0))
        raise EquationError(f"time_table: times must not decrease (row {k + 1}: {t[k]} then "
                            f"{t[k + 1]})")
    if interpolation not in INTERPOLATIONS:
        raise EquationError(f"time_table: interpolation must be one of {INTERPOLATIONS}, "
                            f"got {interpolation!r}")
    if extrapolation not in EXTRAPOLATIONS:
        raise EquationError(f"time_table: extrapolation must be one of {EXTRAPOLATIONS}, "
                            f"got {extrapolation!r}")
    if extrapolation == "periodic" and not t[-1] > t[0]:
        raise EquationError("time_table: periodic extrapolation needs times[-1] > times[0]")
    HYBRID_NODES[0] += 1
    table = TimeTable(t, v, interpolation, extrapolation, source)
    from .variables import time as _time
    return table.leaf + table.c1.leaf * _time


# -- statements ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class Reinit:
    """``reinit(x, value)``: restart the continuous variable ``x`` at ``value`` when the
    enclosing ``when`` fires."""

    target: Symbol
    value: Any


def reinit(x: Any, value: Any) -> Reinit:
    """Statement for a ``when`` body: set the continuous variable ``x`` to ``value``."""
    sym = _symbol(x, "reinit()")
    if sym.is_discrete:
        raise EquationError(f"reinit({sym.name}, ...): {sym.name} is discrete; assign it "
                            f"with '{sym.name} == value' inside when() instead")
    return Reinit(sym, value)


class RuntimeOutput(_Special):
    """One scalar output of a :class:`RuntimeCall`: a hidden discrete slot the call writes."""

    __slots__ = ("call",)

    def __init__(self, name: str, boolean: bool = False) -> None:
        super().__init__(name, Boolean() if boolean else Discrete(), None)
        self.call: RuntimeCall | None = None


@dataclass
class RuntimeCall:
    """A statement of a ``when`` body: a function evaluated on numbers when the branch fires.

    ``function(values)`` takes the numeric values of ``args`` (scalar expressions of the
    model, in order) and returns the values of ``outputs`` (a flat sequence of numbers); it
    runs only where ``guard`` (a Boolean expression or True) holds, before the branch's
    assignments, which may read the outputs. Calls of one branch run in order. ``text``
    names the call (``file:line: name``) for messages."""

    function: Any
    args: list[Any]
    guard: Any
    outputs: list[RuntimeOutput]
    text: str

    def __post_init__(self) -> None:
        for o in self.outputs:
            o.call = self


@dataclass
class When:
    """``when c1 then ... elsewhen c2 then ... end when`` (see :func:`when`)."""

    branches: list[tuple[Any, list[Any]]] = field(default_factory=list)

    def elsewhen(self, condition: Any, *statements: Any) -> When:
        """Add a branch tried when the earlier conditions did not fire."""
        self.branches.append((_condition(condition), _statements(statements)))
        return self


def _condition(c: Any) -> Any:
    if isinstance(c, (list, tuple)):
        if not c:
            raise EquationError("when(): empty list of conditions")
        out = _condition(c[0])
        for x in c[1:]:
            out = out | _condition(x)
        return out
    if not is_boolean(c):
        raise EquationError(f"when-condition {c!r} is not a Boolean expression (use a "
                            "relation such as x > 0, a Boolean variable, sample() or initial())")
    return c


def _statements(stmts: Sequence[Any]) -> list[Any]:
    out = []
    for s in stmts:
        if isinstance(s, (list, tuple)):
            out.extend(_statements(s))
        elif isinstance(s, (Equation, Reinit, RuntimeCall)):
            out.append(s)
        else:
            raise EquationError(f"a when() body holds 'd == value' assignments and reinit() "
                                f"statements, got {s!r}")
    return out


def when(condition: Any, *statements: Any) -> When:
    """A when-equation: the ``statements`` (``self.d == expr`` assignments of discrete
    variables, ``reinit(self.x, expr)``) take effect at the instant ``condition`` becomes true.
    A list of conditions fires when any of them becomes true. Chain ``.elsewhen(c, ...)``."""
    HYBRID_NODES[0] += 1
    return When([(_condition(condition), _statements(statements))])


@dataclass
class Assert:
    """``assert(condition, message)`` of a model: checked while simulating (see
    :func:`assert_`)."""

    condition: Any
    message: str
    level: str = "error"


def assert_(condition: Any, message: str, level: str = "error") -> Assert:
    """A model assertion: the simulation stops with ``message`` and the time at the first
    output point where ``condition`` is false (``level="warning"``: a warning instead)."""
    HYBRID_NODES[0] += 1
    return Assert(condition, str(message), level)


@dataclass
class IfEquation:
    """``if c1 then eqs1 elseif c2 then eqs2 else eqs3 end if`` (see :func:`if_equation`)."""

    branches: list[tuple[Any, list[Equation]]]
    otherwise: list[Equation]


def if_equation(condition: Any, then: Sequence[Any], otherwise: Sequence[Any],
                *elseif: tuple[Any, Sequence[Any]]) -> IfEquation:
    """An if-equation: ``then`` holds where ``condition`` is true, else ``otherwise``; more
    branches as ``(condition, equations)`` pairs after them are tried in order before
    ``otherwise``. Every branch must have the same number of equations (balanced)."""
    HYBRID_NODES[0] += 1
    branches = [(condition, list(then))] + [(c, list(eqs)) for c, eqs in elseif]
    for c, _ in branches:
        if not is_boolean(c) and not isinstance(c, (Number, bool)):
            raise EquationError(f"if-equation condition {c!r} is not a Boolean expression")
    return IfEquation(branches, list(otherwise))
