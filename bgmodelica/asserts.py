"""Model assertions (Modelica ``assert``) checked on a simulation's results.

A violated assertion stops the run: :class:`~bgmodelica.errors.AssertionViolation` names the
message, the element that states it and the first output time at which the condition is
false, with the rows before it in ``.result``. Warnings (``level="warning"``) are reported
with :class:`AssertionWarning` and the run goes on. Conditions are checked at the output
points, on the values recorded there.
"""

from __future__ import annotations

import warnings
from typing import Any

import casadi as ca
import numpy as np

from .errors import AssertionViolation


class AssertionWarning(UserWarning):
    """A model assertion of level warning is false."""


def check_asserts(compiled: Any, result: Any) -> None:
    """Raise :class:`AssertionViolation` at the first output point where an assertion of
    ``compiled`` is false in ``result`` (assertions reading quantities the result does not
    hold are skipped)."""
    asserts = model_asserts(compiled)
    if not asserts or not len(result.time):
        return
    first: tuple[float, Any] | None = None
    for a in asserts:
        args = [_column(result, n) for n in a.names]
        if any(v is None for v in args):
            continue
        fn = ca.Function("assertion", a.symbols, [a.condition])
        n = len(result.time)
        cols = [np.broadcast_to(np.asarray(v, dtype=float), (n,)) for v in args]
        ok = np.asarray(fn.map(n)(*[c.reshape(1, -1) for c in cols])).ravel() != 0 \
            if a.symbols else np.full(n, bool(float(ca.evalf(a.condition))))
        bad = np.nonzero(~ok)[0]
        if not bad.size:
            continue
        k = int(bad[0])
        if a.level == "warning":
            warnings.warn(f"assert at t = {result.time[k]:g} s [{a.where}]: {a.message}",
                          AssertionWarning, stacklevel=3)
            continue
        if first is None or result.time[k] < first[0]:
            first = (float(result.time[k]), a, k)
    if first is not None:
        t, a, k = first
        raise AssertionViolation(f"assert failed at t = {t:g} s [{a.where}]: {a.message}",
                                 t, _rows_before(result, k))


def _rows_before(result: Any, k: int) -> Any:
    from .result import Result

    return Result(result.time[:k], result.values[:k], list(result.names), dict(result.aliases),
                  dict(result.parameters), dict(result.units), dict(result.meta))


def model_asserts(compiled: Any) -> list:
    """The assertions of a compiled model (none for models without)."""
    flat = vars(compiled).get("flat")       # not made on demand: array-path models have none
    return list(getattr(flat, "asserts", None) or [])


def _column(result: Any, name: str) -> Any:
    if name == "time":
        return result.time
    try:
        return result[name]
    except (KeyError, ValueError):
        pass
    params = getattr(result, "parameters", None) or {}
    return params.get(name)
