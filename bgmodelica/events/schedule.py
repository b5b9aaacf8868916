"""Time events known in advance: ``sample`` clocks, relations on time alone and table
breakpoints. Every instant is computed from its definition (``start + k*interval``, the root
of an affine indicator, a breakpoint), never accumulated, so it is hit exactly."""

from __future__ import annotations

import math

import numpy as np

from ..core.flatmodel import FlatTable


def next_sample(start: float, interval: float, t: float) -> float:
    """First instant ``start + k*interval`` (k >= 0) strictly after ``t``."""
    if t < start:
        return start
    k = math.floor((t - start) / interval) + 1
    out = start + k * interval
    while out <= t:
        k += 1
        out = start + k * interval
    prev = start + (k - 1) * interval
    return prev if prev > t else out


def is_sample_instant(start: float, interval: float, t: float) -> bool:
    """Whether ``t`` is one of the instants of ``sample(start, interval)``."""
    if t < start - 1e-12 * max(1.0, abs(t)):
        return False
    k = round((t - start) / interval)
    return k >= 0 and abs(start + k * interval - t) <= 1e-12 * max(1.0, abs(t), interval)


def table_coefficients(table: FlatTable, t: float) -> tuple[float, float, float]:
    """``(c0, c1, next breakpoint)``: the table equals ``c0 + c1*time`` from ``t`` (right
    limit) up to the next breakpoint after ``t`` (inf if none).

    A time within a few ulps of a breakpoint counts as the breakpoint itself: event times
    of periodic tables (``breakpoint + n*period``) are computed in floating point."""
    times = np.asarray(table.times)
    values = np.asarray(table.values)
    t0, t1 = float(times[0]), float(times[-1])
    eps = 1e-12 * max(1.0, abs(t), abs(t1 - t0))
    shift = 0.0
    local = t
    if table.extrapolation == "periodic" and (t < t0 - eps or t >= t1 - eps):
        period = t1 - t0
        n = math.floor((t - t0) / period + eps / period)
        shift = n * period
        local = t - shift
    i = int(np.searchsorted(times, local + eps, side="right"))   # times[i-1] <= local
    n_pts = len(times)
    if i == 0:                                                 # before the table
        nxt = t0 + shift
        if table.extrapolation == "linear" and n_pts > 1 and table.interpolation == "linear":
            c0, c1 = _segment(times, values, 0, 1)
        else:
            c0, c1 = float(values[0]), 0.0
    elif i >= n_pts:                                           # after the table
        nxt = math.inf
        if table.extrapolation == "linear" and n_pts > 1 and table.interpolation == "linear":
            c0, c1 = _segment(times, values, n_pts - 2, n_pts - 1)
        else:
            c0, c1 = float(values[-1]), 0.0
    else:
        nxt = float(times[i]) + shift
        if table.interpolation == "hold":
            c0, c1 = float(values[i - 1]), 0.0
        else:
            c0, c1 = _segment(times, values, i - 1, i)
    if table.extrapolation == "periodic" and nxt == math.inf:
        nxt = t0 + shift + (t1 - t0)
    return c0 - c1 * shift, c1, nxt


def _segment(times: np.ndarray, values: np.ndarray, a: int, b: int) -> tuple[float, float]:
    dt = float(times[b] - times[a])
    if dt <= 0.0:
        return float(values[b]), 0.0
    c1 = float(values[b] - values[a]) / dt
    return float(values[a]) - c1 * float(times[a]), c1
