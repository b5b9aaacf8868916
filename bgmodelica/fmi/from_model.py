"""From a compiled model to an :class:`FmuSpec`: the explicit ODE with outputs.

Algebraic unknowns left after tearing (``z``) are solved inside the model function with
CasADi's code-generatable ``fast_newton`` rootfinder, started from their consistent initial
values, so the FMU sees ``xdot, y = ode(t, x, u, p)``.

Causality: the model's top-level ``Output`` variables are FMU outputs; the states are the FMU's
continuous states; every other variable, aliases included, is a local. Free parameters are tunable
parameters and top-level ``Input`` variables are inputs.
"""

from __future__ import annotations

from pathlib import Path

import casadi as ca
import numpy as np

from ..backends.casadi_init import initialize
from ..compiler import CompiledModel, compile
from ..core.component import Component
from ..core.variables import KIND_OUTPUT
from .export import export_fmu
from .spec import FmuSpec, FmuSpecError, ScalarVariable


def fmu_spec(model: Component | CompiledModel, *, stop_time: float = 1.0,
             step_size: float | None = None, tolerance: float = 1e-6,
             newton_tolerance: float = 1e-12) -> FmuSpec:
    """Describe a model for export (see the module docstring for the conventions)."""
    compiled = model if isinstance(model, CompiledModel) else compile(model)
    dae = compiled.dae
    if dae.hybrid is not None:
        ev = compiled.event_summary() or {}
        what = [c["relation"] for c in ev.get("conditions", [])[:3]]
        what += ["when-clauses"] * bool(ev.get("when_clauses"))
        what += ["sample clocks"] * bool(ev.get("clocks"))
        what += ["time tables"] * bool(ev.get("tables"))
        raise FmuSpecError(
            f"cannot export {compiled.name} as an FMU yet: it has events ("
            + ", ".join(what) + "); the FMU runtime does not handle events, so the FMU "
            "would be wrong. Simulate it natively, or wrap relations that need no event in "
            "no_event()")
    flat = compiled.reduced.model
    n_par = len(dae.parameters)
    p_all = dae.p_default
    init = initialize(dae, p_all)

    t = ca.MX.sym("t")
    x = ca.MX.sym("x", dae.x.numel())
    u = ca.MX.sym("u", len(dae.inputs))
    p = ca.MX.sym("p", n_par)
    pu = ca.vertcat(p, u)

    by_name = {v.name: v for v in flat.variables}
    declared_outputs = [v.name for v in flat.variables
                        if v.decl.kind == KIND_OUTPUT and v.component == "" and v.der_of < 0]
    # top-level outputs removed by alias elimination (e.g. ``y == some.state``) stay outputs
    top_decls = {n: s.decl for n, s in getattr(compiled.source, "_symbols", {}).items()}
    declared_outputs += [n for n, d in top_decls.items()
                         if d.kind == KIND_OUTPUT and n in flat.aliases
                         and flat.aliases[n][0] in dae.observed_index]
    states = set(dae.state_names)
    output_names = [n for n in declared_outputs if n not in states]
    taken = states | set(output_names)
    local_names = [n for n in dae.names if by_name[n].der_of < 0 and n not in taken]
    alias_names = [a for a, (rep, _) in sorted(flat.aliases.items())
                   if rep in dae.observed_index and by_name[rep].der_of < 0
                   and not a.startswith("der(") and a not in taken]

    def observed(n: str) -> ca.SX:
        # a declared output may be an alias (e.g. of a state): export it as an output anyway
        if n in dae.observed_index:
            return dae.observed[dae.observed_index[n]]
        rep, sign = flat.aliases[n]
        return sign * dae.observed[dae.observed_index[rep]]

    y_sx = ca.vertcat(*[observed(n) for n in output_names + local_names + alias_names])
    f_sx = ca.Function("model", [dae.t, dae.x, dae.z, dae.p], [dae.ode, y_sx])
    if dae.z.numel():
        g = ca.Function("g", [dae.z, ca.vertcat(dae.t, dae.x, dae.p)], [dae.alg])
        solver = ca.rootfinder("loops", "fast_newton", g,
                               {"abstol": newton_tolerance, "max_iter": 50})
        z = solver(ca.DM(init.z0), ca.vertcat(t, x, pu))
    else:
        z = ca.MX(0, 1)
    xdot, y = f_sx(t, x, z, pu)
    ode = ca.Function("ode", [t, x, u, p], [xdot, y], ["t", "x", "u", "p"], ["xdot", "y"])

    def scalar(name: str, start: float) -> ScalarVariable:
        v = by_name.get(name)
        decl = v.decl if v is not None else top_decls.get(name)
        return ScalarVariable(name, float(start), getattr(decl, "unit", "") or "",
                              getattr(decl, "description", "") or "")

    y0 = np.asarray(ca.Function("y0", [t, x, u, p], [y])(
        0.0, init.x0, p_all[n_par:], p_all[:n_par])).ravel()
    n_out = len(output_names)
    outputs = [scalar(n, y0[k]) for k, n in enumerate(output_names)]
    locals_ = [scalar(n, y0[n_out + k]) for k, n in enumerate(local_names)]
    locals_ += [ScalarVariable(a, float(y0[n_out + len(local_names) + k]),
                               getattr(by_name[flat.aliases[a][0]].decl, "unit", "") or "")
                for k, a in enumerate(alias_names)]
    state_vars = [scalar(n, init.x0[k]) for k, n in enumerate(dae.state_names)]
    params = [ScalarVariable(q.name, float(p_all[k]), q.decl.unit or "",
                             q.decl.description or "") for k, q in enumerate(dae.parameters)]
    inputs = [ScalarVariable(q.name, float(p_all[n_par + k]), q.decl.unit or "",
                             q.decl.description or "") for k, q in enumerate(dae.inputs)]
    name = "".join(c if c.isalnum() or c == "_" else "_" for c in compiled.name) or "model"
    return FmuSpec(model_name=name, description=f"{compiled.name} (bgmodelica)",
                   states=state_vars, inputs=inputs, parameters=params, outputs=outputs,
                   locals=locals_, ode=ode, init=None, stop_time=stop_time,
                   step_size=step_size, tolerance=tolerance)


def export_model(model: Component | CompiledModel, out_dir: str | Path, *,
                 fmi_version: int = 2, fmu_type: str = "me", stop_time: float = 1.0,
                 step_size: float | None = None, tolerance: float = 1e-6) -> Path:
    """Compile (if needed) and export ``model`` as an FMU into ``out_dir``; returns its path."""
    spec = fmu_spec(model, stop_time=stop_time, step_size=step_size, tolerance=tolerance)
    return export_fmu(spec, out_dir, fmi_version=fmi_version, fmu_type=fmu_type)
