"""The master's loop for its most common cases, as index arrays over one value vector.

The cases: Jacobi or Gauss-Seidel order without extrapolation or input signals, every unit a
Co-Simulation FMU (FMI 2.0 or 3.0) whose coupled connectors are all Real (Float64). Then every
output of every unit lives in one vector ``z`` (the FMUs write into it), an element's inputs
are one gather ``z[idx]`` (unconnected inputs read their start values, kept at the end of
``z``; in Gauss-Seidel order ``z`` already holds the outputs of the units stepped before), a
recorded row is one gather too. The FMU calls, their order and their arguments are exactly
those of the general loop in :meth:`~.master.Master.simulate`, so the results are the same to
the last bit; only the Python work around the calls is less (about a third of it).
"""

from __future__ import annotations

import ctypes
import math
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from .units import CoSimUnit

_DOUBLE_P = ctypes.POINTER(ctypes.c_double)


def applies(units: dict[str, Any], *, order: str, extrapolation: bool, signals: dict) -> bool:
    """Whether :class:`FlatLoop` can run this co-simulation."""
    if order not in ("jacobi", "gauss-seidel") or extrapolation or signals:
        return False
    for unit in units.values():
        if type(unit) is not CoSimUnit:
            return False
        raw = unit._raw
        if (unit.info.fmi_version == 2 and "step" not in raw) \
                or (len(unit.input_names) and "set" not in raw) \
                or (len(unit.output_names) and "get" not in raw):
            return False
    return True


def _array_call(raw: Any, fmi_version: int) -> Any:
    """``f(instance, refs, n, values)`` for FMI 2.0 ``fmi2Set/GetReal`` and FMI 3.0
    ``fmi3Set/GetFloat64`` (which also take the number of values)."""
    if raw is None or fmi_version == 2:
        return raw
    return lambda inst, refs, n, values: raw(inst, refs, n, values, n)


class _Element(NamedTuple):
    """One unit as the loop calls it: its buffers, value references and C functions."""

    name: str
    unit: CoSimUnit
    gather: np.ndarray          # positions of its inputs in z
    in_buf: np.ndarray          # the unit's input buffer ...
    in_refs: Any                # ... their value references, count and C pointer
    n_in: int
    in_ptr: Any
    out_refs: Any               # output value references, count, C pointer into z
    n_out: int
    out_ptr: Any
    set: Any                    # f(instance, refs, n, values): fmi2SetReal/fmi3SetFloat64
    get: Any                    # the same for the getters
    step: Any                   # fmi2DoStep, or None (FMI 3.0 steps through the unit)


class FlatLoop:
    """The loop state: ``z`` = [outputs of every element (in ``names`` order), start values
    of every element's inputs]; per element the gather indices of its inputs in ``z``.

    gather: element -> [(source element, its output positions, our input positions)], as
    the master builds it; feed_order: the elements whose outputs are re-evaluated after a
    step (``propagate``), in order; extra: element -> extra recorded variable names.
    """

    def __init__(self, units: dict[str, CoSimUnit], names: list[str],
                 start_u: dict[str, np.ndarray], gather: dict[str, list],
                 feed_order: list[str], extra: dict[str, list[str]]) -> None:
        self.units = units
        self.names = names
        self.feed_order = feed_order
        self.extra = extra
        n_y = sum(len(units[n].output_names) for n in names)
        n_u = sum(len(units[n].input_names) for n in names)
        self.z = z = np.zeros(n_y + n_u)
        self.n_y = n_y
        self.y: dict[str, np.ndarray] = {}          # views of z
        self.idx: dict[str, np.ndarray] = {}
        y_off, u_off = {}, n_y
        off = 0
        for n in names:
            m = len(units[n].output_names)
            y_off[n] = off
            self.y[n] = z[off:off + m]
            off += m
        for n in names:
            m = len(units[n].input_names)
            z[u_off:u_off + m] = start_u[n]
            idx = np.arange(u_off, u_off + m)
            for src, from_pos, to_pos in gather[n]:
                idx[to_pos] = y_off[src] + np.asarray(from_pos, dtype=int)
            self.idx[n] = idx
            u_off += m
        base = z.ctypes.data
        self.calls: list[_Element] = []
        for n in names:
            unit = units[n]
            raw, version = unit._raw, unit.info.fmi_version
            self.calls.append(_Element(
                n, unit, self.idx[n], unit._u_buf, unit._u_vr, len(unit.input_names),
                unit._u_ptr, unit._y_vr, len(unit.output_names),
                ctypes.cast(base + 8 * y_off[n], _DOUBLE_P), _array_call(raw.get("set"), version),
                _array_call(raw.get("get"), version), raw.get("step") if version == 2 else None))
        self.by_name = {c.name: c for c in self.calls}
        # a recorded row: per element its inputs, its outputs, then its extra variables
        row_idx, self.extra_cols = [], []
        col = 0
        for n in names:
            m_u, m_y = len(units[n].input_names), len(units[n].output_names)
            row_idx += [self.idx[n], np.arange(y_off[n], y_off[n] + m_y)]
            col += m_u + m_y
            if extra[n]:
                self.extra_cols.append((n, col, col + len(extra[n])))
                col += len(extra[n])
        self.row_idx = np.concatenate(row_idx) if row_idx else np.zeros(0, dtype=int)
        self.direct = not self.extra_cols
        if not self.direct:
            self.row_pos = np.concatenate(
                [np.arange(a, b) for a, b in self._own_cols(col)]) if col else np.zeros(0, int)

    def _own_cols(self, width: int) -> list[tuple[int, int]]:
        """Column ranges of the inputs and outputs (everything but the extra variables)."""
        spans, start = [], 0
        for _, a, b in self.extra_cols:
            spans.append((start, a))
            start = b
        spans.append((start, width))
        return spans

    def load(self, y: dict[str, np.ndarray]) -> None:
        """Start from the outputs ``y`` (element -> values) read by the master."""
        for n in self.names:
            self.y[n][:] = y[n]

    def _set(self, el: _Element, u: np.ndarray) -> None:
        if not el.n_in:
            return
        el.in_buf[:] = u
        if el.set(el.unit.fmu.component, el.in_refs, el.n_in, el.in_ptr) > 1:
            el.unit.set_inputs(u)                    # raises with the FMU's messages

    def _get(self, el: _Element) -> None:
        if el.n_out and el.get(el.unit.fmu.component, el.out_refs, el.n_out, el.out_ptr) > 1:
            self.y[el.name][:] = el.unit.get_outputs()   # raises with the FMU's messages

    def propagate(self, last: dict[str, np.ndarray]) -> None:
        """Re-evaluate the feedthrough outputs with the inputs of this instant (as
        ``propagate_outputs`` of the general loop: only where an input changed)."""
        z, by_name = self.z, self.by_name
        for name in self.feed_order:
            el = by_name[name]
            u = z.take(el.gather)
            if u.tolist() != last[name].tolist():
                self._set(el, u)
                last[name] = u
                self._get(el)

    def record(self, data: np.ndarray, row: int) -> None:
        """Row ``row`` of ``data``: every element's inputs, outputs and extra variables."""
        if self.direct:
            self.z.take(self.row_idx, out=data[row])
            return
        data[row, self.row_pos] = self.z[self.row_idx]
        for n, a, b in self.extra_cols:
            data[row, a:b] = self.units[n].get(self.extra[n])

    def _step(self, el: _Element, t: float, h: float, last: dict[str, np.ndarray]) -> bool:
        """Set the element's inputs from ``z`` and step it from ``t`` to ``t + h``; True when
        the step did not succeed (the unit then says whether it terminated)."""
        unit, buf = el.unit, el.in_buf
        if el.n_in:
            self.z.take(el.gather, out=buf)
            if el.set(unit.fmu.component, el.in_refs, el.n_in, el.in_ptr) > 1:
                unit.set_inputs(buf.copy())          # raises with the FMU's messages
        last[el.name] = buf.copy()
        unit.time = t
        if el.step is None:                          # FMI 3.0: early returns, terminate
            unit._step3(t, h)
            return unit.terminated
        status = el.step(unit.fmu.component, t, h, 1)
        if status <= 1:
            unit.time = t + h
            return False
        from fmpy.fmi1 import FMICallException

        unit.step_failed(FMICallException(function="fmi2DoStep", status=status), t)
        return True

    def run(self, t0: float, h: float, n_steps: int, every: int, propagate: bool,
            last: dict[str, np.ndarray], data: np.ndarray, times: np.ndarray, row: int,
            check: Callable[[dict[str, np.ndarray], float], None], always_check: bool, *,
            sequence: list[str] | None = None, feedthrough: set[str] = frozenset()
            ) -> tuple[int, Any]:
        """Macro steps 0..n_steps-1 from the state after the first recorded point; fills
        ``data`` and ``times`` from ``row`` on. ``check(y, t)`` raises for diverging outputs
        (called when an output is not finite, at every step when ``always_check``).
        ``sequence``: Gauss-Seidel order (None: Jacobi); ``feedthrough``: the elements
        whose outputs are re-evaluated right after their step in Gauss-Seidel order.
        Returns the next row and the ``terminated`` record (None when all ran to the end)."""
        z, calls = self.z, self.calls
        z_y = z[:self.n_y]
        step_one, get_one = self._step, self._get
        ordered = [self.by_name[n] for n in sequence] if sequence is not None else None
        for k in range(n_steps):
            t = t0 + k * h
            failed = False
            if ordered is None:                      # Jacobi: all step, then all are read
                for el in calls:
                    failed = step_one(el, t, h, last) or failed
                for el in calls:
                    get_one(el)
            else:                                    # Gauss-Seidel: each reads the newest
                for el in ordered:
                    failed = step_one(el, t, h, last) or failed
                    get_one(el)
                    if propagate and el.name in feedthrough:
                        u = z.take(el.gather)
                        self._set(el, u)
                        last[el.name] = u
                        get_one(el)
            if propagate:
                self.propagate(last)
            if failed:
                stopped = [n for n in self.names if self.units[n].terminated]
                if stopped:
                    first = min(stopped, key=lambda n: self.units[n].time)
                    terminated = {"element": first, "time": self.units[first].time,
                                  "reason": self.units[first].stop_reason}
                    self.record(data, row)
                    times[row] = self.units[first].time
                    return row + 1, terminated
            if always_check or not math.isfinite(z_y.sum()):    # one sum: any inf or NaN
                check(self.y, t)
            if (k + 1) % every == 0 or k + 1 == n_steps:
                self.record(data, row)
                times[row] = t0 + (k + 1) * h
                row += 1
        return row, None
