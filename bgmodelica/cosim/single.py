"""Simulate one FMU (any FMI 2.0/3.0 Co-Simulation or Model Exchange FMU) with the master:
``bgmodelica simulate-fmu FMU ...`` and :func:`simulate_fmu`.

The result has the same conventions as :func:`bgmodelica.simulate`: a ``time`` column and one
column per variable under the FMU's own names (array elements as ``x[1]``...), Booleans as
0/1; String and Binary variables are in ``result.text`` (``str``, ``bytes``). Inputs come
from a CSV (``time`` first, one column per input; linear between rows, a repeated time is a
jump, the last row held) or a mapping ``{name: (times, values)}``; inputs
without data keep their start values.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from ..result import Result
from .errors import InvalidExperimentError, UnknownConnectorError
from .fmu import read_fmu_info
from .master import Master
from .ssp import system_from_fmus

ELEMENT = "fmu"


def _experiment(md: Any) -> tuple[float | None, float | None, float | None]:
    de = getattr(md, "defaultExperiment", None)
    if de is None:
        return None, None, None

    def num(x: Any) -> float | None:
        try:
            return float(x) if x is not None else None
        except (TypeError, ValueError):
            return None

    return num(de.startTime), num(de.stopTime), num(de.stepSize)


def simulate_fmu(fmu: str | Path, *, stop_time: float | None = None,
                 interval: float | None = None, start_time: float | None = None,
                 parameters: Mapping[str, Any] | None = None, inputs: Any = None,
                 interface: str = "auto", rtol: float = 1e-8, atol: float = 1e-10,
                 record: Iterable[str] | None = None,
                 euler_step: float | None = None) -> Result:
    """Simulate the FMU at ``fmu`` from ``start_time`` to ``stop_time`` [s] (defaults: its
    DefaultExperiment, else 0 and 1 s) with results every ``interval`` [s] (default: its
    step size, else 1/500 of the horizon), which is also the communication step.

    ``parameters``: name -> value for parameters and input start values of any type.
    ``inputs``: CSV path or ``{name: (times, values)}``. ``interface``: ``"cs"``, ``"me"``
    (the master's integrator with events, tolerances ``rtol``/``atol``) or ``"auto"`` (CS
    when the FMU has it); ``rtol`` also goes to the FMU as its experiment tolerance (the
    embedded solver of a Co-Simulation FMU may use it). ``record``: variables to record
    besides the outputs (default: the continuous states). ``euler_step``: Model Exchange
    with forward Euler at this fixed step instead of the error-controlled Radau.
    """
    info = read_fmu_info(fmu)
    md = info.description
    t_start, t_stop, step = _experiment(md)
    t0 = start_time if start_time is not None else (t_start or 0.0)
    t1 = stop_time if stop_time is not None else (t_stop if t_stop is not None else 1.0)
    if not t1 > t0:
        raise InvalidExperimentError(f"stop time {t1:g} must be after the start time {t0:g}")
    h = interval if interval is not None else (step if step else (t1 - t0) / 500)
    table = {}
    if inputs is not None:
        from ..events.inputs import read_input_table

        table = read_input_table(inputs)
    for name in table:
        var = info.variables.get(name)
        if var is None or var.causality != "input":
            known = ", ".join(v.name for v in info.inputs) or "none"
            raise UnknownConnectorError(f"input data for {name!r}: {info.path.name} has no "
                                        f"such input (inputs: {known})")
    if record is None:
        state_names = {str(d.variable.derivative.name) for d in md.derivatives
                       if getattr(d.variable, "derivative", None) is not None}
        extra = [n for n, v in info.variables.items()
                 if (v.base or n) in state_names and v.causality not in ("output", "input")]
    else:
        extra = [n for n in record if info.variable(n).causality != "output"]
    for name in extra:
        info.variable(name)
    system = system_from_fmus(info.model_name, {ELEMENT: info.path}, [])
    master = Master(system, interface=interface, allow_unconnected=True, me_rtol=rtol,
                    me_atol=atol, me_euler_step=euler_step)
    result = master.simulate(t1, h, start_time=t0,
                             parameters={ELEMENT: dict(parameters or {})},
                             record=[f"{ELEMENT}.{n}" for n in extra],
                             inputs={f"{ELEMENT}.{k}": v for k, v in table.items()},
                             tolerance=rtol)
    prefix = ELEMENT + "."
    columns = [n[len(prefix):] for n in result.names]
    meta = dict(result.meta)
    meta["fmu"] = str(info.path)
    meta["model"] = info.model_name
    if meta.get("terminated"):
        meta["terminated"] = {k: v for k, v in meta["terminated"].items() if k != "element"}
    if "events" in meta:
        meta["events"] = meta["events"].get(ELEMENT, [])
    return Result(result.time, result.values, columns,
                  parameters={k[len(prefix):]: v for k, v in result.parameters.items()},
                  units={k[len(prefix):]: v for k, v in result.units.items()}, meta=meta,
                  text={k[len(prefix):]: v for k, v in result.text.items()})
