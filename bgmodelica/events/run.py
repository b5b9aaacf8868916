"""``simulate`` for hybrid models: run the event loop and package a :class:`Result`."""

from __future__ import annotations

import time as _time
from typing import Any

import numpy as np

from ..backends.casadi_dae import CasadiDAE
from ..errors import SimulationError
from ..result import Result
from .inputs import with_input_tables
from .loop import HybridSimulator
from .selection import Selection


def simulate_hybrid(compiled, dae: CasadiDAE, p: np.ndarray, grid: np.ndarray, *, rtol: float,
                    atol: float, max_step: float | None, max_steps: int, outputs, inputs: Any,
                    t_start: float, selection: Selection | None = None,
                    progress=None, solver_options: dict | None = None) -> Result:
    """Simulate a model with events, time-varying inputs or dynamic state selection over the
    output ``grid``."""
    if inputs is not None:
        n_before = len(dae.discretes)
        dae = with_input_tables(dae, inputs)
        p = np.concatenate([p, np.zeros(len(dae.discretes) - n_before)])
    obs_idx = _output_indices(dae, outputs)
    if selection is not None:
        selection.selector.switches.clear()
    if selection is not None and inputs is not None:
        prepare = selection.prepare
        selection.prepare = lambda d: with_input_tables(prepare(d) if prepare else d, inputs)
    sim = HybridSimulator(dae, p, rtol, atol, max_step, max_steps, obs_idx,
                          selection=selection, solver_options=solver_options)
    times, rows, failure = sim.run(grid, progress)
    dae = sim.dae
    names = [dae.names[k] for k in obs_idx]
    kept = set(names)
    aliases = {a: rep for a, rep in dae.aliases.items() if rep[0] in kept}
    flat = compiled.declarations
    units = {v.name: v.decl.unit for v in flat.variables}
    units.update({d.name: d.decl.unit for d in flat.discretes})
    units.update({q.name: q.decl.unit for q in (*flat.parameters, *flat.inputs)})
    params_out = dae.parameter_values(sim.p)     # with those initialization solved
    meta = {"model": compiled.name, "compile_seconds": compiled.compile_time,
            "run_seconds": _time.perf_counter() - t_start,
            "timings": dict(compiled.timings), "solver": "cvodes" if not dae.z.numel()
            else "idas", "solver_choice": "auto",      # the event loop picks by structure
            "stats": dict(sim.stats), "states": list(dae.state_names),
            "init_notes": list(sim.init_notes), **sim.meta}
    if selection is not None and selection.mode == "switch":
        meta["state_switches"] = list(selection.selector.switches)
        meta["states"] = list(dae.state_names)
    values = rows if len(rows) else np.zeros((0, len(names)))
    result = Result(times, values, names, aliases, params_out, units, meta)
    if failure is not None:
        t_reached = float(times[-1]) if len(times) else float(grid[0])
        raise SimulationError(
            f"the integrator failed after t = {t_reached:g} s (last good point).\nSolver said: "
            f"{failure.strip().splitlines()[-1][:300]}", t_reached, result)
    return result


def _output_indices(dae: CasadiDAE, outputs) -> list[int]:
    from ..errors import ParameterError

    if outputs is None:
        return list(range(len(dae.names)))
    idx = []
    for n in outputs:
        name = dae.aliases[n][0] if n not in dae.observed_index and n in dae.aliases else n
        if name not in dae.observed_index:
            raise ParameterError(f"unknown output variable: {n}")
        idx.append(dae.observed_index[name])
    return sorted(set(idx))
