"""From a compiled model to an :class:`FmuSpec`: the explicit ODE with outputs.

Algebraic unknowns left after tearing (``z``) are solved inside the model function with
CasADi's code-generatable ``fast_newton`` rootfinder, started from their consistent initial
values, so the FMU sees ``xdot, y = ode(t, x, u, p)``.

Causality: the model's top-level ``Output`` variables are FMU outputs; the states are the FMU's
continuous states; every other variable, aliases included, is a local. Free parameters are tunable
parameters and top-level ``Input`` variables are inputs.

Ranges: the ``min``/``max`` of the declarations (``Parameter(..., min=, max=)``,
``Variable(..., min=, max=)``) go to ``modelDescription.xml`` for parameters, inputs, states,
outputs and locals (an alias gets the range of the variable it stands for, mirrored when the
sign is negative); the FMU refuses parameter, input and state start values outside them. A
default value outside its own range is refused at export (:class:`FmuSpecError`); a
consistent initial state within 1e-9 (relative) of a bound is put on the bound.

Models with events (relations, ``when``, ``sample``, tables) export with the event runtime of
:mod:`bgmodelica.fmi.hybrid`: ``ode`` then takes the discrete slots ``d`` as a fifth argument,
discrete variables are exported with their FMI types, and the start state is the native one
(relations at their values at the start time).
"""

from __future__ import annotations

import inspect
import math
from pathlib import Path

import casadi as ca
import numpy as np

from ..backends.casadi_init import initial_state_function, initialize
from ..compiler import CompiledModel, compile
from ..core.component import Component
from ..core.variables import KIND_OUTPUT
from .export import export_fmu
from .spec import FmuSpec, FmuSpecError, ScalarVariable


def parameters_and_inputs(dae, p_all) -> tuple[list[ScalarVariable], list[ScalarVariable]]:
    """The FMU's parameters and inputs, with the values of ``p_all`` (parameters first)."""
    n_par = len(dae.parameters)

    def var(q, value: float, kind: str) -> ScalarVariable:
        return ScalarVariable(q.name, float(value), q.decl.unit or "",
                              q.decl.description or "", *_bounds(q.decl, q.name, kind))
    return ([var(q, p_all[k], "parameter") for k, q in enumerate(dae.parameters)],
            [var(q, p_all[n_par + k], "input") for k, q in enumerate(dae.inputs)])


def model_identifier(name: str) -> str:
    """``name`` as a C identifier (other characters become ``_``)."""
    return "".join(c if c.isalnum() or c == "_" else "_" for c in name) or "model"


def _bounds(decl: object, name: str, kind: str) -> tuple[float | None, float | None]:
    """``(min, max)`` of a declaration as floats (None: not declared or infinite)."""
    out: list[float | None] = []
    for attr in ("min", "max"):
        b = getattr(decl, attr, None)
        if b is None:
            out.append(None)
            continue
        try:
            x = float(b)
        except (TypeError, ValueError):
            raise FmuSpecError(f"{kind} {name!r}: {attr}={b!r} is not a number") from None
        if math.isnan(x):
            raise FmuSpecError(f"{kind} {name!r}: {attr} is NaN")
        out.append(x if math.isfinite(x) else None)
    lo, hi = out
    if lo is not None and hi is not None and lo > hi:
        raise FmuSpecError(f"{kind} {name!r}: min {lo:g} > max {hi:g}")
    return lo, hi


def _on_bound(value: float, lo: float | None, hi: float | None, name: str) -> float:
    """A state's initial value, put on a bound it misses by rounding only."""
    for b, below in ((lo, True), (hi, False)):
        if b is None or (value >= b if below else value <= b):
            continue
        if abs(value - b) <= 1e-9 * max(1.0, abs(b)):
            return b
        raise FmuSpecError(f"state {name!r}: its consistent initial value {value:g} is outside "
                           f"its declared range [{'-inf' if lo is None else f'{lo:g}'}, "
                           f"{'inf' if hi is None else f'{hi:g}'}]")
    return value


def fmu_spec(model: Component | CompiledModel, *, stop_time: float = 1.0,
             step_size: float | None = None, tolerance: float = 1e-6,
             newton_tolerance: float = 1e-12, static_states: bool = False) -> FmuSpec:
    """Describe a model for export (see the module docstring for the conventions).

    A model whose state choice must change during a simulation (dynamic state selection,
    e.g. the Cartesian pendulum) exports with every candidate choice and switches between
    them at events (:mod:`bgmodelica.fmi.state_sets`); ``static_states=True`` keeps the
    compiled choice instead, for motions known to stay where it is valid. A model with events
    of its own keeps the choice the native simulation starts with (PendulumWall: the
    preferred ``x, vx``, which the native simulation keeps too)."""
    compiled = model if isinstance(model, CompiledModel) else compile(model)
    flat = compiled.reduced.model        # first: a model from the array path completes here
    dae = compiled.dae
    hybrid = dae.hybrid is not None      # events: see bgmodelica.fmi.hybrid
    if hybrid:
        from .hybrid import check_exportable

        check_exportable(dae, compiled.name)
    if not static_states and compiled.needs_dynamic_selection():
        from .state_sets import start_variant, state_set_spec

        if not hybrid:
            return state_set_spec(compiled, stop_time=stop_time, step_size=step_size,
                                  tolerance=tolerance, newton_tolerance=newton_tolerance)
        # with events: the selection the native simulation starts with, kept (open: the
        # switch between selections in an FMU with events of its own)
        from ..dynamic_selection import StateSelector

        compiled = start_variant(StateSelector(compiled))
        flat, dae = compiled.reduced.model, compiled.dae
    n_par = len(dae.parameters)
    p_all = dae.p_default
    if hybrid:
        from .hybrid import consistent_start

        x_init, z_init, p_init = consistent_start(dae, p_all)
    else:
        init = initialize(dae, p_all)
        x_init, z_init, p_init = init.x0, init.z0, p_all

    t = ca.MX.sym("t")
    x = ca.MX.sym("x", dae.x.numel())
    u = ca.MX.sym("u", len(dae.inputs))
    p = ca.MX.sym("p", n_par)
    d = ca.MX.sym("d", len(dae.discretes)) if hybrid else None
    pu = ca.vertcat(p, u, d) if hybrid else ca.vertcat(p, u)

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
    # discrete variables are exported apart, with their FMI types (hybrid models)
    discrete = set(dae.discrete_names) | {q.name for q in dae.discretes}
    local_names = [n for n in dae.names
                   if n not in discrete and by_name[n].der_of < 0 and n not in taken]
    alias_names = [a for a, (rep, _) in sorted(flat.aliases.items())
                   if rep in dae.observed_index and rep not in discrete
                   and by_name[rep].der_of < 0 and not a.startswith("der(") and a not in taken]

    def observed(n: str) -> ca.SX:
        # a declared output may be an alias (e.g. of a state): export it as an output anyway
        if n in dae.observed_index:
            return dae.observed[dae.observed_index[n]]
        rep, sign = flat.aliases[n]
        return sign * dae.observed[dae.observed_index[rep]]

    y_sx = ca.vertcat(*[observed(n) for n in output_names + local_names + alias_names])
    f_sx = ca.Function("model", [dae.t, dae.x, dae.z, dae.p], [dae.ode, y_sx])
    z_of = None
    if dae.z.numel():
        g = ca.Function("g", [dae.z, ca.vertcat(dae.t, dae.x, dae.p)], [dae.alg])
        solver = ca.rootfinder("loops", "fast_newton", g,
                               {"abstol": newton_tolerance, "max_iter": 50})

        def z_of(t_, x_, p_):
            return solver(ca.DM(z_init), ca.vertcat(t_, x_, p_))

        z = z_of(t, x, pu)
    else:
        z = ca.MX(0, 1)
    xdot, y = f_sx(t, x, z, pu)
    ds, dn = ([d], ["d"]) if hybrid else ([], [])
    ode = ca.Function("ode", [t, x, u, p] + ds, [xdot, y], ["t", "x", "u", "p"] + dn,
                      ["xdot", "y"])

    def scalar(name: str, start: float, kind: str = "variable") -> ScalarVariable:
        v = by_name.get(name)
        decl = v.decl if v is not None else top_decls.get(name)
        lo, hi = _bounds(decl, name, kind)
        if kind == "state":
            start = _on_bound(float(start), lo, hi, name)
        return ScalarVariable(name, float(start), getattr(decl, "unit", "") or "",
                              getattr(decl, "description", "") or "", min=lo, max=hi)

    def alias(a: str, start: float) -> ScalarVariable:
        rep, sign = flat.aliases[a]
        decl = by_name[rep].decl
        lo, hi = _bounds(decl, rep, "variable")
        if sign < 0:
            lo, hi = (None if hi is None else -hi), (None if lo is None else -lo)
        return ScalarVariable(a, float(start), getattr(decl, "unit", "") or "", min=lo,
                              max=hi)

    n_base = dae.n_base
    y0 = np.asarray(ca.Function("y0", [t, x, u, p] + ds, [y])(
        0.0, x_init, p_init[n_par:n_base], p_init[:n_par],
        *([p_init[n_base:]] if hybrid else []))).ravel()
    n_out = len(output_names)
    outputs = [scalar(n, y0[k]) for k, n in enumerate(output_names)]
    locals_ = [scalar(n, y0[n_out + k]) for k, n in enumerate(local_names)]
    locals_ += [alias(a, y0[n_out + len(local_names) + k]) for k, a in enumerate(alias_names)]
    state_vars = [scalar(n, x_init[k], "state") for k, n in enumerate(dae.state_names)]
    params, inputs = parameters_and_inputs(dae, p_all)
    name = model_identifier(compiled.name)
    hyb_spec = None
    if hybrid:
        from .hybrid import build_hybrid

        hyb_spec = build_hybrid(dae, flat, by_name, z_of,
                                lambda p_, u_, d_: ca.vertcat(p_, u_, d_))
        # the initial state also depends on the discrete slots (relations at the start)
        f0 = initial_state_function(dae, p_init)
        init = None if f0 is None else ca.Function(
            "init", [t, u, p, d], [f0(t, ca.vertcat(p, u, d))], ["t", "u", "p", "d"], ["x0"])
    else:
        init = _init_function(dae, p_all, t, u, p)
    return FmuSpec(model_name=name, description=docstring_summary(compiled),
                   states=state_vars, inputs=inputs, parameters=params, outputs=outputs,
                   state_outputs=[n for n in declared_outputs if n in states],
                   locals=locals_, ode=ode, init=init,
                   stop_time=stop_time,
                   step_size=step_size, tolerance=tolerance, hybrid=hyb_spec)


def docstring_summary(compiled: CompiledModel) -> str:
    """The first paragraph of the model's own docstring (its class's, not inherited), on one
    line; ``"<name> (bgmodelica)"`` when it has none."""
    source = compiled.source
    doc = None
    if source is not None:
        doc = type(source).__dict__.get("__doc__") if not isinstance(source, type) \
            else source.__dict__.get("__doc__")
    first = " ".join(inspect.cleandoc(doc).split("\n\n")[0].split()) if doc else ""
    return first or f"{compiled.name} (bgmodelica)"


def _init_function(dae, p_all, t, u, p) -> ca.Function | None:
    """``(t, u, p) -> x0`` when the initial state follows from conditions through the model's
    equations (fixed start values of non-states), so that parameters set in the FMU change it
    exactly as in native simulation; None when the initial state is the fixed start values."""
    f0 = initial_state_function(dae, p_all)
    if f0 is None:
        return None
    return ca.Function("init", [t, u, p], [f0(t, ca.vertcat(p, u))], ["t", "u", "p"], ["x0"])


def default_experiment(compiled: CompiledModel, stop_time: float | None = None,
                       step_size: float | None = None, tolerance: float | None = None
                       ) -> dict[str, float | None]:
    """The FMU's DefaultExperiment: the values given, else the model's ``experiment``
    annotation (Modelica models: StartTime, StopTime, Interval, Tolerance), else a stop time
    of 1 s and a tolerance of 1e-6."""
    from ..modelica import experiment_of

    exp = experiment_of(compiled.source) if compiled.source is not None else {}
    start = float(exp.get("start_time", 0.0))
    stop = stop_time if stop_time is not None else exp.get("stop_time", start + 1.0)
    return {"start_time": start, "stop_time": float(stop),
            "step_size": step_size if step_size is not None else exp.get("interval"),
            "tolerance": float(tolerance if tolerance is not None else exp.get("rtol", 1e-6))}


def export_model(model: Component | CompiledModel, out_dir: str | Path, *,
                 fmi_version: int = 2, fmu_type: str = "me", stop_time: float | None = None,
                 step_size: float | None = None, tolerance: float | None = None,
                 static_states: bool = False) -> Path:
    """Compile (if needed) and export ``model`` as an FMU into ``out_dir``; returns its path.
    ``stop_time``, ``step_size`` and ``tolerance`` left None come from the model's experiment
    annotation (:func:`default_experiment`); ``static_states``: see :func:`fmu_spec`."""
    compiled = model if isinstance(model, CompiledModel) else compile(model)
    exp = default_experiment(compiled, stop_time, step_size, tolerance)
    spec = fmu_spec(compiled, stop_time=exp["stop_time"], step_size=exp["step_size"],
                    tolerance=exp["tolerance"], static_states=static_states)
    spec.start_time = exp["start_time"]
    return export_fmu(spec, out_dir, fmi_version=fmi_version, fmu_type=fmu_type)
