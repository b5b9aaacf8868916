"""Time signals for unconnected inputs of a co-simulation (``Master.simulate(inputs=...)``,
``bgmodelica simulate-fmu --input``): tables of (time, value), linear between rows, a
repeated time a jump, the end values held."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from .checks import Plan
from .errors import InvalidExperimentError, SetupError, UnknownConnectorError


def _signal(times: np.ndarray, values: np.ndarray) -> Any:
    """f(t): linear between breakpoints, a repeated time a jump (the later value from that
    instant), the first/last value held outside. A macro step [t, t+h] ramps from f(t) to
    the left limit f(t+h-), so a jump on the communication grid is taken exactly."""
    last = len(times) - 1

    def f(t: float, left: bool = False) -> float:
        """The value at ``t``; ``left``: the limit from the left (before a jump at t)."""
        k = int(np.searchsorted(times, t, side="left" if left else "right")) - 1
        if k < 0:
            return float(values[0])
        if k >= last:
            return float(values[last])
        t0, t1 = times[k], times[k + 1]
        return float(values[k] + (values[k + 1] - values[k]) * (t - t0) / (t1 - t0))

    return f


def input_signals(inputs: Mapping[str, tuple[Any, Any]], plan: Plan,
                   src_index: Mapping[str, list]) -> dict[str, list[tuple[int, Any]]]:
    """element -> [(input position, f(t))] for the unconnected inputs given signals."""
    out: dict[str, list[tuple[int, Any]]] = {}
    for full, (times, values) in inputs.items():
        el, _, name = full.partition(".")
        if el not in plan.inputs or name not in plan.inputs[el]:
            known = [f"{e}.{u}" for e in plan.inputs for u in plan.inputs[e]]
            raise UnknownConnectorError(f"input signal {full!r}: no such input (inputs: "
                                        f"{', '.join(known) or 'none'})")
        j = plan.inputs[el].index(name)
        if src_index[el][j] is not None:
            raise SetupError(f"input signal {full!r}: the input is connected to an output")
        t_arr = np.asarray(times, dtype=float).ravel()
        v_arr = np.asarray(values, dtype=float).ravel()
        if t_arr.size == 0 or t_arr.size != v_arr.size or np.any(np.diff(t_arr) < 0) \
                or not (np.all(np.isfinite(t_arr)) and np.all(np.isfinite(v_arr))):
            raise InvalidExperimentError(f"input signal {full!r}: needs as many finite times "
                                         "(non-decreasing) as values")
        out.setdefault(el, []).append((j, _signal(t_arr, v_arr)))
    return out
