"""Slopes of the cubic Hermite splines of the MSL tables (``Modelica.Blocks.Types.Smoothness``).

Each rule maps strictly increasing abscissae ``x`` and ordinates ``y`` (same length n >= 2)
to the spline's derivative ``dy/dx`` at every point; the interpolant on ``[x[i], x[i+1]]`` is
the cubic with values and derivatives given at both ends. Two points give the straight line.

- Akima (``ContinuousDerivative``): Akima's weighted mean of neighbouring secants, with the
  secants continued linearly by two on each end (Akima 1970); three points give the parabola
  through them.
- Modified Akima (``ModifiedContinuousDerivative``): the same with the weights
  ``|d[i+1]-d[i]| + |d[i+1]+d[i]|/2`` that avoid overshoot on flat parts.
- Fritsch–Butland (``MonotoneContinuousDerivative1``): weighted harmonic mean of the two
  secants (zero at local extrema), end slopes equal to the end secants.
- Steffen (``MonotoneContinuousDerivative2``): Steffen's (1990) limited slopes, end slopes
  equal to the end secants.
"""

from __future__ import annotations

import numpy as np


def _secants(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    h = np.diff(x)
    return h, np.diff(y) / h


def _parabola(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Derivatives of the parabola through three points."""
    h, d = _secants(x, y)
    curv = (d[1] - d[0]) / (x[2] - x[0])          # half the second derivative
    return np.array([d[0] - curv * h[0], d[0] + curv * h[0], d[1] + curv * h[1]])


def _akima(x: np.ndarray, y: np.ndarray, modified: bool) -> np.ndarray:
    n = x.size
    if n == 2:
        return np.full(2, (y[1] - y[0]) / (x[1] - x[0]))
    if n == 3 and not modified:
        return _parabola(x, y)
    _, d = _secants(x, y)
    m = np.empty(n + 3)
    m[2:n + 1] = d
    m[1] = 2.0 * m[2] - m[3]
    m[0] = 2.0 * m[1] - m[2]
    m[n + 1] = 2.0 * m[n] - m[n - 1]
    m[n + 2] = 2.0 * m[n + 1] - m[n]
    w1 = np.abs(m[3:] - m[2:-1])                  # weight of the left secant m[i+1]
    w2 = np.abs(m[1:-2] - m[:-3])                 # weight of the right secant m[i+2]
    if modified:
        w1 = w1 + 0.5 * np.abs(m[3:] + m[2:-1])
        w2 = w2 + 0.5 * np.abs(m[1:-2] + m[:-3])
    left, right = m[1:-2], m[2:-1]
    total = w1 + w2
    scale = max(float(np.max(np.abs(d))), 1.0)
    flat = total <= 1e-12 * scale
    safe = np.where(flat, 1.0, total)
    return np.where(flat, 0.5 * (left + right), (w1 * left + w2 * right) / safe)


def akima(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Akima slopes."""
    return _akima(x, y, modified=False)


def modified_akima(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Modified Akima slopes."""
    return _akima(x, y, modified=True)


def fritsch_butland(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Fritsch–Butland slopes (monotonicity preserving)."""
    h, d = _secants(x, y)
    c = np.empty(x.size)
    c[0], c[-1] = d[0], d[-1]
    for i in range(1, x.size - 1):
        d0, d1 = d[i - 1], d[i]
        if d0 * d1 <= 0.0:
            c[i] = 0.0
        else:
            w0, w1 = 2.0 * h[i] + h[i - 1], h[i] + 2.0 * h[i - 1]
            c[i] = (w0 + w1) / (w0 / d0 + w1 / d1)
    return c


def steffen(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Steffen slopes (monotonicity preserving, no overshoot)."""
    h, d = _secants(x, y)
    c = np.empty(x.size)
    c[0], c[-1] = d[0], d[-1]
    for i in range(1, x.size - 1):
        d0, d1 = d[i - 1], d[i]
        p = (d0 * h[i] + d1 * h[i - 1]) / (h[i - 1] + h[i])
        c[i] = (np.sign(d0) + np.sign(d1)) * min(abs(d0), abs(d1), 0.5 * abs(p))
    return c
