"""Checks of a co-simulation experiment: finite times, the macro step count, the order."""

from __future__ import annotations

import math
from typing import Any

from .errors import InvalidExperimentError, SetupError

ORDERS = ("jacobi", "gauss-seidel")
MAX_STEPS = 100_000_000              # macro steps of one run (1e8: hours of FMU calls)


def _finite(value: Any, what: str) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InvalidExperimentError(f"{what} {value!r} is not a number") from None
    if not math.isfinite(x):
        raise InvalidExperimentError(f"{what} {x} is not finite")
    return x


def count_steps(start_time: Any, stop_time: Any, step: Any,
                max_steps: int | None = None) -> int:
    """The number of macro steps ``step`` from ``start_time`` to ``stop_time``; raises
    :class:`~.errors.InvalidExperimentError` unless all are finite, ``step > 0``, the
    horizon positive and a multiple of the step, and the count at most ``max_steps``
    (default :data:`MAX_STEPS`)."""
    t0 = _finite(start_time, "start time")
    t1 = _finite(stop_time, "stop time")
    h = _finite(step, "macro step")
    limit = MAX_STEPS if max_steps is None else int(max_steps)
    if not h > 0:
        raise InvalidExperimentError(f"macro step must be > 0, got {h:g}")
    span = t1 - t0
    if not span > 0 or not math.isfinite(span):
        raise InvalidExperimentError(f"stop time {t1:g} must be after the start time {t0:g}")
    ratio = span / h
    if not math.isfinite(ratio) or ratio > limit + 0.5:
        raise InvalidExperimentError(
            f"the horizon {span:g} s at macro step {h:g} s needs {ratio:.4g} macro steps, "
            f"more than the limit of {limit:.4g} (a wrong unit or a typo in the stop time or "
            "step? Master.simulate(max_steps=...) allows more)")
    n_steps = int(round(ratio))
    if n_steps < 1 or abs(n_steps * h - span) > 1e-9 * max(1.0, span):
        raise InvalidExperimentError(f"the horizon {span:g} s is not a multiple of the macro "
                                     f"step {h:g} s")
    return n_steps


def _norm_order(order: str) -> str:
    o = str(order).lower().replace("_", "-")
    if o in ("gs", "gauss-seidel", "gaussseidel", "seidel", "sequential"):
        return "gauss-seidel"
    if o in ("jacobi", "parallel"):
        return "jacobi"
    raise SetupError(f"order must be 'jacobi' or 'gauss-seidel', not {order!r}")
