"""One interpolated table column as a piecewise cubic polynomial, numeric and symbolic.

A :class:`Curve` holds pieces ``k`` valid on ``[starts[k], starts[k+1])`` (right-continuous,
so a repeated abscissa is a jump whose later row holds from that point) with
``y = p0 + s*(p1 + s*(p2 + s*p3))``, ``s = u - bases[k]``. The pieces cover the table's
interpolation (constant, linear or cubic Hermite) and the extrapolation outside it
(``HoldLastPoint``, ``LastTwoPoints``; ``Periodic`` maps ``u`` into the table range).
Evaluation gives the value or its first or second derivative at a number (optionally the
left limit, for a jump approached from below) or, for a symbolic ``u`` (an expression of
:mod:`bgmodelica.core.expr` or a CasADi SX/MX), the same piecewise formula as an expression.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from ...core.expr import Expr, Op, if_else
from . import hermite
from .errors import ExtrapolationError

#: Modelica.Blocks.Types.Smoothness
LINEAR, AKIMA, CONSTANT, FRITSCH_BUTLAND, STEFFEN, MODIFIED_AKIMA = range(1, 7)
#: Modelica.Blocks.Types.Extrapolation
HOLD, LAST_TWO, PERIODIC, NO_EXTRAPOLATION = range(1, 5)

SMOOTHNESS_NAMES = {LINEAR: "LinearSegments", AKIMA: "ContinuousDerivative",
                    CONSTANT: "ConstantSegments", FRITSCH_BUTLAND: "MonotoneContinuousDerivative1",
                    STEFFEN: "MonotoneContinuousDerivative2",
                    MODIFIED_AKIMA: "ModifiedContinuousDerivative"}
EXTRAPOLATION_NAMES = {HOLD: "HoldLastPoint", LAST_TWO: "LastTwoPoints", PERIODIC: "Periodic",
                       NO_EXTRAPOLATION: "NoExtrapolation"}
_SLOPES = {AKIMA: hermite.akima, FRITSCH_BUTLAND: hermite.fritsch_butland,
           STEFFEN: hermite.steffen, MODIFIED_AKIMA: hermite.modified_akima}


def is_symbolic(u: Any) -> bool:
    """Whether ``u`` is an expression (bgmodelica or CasADi symbolic) rather than a number."""
    if isinstance(u, Expr):
        return True
    if isinstance(u, (ca.SX, ca.MX)):
        return not u.is_constant()
    return False


def floor(u: Any) -> Any:
    """Largest integer not above ``u`` (number, expression or CasADi), without event."""
    if isinstance(u, Expr):
        return Op("floor", (u,))
    if isinstance(u, (ca.SX, ca.MX, ca.DM)):
        return ca.floor(u)
    return float(math.floor(u))


def _pieces(x: np.ndarray, y: np.ndarray, smoothness: int) -> list[tuple[float, float, tuple]]:
    """Interior pieces ``(start, base, (p0, p1, p2, p3))``; zero-length intervals dropped."""
    out = []
    slopes = _SLOPES[smoothness](x, y) if smoothness in _SLOPES else None
    for i in range(x.size - 1):
        h = x[i + 1] - x[i]
        if h == 0.0:
            continue
        if smoothness == CONSTANT:
            coef = (y[i], 0.0, 0.0, 0.0)
        elif slopes is None:
            coef = (y[i], (y[i + 1] - y[i]) / h, 0.0, 0.0)
        else:
            d = (y[i + 1] - y[i]) / h
            c0, c1 = slopes[i], slopes[i + 1]
            coef = (y[i], c0, (3.0 * d - 2.0 * c0 - c1) / h, (c0 + c1 - 2.0 * d) / h ** 2)
        out.append((float(x[i]), float(x[i]), tuple(float(c) for c in coef)))
    return out


def _end_slopes(x: np.ndarray, y: np.ndarray, smoothness: int) -> tuple[float, float]:
    """Slopes continued outside the table by ``LastTwoPoints``: the secants through the first
    and last two distinct points for constant and linear segments, else the spline's end
    derivatives."""
    if smoothness in (LINEAR, CONSTANT):
        k0 = next(i for i in range(x.size - 1) if x[i + 1] > x[i])
        k1 = next(i for i in range(x.size - 1, 0, -1) if x[i] > x[i - 1])
        return (float((y[k0 + 1] - y[k0]) / (x[k0 + 1] - x[k0])),
                float((y[k1] - y[k1 - 1]) / (x[k1] - x[k1 - 1])))
    slopes = _SLOPES[smoothness](x, y)
    return float(slopes[0]), float(slopes[-1])


@dataclass
class Curve:
    """One table column: interpolation plus extrapolation (see the module docstring).

    name: what error messages call the column (table and column number).
    x, y: abscissae and ordinates of the table rows.
    """

    name: str
    x: np.ndarray
    y: np.ndarray
    smoothness: int
    extrapolation: int

    def __post_init__(self) -> None:
        x, y = self.x, self.y
        self.u_min, self.u_max = float(x[0]), float(x[-1])
        if x.size == 1:
            self.starts = np.array([-np.inf])
            self.bases = np.array([0.0])
            self.coefs = np.array([[y[0], 0.0, 0.0, 0.0]])
            return
        pieces = _pieces(x, y, self.smoothness)
        if self.extrapolation != PERIODIC:
            s0, s1 = (0.0, 0.0) if self.extrapolation == HOLD else \
                _end_slopes(x, y, self.smoothness)
            pieces = [(-np.inf, self.u_min, (float(y[0]), s0, 0.0, 0.0)), *pieces,
                      (self.u_max, self.u_max, (float(y[-1]), s1, 0.0, 0.0))]
        self.starts = np.array([p[0] for p in pieces])
        self.bases = np.array([p[1] for p in pieces])
        self.coefs = np.array([p[2] for p in pieces])

    @property
    def period(self) -> float:
        """Length of the abscissa range (the period of ``Periodic`` extrapolation)."""
        return self.u_max - self.u_min

    # -- numbers ----------------------------------------------------------------------------

    def evaluate(self, u: float, order: int = 0, left: bool = False,
                 snap: float = 0.0) -> float:
        """Value (``order`` 0) or derivative (1, 2) at ``u``; ``left``: the left limit;
        ``snap``: an abscissa this close to a table point is taken as that point."""
        u = float(u)
        if self.x.size > 1:
            if self.extrapolation == PERIODIC:
                u = self.u_min + (u - self.u_min) % self.period
            if snap > 0.0:
                j = int(np.argmin(np.abs(self.x - u)))
                if abs(self.x[j] - u) <= snap:
                    u = float(self.x[j])
            if self.extrapolation == PERIODIC:
                if left and u <= self.u_min:
                    u = self.u_max
                elif not left and u >= self.u_max:
                    u = self.u_min
            elif self.extrapolation == NO_EXTRAPOLATION and not \
                    self.u_min <= u <= self.u_max:
                raise ExtrapolationError(
                    f"{self.name}: abscissa {u:g} outside the table range "
                    f"[{self.u_min:g}, {self.u_max:g}] and extrapolation = NoExtrapolation")
        k = int(np.searchsorted(self.starts, u, side="left" if left else "right")) - 1
        k = min(max(k, 0), len(self.starts) - 1)
        return float(_poly(self.coefs[k], u - float(self.bases[k]), order))

    # -- expressions ------------------------------------------------------------------------

    def symbolic(self, u: Any, order: int = 0) -> Any:
        """The piecewise formula of :meth:`evaluate` (right-continuous) for a symbolic ``u``.
        ``NoExtrapolation`` continues the end slopes: check :attr:`u_min`/:attr:`u_max`."""
        if self.x.size > 1 and self.extrapolation == PERIODIC:
            u = u - self.period * floor((u - self.u_min) / self.period)

        def build(lo: int, hi: int) -> Any:       # balanced: depth log2(pieces)
            if lo == hi:
                return _poly(self.coefs[lo], u - float(self.bases[lo]), order)
            mid = (lo + hi + 1) // 2
            return if_else(u < float(self.starts[mid]), build(lo, mid - 1), build(mid, hi))

        return build(0, len(self.starts) - 1)


def _poly(c: np.ndarray, s: Any, order: int) -> Any:
    """``order``-th derivative of ``c0 + c1 s + c2 s^2 + c3 s^3`` at ``s`` (Horner)."""
    c0, c1, c2, c3 = (float(v) for v in c)
    if order == 0:
        if c2 == 0.0 and c3 == 0.0:
            return c0 if c1 == 0.0 else c0 + c1 * s
        return c0 + s * (c1 + s * (c2 + s * c3))
    if order == 1:
        if c2 == 0.0 and c3 == 0.0:
            return c1
        return c1 + s * (2.0 * c2 + s * (3.0 * c3))
    if order == 2:
        return 2.0 * c2 + 6.0 * c3 * s if c3 != 0.0 else 2.0 * c2
    raise ValueError(f"derivative order {order} not available (0, 1 or 2)")
