"""Re-implementation of ModelicaStandardTables (1-D tables and time tables) in Python.

Entry points take the arguments of the MSL's ``external "C"`` calls in their order
(``Modelica.Blocks.Types.ExternalCombiTable1D``/``ExternalCombiTimeTable`` and
``Modelica.Blocks.Tables.Internal``). ``init3`` returns a table object; the lookup functions
take it back. Enumerations arrive as their 1-based indices (see :mod:`.curve`).

Conventions (from the MSL documentation):

- ``columns`` selects table columns (1-based); ``icol`` indexes ``columns``.
- The abscissa must not decrease; cubic splines need it strictly increasing. A repeated
  abscissa (constant or linear segments) is a jump: the later row holds from that point on.
- ``ConstantSegments`` returns the value of the previous table point (right-continuous).
- One row: that row's values everywhere.
- Time tables: ``y = 0`` for ``time < startTime``; the table's first column is relative to
  ``shiftTime``. ``nextTimeEvent(t)`` is the first event instant after ``t`` (``startTime``,
  then table points as ``timeEvents`` asks, repeated every period for ``Periodic``), or
  :data:`NO_EVENT` (DBL_MAX). ``getValue(..., t, nextTimeEvent, pre(nextTimeEvent))`` gives
  the left limit at an event instant not yet processed (``nextTimeEvent <= t``) and the
  right limit after it, so values at jumps are exact on both sides.
- A symbolic abscissa or time (bgmodelica expression or CasADi SX/MX) gives the piecewise
  formula wrapped in ``noEvent`` (lookups generate no state events), right-continuous at
  jumps; a time table ignores the event arguments then (schedule
  :func:`time_breakpoints` as time events instead). ``NoExtrapolation`` raises for numbers;
  symbolically it continues the end slopes, and :func:`in_range` gives the condition to
  assert (:func:`valid_range` the range).
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from typing import Any

import casadi as ca
import numpy as np

from ...core.expr import Expr, Op, if_else
from .curve import (
    CONSTANT,
    EXTRAPOLATION_NAMES,
    LINEAR,
    PERIODIC,
    SMOOTHNESS_NAMES,
    Curve,
    is_symbolic,
)
from .errors import TableError
from .table_files import read_table

#: returned by ``nextTimeEvent`` when no event follows (C's DBL_MAX)
NO_EVENT = sys.float_info.max
#: Modelica.Blocks.Types.TimeEvents
ALWAYS, AT_DISCONTINUITIES, NO_TIME_EVENTS = 1, 2, 3


def _no_name(s: str) -> bool:
    return not str(s).strip() or str(s).strip() == "NoName"


def _tol(t: float) -> float:
    """Time instants this close [s] count as equal (rounding of shifted/periodic events)."""
    return 1e-13 * max(1.0, abs(t))


def _no_event(e: Any) -> Any:
    return Op("noEvent", (e,)) if isinstance(e, Expr) else e


class _Table:
    """Matrix, columns and one :class:`Curve` per selected column."""

    kind = "table"
    external_object = True        # a value made when the model is built, never a variable

    def __init__(self, file_name: str, table_name: str, table: Any, columns: Any,
                 smoothness: int, extrapolation: int, delimiter: str = ",",
                 n_header: int = 0, label: str | None = None) -> None:
        if _no_name(file_name):
            if not _no_name(table_name):
                raise TableError(f"{self.kind} {table_name!r}: tables in 'usertab' are not "
                                 "supported; give the matrix or a file")
            self.label = label or f"{self.kind} (matrix)"
            matrix = np.asarray(table, dtype=float)
        else:
            self.label = label or f"{self.kind} {table_name!r} of {file_name!r}"
            matrix = read_table(str(file_name), str(table_name), delimiter, int(n_header))
        self.matrix = _check_matrix(np.atleast_2d(matrix) if matrix.size else matrix,
                                    self.label)
        self.columns = [int(c) for c in np.atleast_1d(np.asarray(columns)).ravel()]
        self.smoothness, self.extrapolation = int(smoothness), int(extrapolation)
        _check_settings(self.matrix, self.columns, self.smoothness, self.extrapolation,
                        self.label)
        x = self.matrix[:, 0]
        self.curves = [Curve(f"{self.label} column {c}", x, self.matrix[:, c - 1],
                             self.smoothness, self.extrapolation) for c in self.columns]

    @property
    def u_min(self) -> float:
        """Smallest abscissa of the table."""
        return float(self.matrix[0, 0])

    @property
    def u_max(self) -> float:
        """Largest abscissa of the table."""
        return float(self.matrix[-1, 0])

    def curve(self, icol: int) -> Curve:
        """The curve of output ``icol`` (1-based index into ``columns``)."""
        if not 1 <= int(icol) <= len(self.curves):
            raise TableError(f"{self.label}: output {icol} requested, the table has "
                             f"{len(self.curves)} (columns {self.columns})")
        return self.curves[int(icol) - 1]

    def __repr__(self) -> str:
        return (f"<{type(self).__name__} {self.label}: {self.matrix.shape[0]} rows, columns "
                f"{self.columns}, {SMOOTHNESS_NAMES[self.smoothness]}, "
                f"{EXTRAPOLATION_NAMES[self.extrapolation]}>")


def _check_matrix(m: np.ndarray, label: str) -> np.ndarray:
    if m.ndim != 2 or m.size == 0:
        raise TableError(f"{label}: the table matrix is empty")
    if not np.all(np.isfinite(m)):
        r, c = np.argwhere(~np.isfinite(m))[0]
        raise TableError(f"{label}: entry [{r + 1},{c + 1}] is not a finite number")
    return m


def _check_settings(m: np.ndarray, columns: list[int], smoothness: int, extrapolation: int,
                    label: str) -> None:
    if smoothness not in SMOOTHNESS_NAMES:
        raise TableError(f"{label}: smoothness {smoothness} is not a Smoothness (1..6)")
    if extrapolation not in EXTRAPOLATION_NAMES:
        raise TableError(f"{label}: extrapolation {extrapolation} is not an Extrapolation "
                         "(1..4)")
    for c in columns:
        if not 1 <= c <= m.shape[1]:
            raise TableError(f"{label}: column {c} out of range (the table has "
                             f"{m.shape[1]} columns)")
    x = m[:, 0]
    dx = np.diff(x)
    if np.any(dx < 0):
        k = int(np.argmax(dx < 0))
        raise TableError(f"{label}: the first column is not monotonically increasing (row "
                         f"{k + 1}: {x[k]:g}, row {k + 2}: {x[k + 1]:g})")
    if np.any(dx == 0) and smoothness not in (LINEAR, CONSTANT):
        k = int(np.argmax(dx == 0))
        raise TableError(f"{label}: the first column is not strictly increasing (rows "
                         f"{k + 1} and {k + 2}: {x[k]:g}), as "
                         f"{SMOOTHNESS_NAMES[smoothness]} needs")
    if x.size > 1 and x[-1] == x[0]:
        raise TableError(f"{label}: all abscissae are equal ({x[0]:g})")


class CombiTable1D(_Table):
    """A 1-D table ``y = f(u)`` (``ExternalCombiTable1D``)."""

    kind = "CombiTable1D"

    def value(self, icol: int, u: Any, order: int = 0) -> Any:
        """Interpolated value (``order`` 0) or its derivative (1, 2) with respect to ``u``."""
        c = self.curve(icol)
        if is_symbolic(u):
            return _no_event(c.symbolic(u, order))
        return c.evaluate(float(u), order)


class CombiTimeTable(_Table):
    """A table of time (``ExternalCombiTimeTable``)."""

    kind = "CombiTimeTable"

    def __init__(self, file_name: str, table_name: str, table: Any, start_time: float,
                 columns: Any, smoothness: int, extrapolation: int, shift_time: float = 0.0,
                 time_events: int = ALWAYS, delimiter: str = ",", n_header: int = 0,
                 label: str | None = None) -> None:
        super().__init__(file_name, table_name, table, columns, smoothness, extrapolation,
                         delimiter, n_header, label)
        self.start_time, self.shift_time = float(start_time), float(shift_time)
        self.time_events = int(time_events)
        if self.time_events not in (ALWAYS, AT_DISCONTINUITIES, NO_TIME_EVENTS):
            raise TableError(f"{self.label}: timeEvents {time_events} is not a TimeEvents "
                             "(1..3)")
        self.events = self._local_events()

    def _local_events(self) -> np.ndarray:
        """Table times [s, unshifted] that are events (within one period if periodic)."""
        x = self.matrix[:, 0]
        if x.size == 1 or self.time_events == NO_TIME_EVENTS:
            return np.empty(0)
        if self.time_events == ALWAYS:
            ev = np.unique(x)
        else:
            ev = np.unique(x[1:][np.diff(x) == 0])
        if self.extrapolation == PERIODIC:
            ev = np.unique(np.concatenate([[x[0]], ev[ev < x[-1]]]))
        return ev

    def _events_between(self, a: float, b: float) -> np.ndarray:
        """Table events in [a, b] (global time [s]), sorted, without duplicates."""
        ev = self.events
        if not ev.size or b < a:
            return np.empty(0)
        if self.extrapolation != PERIODIC:
            g = self.shift_time + ev
        else:
            period, x0 = self.u_max - self.u_min, self.u_min
            k0 = math.floor((a - self.shift_time - x0) / period) - 1
            k1 = math.floor((b - self.shift_time - x0) / period) + 1
            ks = np.arange(k0, k1 + 1, dtype=float)
            g = (self.shift_time + (ev[None, :] + ks[:, None] * period)).ravel()
        return np.unique(g[(g >= a) & (g <= b)])

    #: at most this many event instants in the closed form of a symbolic ``next_event``
    MAX_SYMBOLIC_EVENTS = 2000

    def next_event(self, t: Any) -> Any:
        """First event instant after ``t`` [s], or :data:`NO_EVENT`; for a symbolic ``t`` a
        piecewise-constant expression of it (a periodic table: its first
        :data:`MAX_SYMBOLIC_EVENTS` events)."""
        if is_symbolic(t):
            return self._next_event_symbolic(t)
        t = float(t)
        if t < self.start_time - _tol(self.start_time):
            return self.start_time
        lo = t + _tol(t)
        if not self.events.size:
            return NO_EVENT
        if self.extrapolation == PERIODIC:
            g = self._events_between(lo, lo + (self.u_max - self.u_min))
        else:
            g = self.shift_time + self.events
        g = g[g > lo]
        return float(g.min()) if g.size else NO_EVENT

    def _next_event_symbolic(self, t: Any) -> Any:
        start = self.start_time
        if self.extrapolation == PERIODIC and self.events.size:
            period = self.u_max - self.u_min
            per = max(1, len(self.events))
            horizon = start + period * max(1, self.MAX_SYMBOLIC_EVENTS // per)
        else:
            horizon = max(start, self.shift_time + self.u_max) + 1.0
        points = self.breakpoints(start, horizon)[: self.MAX_SYMBOLIC_EVENTS]
        out: Any = NO_EVENT
        for b in reversed(points):
            out = if_else(t < b - _tol(b), b, out)
        return _no_event(out)

    def breakpoints(self, t0: float, t1: float) -> list[float]:
        """Sorted event instants in [t0, t1] [s]: ``startTime`` and the table's events."""
        g = self._events_between(max(t0, self.start_time), t1)
        out = set(g.tolist())
        if t0 <= self.start_time <= t1:
            out.add(self.start_time)
        return sorted(out)

    def value(self, icol: int, t: Any, next_event: Any = NO_EVENT, pre_next_event: Any = 0.0,
              order: int = 0) -> Any:
        """Value (``order`` 0) or time derivative (1, 2) of output ``icol`` at time ``t``."""
        c = self.curve(icol)
        if is_symbolic(t):
            inner = c.symbolic(t - self.shift_time, order)
            return _no_event(if_else(t < self.start_time, 0.0, inner))
        t = float(t)
        tol = _tol(t)
        pending = not is_symbolic(next_event) and float(next_event) <= t + tol
        if t < self.start_time - tol or (pending and t <= self.start_time + tol):
            return 0.0
        return c.evaluate(t - self.shift_time, order, left=pending, snap=tol)


def time_breakpoints(table: CombiTimeTable, t0: float, t1: float) -> list[float]:
    """Sorted event instants of a time table in [t0, t1] [s] (for a caller that uses the
    closed form of a symbolic lookup and schedules these as time events)."""
    return table.breakpoints(t0, t1)


def valid_range(table: _Table) -> tuple[float, float]:
    """Abscissa range [u_min, u_max] of a table (time tables: unshifted, like the MSL's
    ``t_minScaled``/``t_maxScaled``), where ``NoExtrapolation`` lookups are allowed."""
    return table.u_min, table.u_max


def in_range(table: _Table, u: Any) -> Any:
    """Whether a lookup at ``u`` stays in the table range (a Boolean, or a Boolean expression
    for a symbolic ``u``): the condition a ``NoExtrapolation`` table asserts. For a time table
    ``u`` is the time: before ``startTime`` any time is allowed, after it ``time - shiftTime``
    must lie in the range."""
    lo, hi = table.u_min, table.u_max
    shift = table.shift_time if isinstance(table, CombiTimeTable) else 0.0
    if not is_symbolic(u):
        ok = lo <= float(u) - shift <= hi
        return ok or (isinstance(table, CombiTimeTable) and float(u) < table.start_time)
    land, lor = (ca.logic_and, ca.logic_or) if isinstance(u, (ca.SX, ca.MX)) else \
        (lambda a, b: a & b, lambda a, b: a | b)
    ok = land(lo <= u - shift, u - shift <= hi)
    if isinstance(table, CombiTimeTable):
        ok = lor(u < table.start_time, ok)
    return _no_event(ok)


# -- entry points (arguments as in the MSL's external "C" calls) -------------------------------


def table1d_init3(file_name: str, table_name: str, table: Any, n_row: int, n_col: int,
                  columns: Any, n_columns: int, smoothness: int, extrapolation: int,
                  verbose: bool = False, delimiter: str = ",", n_header: int = 0, *,
                  label: str | None = None) -> CombiTable1D:
    """``ModelicaStandardTables_CombiTable1D_init3``: the table object."""
    return CombiTable1D(file_name, table_name, _shaped(table, n_row, n_col), columns,
                        smoothness, extrapolation, delimiter, n_header, label)


def time_table_init3(file_name: str, table_name: str, table: Any, n_row: int, n_col: int,
                     start_time: float, columns: Any, n_columns: int, smoothness: int,
                     extrapolation: int, shift_time: float = 0.0, time_events: int = ALWAYS,
                     verbose: bool = False, delimiter: str = ",", n_header: int = 0, *,
                     label: str | None = None) -> CombiTimeTable:
    """``ModelicaStandardTables_CombiTimeTable_init3``: the table object."""
    return CombiTimeTable(file_name, table_name, _shaped(table, n_row, n_col), start_time,
                          columns, smoothness, extrapolation, shift_time, time_events,
                          delimiter, n_header, label)


def _shaped(table: Any, n_row: int, n_col: int) -> np.ndarray:
    m = np.asarray(table, dtype=float)
    if m.ndim != 2 and m.size == int(n_row) * int(n_col):
        m = m.reshape(int(n_row), int(n_col))
    return m


def _close(table: Any) -> None:
    """Destructor: nothing to release."""
    return None


REGISTRY: dict[str, Callable[..., Any]] = {
    "ModelicaStandardTables_CombiTable1D_init3": table1d_init3,
    "ModelicaStandardTables_CombiTable1D_close": _close,
    "ModelicaStandardTables_CombiTable1D_getValue":
        lambda table, icol, u: table.value(icol, u),
    "ModelicaStandardTables_CombiTable1D_getDerValue":
        lambda table, icol, u, der_u: table.value(icol, u, 1) * der_u,
    "ModelicaStandardTables_CombiTable1D_getDer2Value":
        lambda table, icol, u, der_u, der2_u: (table.value(icol, u, 2) * der_u * der_u
                                               + table.value(icol, u, 1) * der2_u),
    "ModelicaStandardTables_CombiTable1D_minimumAbscissa": lambda table: table.u_min,
    "ModelicaStandardTables_CombiTable1D_maximumAbscissa": lambda table: table.u_max,
    "ModelicaStandardTables_CombiTimeTable_init3": time_table_init3,
    "ModelicaStandardTables_CombiTimeTable_close": _close,
    "ModelicaStandardTables_CombiTimeTable_getValue":
        lambda table, icol, t, nxt, pre: table.value(icol, t, nxt, pre),
    "ModelicaStandardTables_CombiTimeTable_getDerValue":
        lambda table, icol, t, nxt, pre, der_t: table.value(icol, t, nxt, pre, 1) * der_t,
    "ModelicaStandardTables_CombiTimeTable_getDer2Value":
        lambda table, icol, t, nxt, pre, der_t, der2_t: (
            table.value(icol, t, nxt, pre, 2) * der_t * der_t
            + table.value(icol, t, nxt, pre, 1) * der2_t),
    "ModelicaStandardTables_CombiTimeTable_nextTimeEvent":
        lambda table, t: table.next_event(t),
    "ModelicaStandardTables_CombiTimeTable_minimumTime": lambda table: table.u_min,
    "ModelicaStandardTables_CombiTimeTable_maximumTime": lambda table: table.u_max,
}
