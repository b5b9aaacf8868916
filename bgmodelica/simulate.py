"""``simulate``: compile (if needed), initialize, integrate with SUNDIALS IDAS, observe."""

from __future__ import annotations

import functools
import time as _time
from collections.abc import Callable, Sequence
from typing import Any

import casadi as ca
import numpy as np

from .asserts import check_asserts
from .backends.casadi_dae import CasadiDAE
from .backends.casadi_init import initialize
from .compiler import CompiledModel, compile
from .core.component import Component
from .core.units import with_units
from .diagnose import check_initial_point, check_result, unsafe_outputs
from .errors import ModelError, ParameterError, SimulationError
from .events.fast import Fast
from .integration import _integrate, _integrator, _xdot  # noqa: F401 (used by studies)
from .overrides import split_overrides, with_starts
from .result import Deferred, Result
from .solver_options import integrator_settings
from .validate import check_run_options, output_grid
from .value_checks import check_values

_HINTS = {
    "IDA_CONV_FAIL": "the Newton iteration failed repeatedly: the model may be singular at "
                     "this point (check the algebraic loops) or very stiff",
    "IDA_ERR_FAIL": "error test failed repeatedly: a discontinuity or a finite-time blow-up",
    "IDA_TOO_MUCH_WORK": "too many internal steps: raise max_steps or check for a blow-up",
    "IDA_LSETUP_FAIL": "the linear solver setup failed: singular iteration matrix",
    "IDA_LSOLVE_FAIL": "the linear solve failed: singular iteration matrix",
    "IDA_RES_FAIL": "the residual could not be evaluated (NaN / Inf in the model)",
    "IDA_REP_RES_ERR": "the residual returned NaN / Inf repeatedly",
    "CV_CONV_FAILURE": "the Newton iteration failed repeatedly",
    "CV_ERR_FAILURE": "error test failed repeatedly",
    "CV_TOO_MUCH_WORK": "too many internal steps",
}


def _located(fn: Callable) -> Callable:
    """An internal exception (CasADi's, Python's) while simulating a model read from Modelica
    becomes one line at the model's class rather than a traceback."""
    @functools.wraps(fn)
    def run(model: Any, *args: Any, **kwargs: Any) -> Any:
        try:
            return fn(model, *args, **kwargs)
        except ModelError:
            raise
        except (RecursionError, RuntimeError, KeyError, IndexError, TypeError,
                AttributeError, ZeroDivisionError) as err:
            from .modelica.errors import compile_failure

            located = compile_failure(getattr(model, "source", None) or model, err,
                                      "simulate")
            if located is None:
                raise
            raise located from None
    return run


@_located
def simulate(model: Component | CompiledModel | str, stop_time: float = 1.0,
             interval: float | None = None, params: dict[str, Any] | None = None, *,
             start_time: float = 0.0, rtol: float = 1e-6, atol: float | None = None,
             max_step: float | None = None, max_steps: int = 100000, solver: str = "auto",
             outputs: Sequence[str] | None = None, dynamic: bool = True,
             progress: Callable[[float], None] | None = None,
             inputs: Any = None, units: str = "error",
             sensitivities: Sequence[str] | None = None,
             sensitivity_method: str = "forward", init: str = "start",
             linear_solver: str = "auto", jit: bool | str = False) -> Result:
    """Simulate ``model`` from ``start_time`` to ``stop_time`` [s] and return a :class:`Result`.

    Parameters:

    - ``model``: a :class:`~bgmodelica.Component`, a :class:`~bgmodelica.CompiledModel`
      (compile once, simulate many times) or a MODEL reference as on the command line
      (``"library.examples:RC"``, ``"path/file.py:Name"``, ``"file.mo:Package.Model"``).
    - ``stop_time``, ``start_time`` [s]: the time span (default 0 to 1 s).
    - ``interval`` [s]: output grid step: the result holds exactly ``start_time +
      k*interval`` below ``stop_time``, then ``stop_time`` (default: 500 equal intervals).
    - ``params``: overrides by dotted name of parameters, model inputs (held constant) or
      start values of variables; a value may carry a unit (``{"R.R": "2 kOhm"}``), converted
      to the declared unit.
    - ``rtol``, ``atol``: integrator tolerances (``atol`` by default 1e-8, or ``rtol`` times
      the smallest ``nominal`` a state declares when that is smaller: a relative angle of
      nominal 1e-4 rad is then resolved as a Modelica tool resolves it; ``result.meta["atol"]``
      says which); ``max_step`` [s]: largest internal step; ``max_steps``: most internal
      steps per output interval.
    - ``solver``: ``"auto"`` (default: CVODES when the reduced model is an explicit ODE, no
      algebraic unknowns left; IDAS otherwise), ``"idas"`` or ``"cvodes"`` (ODE models only);
      ``result.meta["solver"]`` says which ran and ``meta["solver_choice"]`` whether it was
      chosen automatically.
    - ``outputs``: names to record (default: every variable).
    - ``dynamic``: allow dynamic state selection when index reduction left a choice whose
      conditioning depends on the state (see :mod:`bgmodelica.dynamic_selection`).
    - ``progress``: called with the fraction done after each chunk of the run.
    - ``inputs``: time-varying values of top-level ``Input``s: a CSV path or a mapping of input
      name to ``(times, values)`` (see :mod:`bgmodelica.events.inputs`).
    - ``units``: the unit check of :func:`~bgmodelica.compile` when ``model`` is compiled here
      (``"error"``, ``"warn"`` or ``"off"``).
    - ``sensitivities``: parameters / inputs p_j to differentiate the recorded variables with
      respect to: ``result.sensitivity("rotor.w", "resistor.R")`` is d(rotor.w)/d(resistor.R)
      along ``result.time``; ``sensitivity_method``: ``"forward"`` (CVODES/IDAS forward
      sensitivities through CasADi; refused for models with events) or ``"fd"`` (central
      finite differences of whole runs, labelled so in ``result.meta["sensitivity_method"]``);
      see :mod:`bgmodelica.studies.sensitivity`.
    - ``init``: ``"start"`` (default): the initial conditions are the fixed start values and
      the components' initial equations; ``"steady-state"``: the steady state der(x) = 0 with
      the given parameters and inputs, every start value a guess (see
      :func:`bgmodelica.steady_state`).
    - ``linear_solver``: the direct solver of the Newton iterations: ``"auto"`` (sparse QR,
      measured best at every size), ``"qr"``, ``"csparse"`` (sparse LU), ``"lapacklu"`` or
      ``"lapackqr"`` (dense); ``jit``: compile the model functions to C first (True, or an
      optimization level ``"O1"``, ``"O2"``; worth it for long or repeated runs, see
      :mod:`bgmodelica.solver_options`). ``result.meta`` reports ``linear_solver`` and ``jit``.

    Models with events (relations, ``when``, ``sample``, tables) or with ``inputs`` run in
    the event loop (:mod:`bgmodelica.events`): at every event the result holds two rows with
    the same time, the left and the right limit; ``result.meta["event_times"]`` lists them.

    Errors: options that are NaN, Inf, zero or negative, or a grid too large to hold, raise
    :class:`~bgmodelica.errors.OptionError`; parameters and fixed start values outside their
    declared ``min``/``max`` :class:`ParameterError`; a model undefined at its initial point
    (division by zero, log of a negative number) :class:`InitializationError` naming the
    equation; NaN/Inf in the result :class:`SimulationError` naming the variable and time,
    with ``.result`` holding the rows before.
    """
    opt = check_run_options(start_time=start_time, stop_time=stop_time, interval=interval,
                            rtol=rtol, atol=atol, max_step=max_step, max_steps=max_steps,
                            solver=solver)
    start_time, stop_time, interval = opt["start_time"], opt["stop_time"], opt["interval"]
    rtol, atol, max_step = opt["rtol"], opt["atol"], opt["max_step"]
    compiled = model if isinstance(model, CompiledModel) else compile(model, units=units)
    dae = compiled.dae
    if atol is None:
        atol = default_atol(compiled, rtol)
    choice = "auto" if solver == "auto" else "given"
    if solver == "auto":
        solver = "cvodes" if dae.z.numel() == 0 else "idas"
    elif solver == "cvodes" and dae.z.numel():
        raise ParameterError(f"solver 'cvodes' cannot handle the {dae.z.numel()} algebraic "
                             f"unknown(s) left in {compiled.name} (e.g. {dae.algebraic_names[0]}); "
                             "use solver='idas' or 'auto'")
    extra, solver_meta = integrator_settings(dae.x.numel() + dae.z.numel(), linear_solver, jit)
    t_start = _time.perf_counter()
    params = with_units(params or {}, compiled)
    p_over, start_over = split_overrides(dae, params)
    p = dae.p_vector(p_over)
    if start_over:
        dae = with_starts(dae, start_over)
    if init != "start":
        from .analysis.steady_state import steady_state_dae

        dae = steady_state_dae(compiled, dae, p, start_time, init)
    check_values(dae, p, compiled.declarations)
    grid = output_grid(start_time, stop_time, interval,        # exactly the points asked for
                       len(outputs) if outputs is not None else len(dae.names))
    selection = _selection(compiled, dynamic, start_over, stop_time - start_time)
    if init != "start" and selection is not None:     # other states: the same steady values
        from .analysis.steady_state import fixed_at_values

        selection.prepare = fixed_at_values(dae, p, start_time)
    if sensitivities is not None:
        from .studies.sensitivity import simulate_sensitivities

        return simulate_sensitivities(compiled, dae, p, grid, sensitivities,
                                      method=sensitivity_method, outputs=outputs, rtol=rtol,
                                      atol=atol, max_step=max_step, max_steps=max_steps,
                                      inputs=inputs, selection=selection, params=params,
                                      t_start=t_start, solver=solver)
    if dae.hybrid is not None or inputs is not None or selection is not None:
        from .events.run import simulate_hybrid

        try:
            result = simulate_hybrid(compiled, dae, p, grid, rtol=rtol, atol=atol,
                                     max_step=max_step, max_steps=max_steps, outputs=outputs,
                                     inputs=inputs, t_start=t_start, selection=selection,
                                     progress=progress, solver_options=extra)
        except SimulationError as err:      # NaN / Inf in the rows computed: say where
            if err.result is not None:
                check_result(err.result, dae, p)
            raise
        check_result(result, dae, p)
        result.meta.update(solver_meta, rtol=rtol, atol=atol)
        check_asserts(compiled, result)
        return result
    init = initialize(dae, p, start_time)
    check_initial_point(dae, init.x0, init.z0, p, start_time)
    obs_idx = _output_indices(dae, outputs, compiled.declarations.aliases)
    opts = {"abstol": atol, "reltol": rtol, "max_num_steps": max_steps,
            "calc_ic": False,   # initialize() already made x0, z0 consistent
            **extra}
    if max_step is not None:
        opts["max_step_size"] = float(max_step)
    xs, zs, stats, failure = _integrate(dae, solver, grid, init.x0, init.z0, p, opts,
                                        progress)
    n_ok = xs.shape[1]
    values = ((lambda: np.asarray(observer(dae, obs_idx)(grid[:n_ok], xs, zs, p)))
              if n_ok else np.zeros((0, len(obs_idx))))
    run = _time.perf_counter() - t_start
    names = list(dae.names) if len(obs_idx) == len(dae.names) else \
        [dae.names[k] for k in obs_idx]
    flat = compiled.declarations
    params_out = dae.parameter_values(p)
    meta = {"model": compiled.name, "compile_seconds": compiled.compile_time,
            "run_seconds": run,
            "timings": dict(compiled.timings), "solver": solver, "solver_choice": choice,
            "rtol": rtol, "atol": atol,
            **solver_meta, "stats": stats,
            "states": list(dae.state_names), "init_notes": init.notes}
    # a large model's units and aliases are made when first read
    aliases = Deferred(lambda: _kept_aliases(dae, flat, obs_idx, names))
    units = Deferred(lambda: dict(_units_by_name(dae, flat)))
    result = Result(grid[:n_ok], values, names, aliases, params_out, units, meta)
    if not _finite_run(dae, obs_idx, grid[:n_ok], xs, zs, p):
        check_result(result, dae, p)            # names the variable and time
    if failure is not None:
        t_reached = float(grid[n_ok - 1]) if n_ok else start_time
        hint = next((h for key, h in _HINTS.items() if key in failure), "see the solver message")
        raise SimulationError(
            f"{solver.upper()} failed after t = {t_reached:g} s (last good output point): "
            f"{hint}.\nSolver said: {failure.strip().splitlines()[-1][:300]}",
            t_reached, result)
    check_asserts(compiled, result)
    return result


def default_atol(compiled: CompiledModel, rtol: float) -> float:
    """The absolute tolerance when none is given: 1e-8, or ``rtol`` times the smallest
    ``nominal`` declared by a state when that is smaller (kept in ``dae.cache``)."""
    dae = compiled.dae
    key = ("nominal atol", rtol)
    if key not in dae.cache:
        states = set(dae.state_names)
        nominal = [abs(float(getattr(v.decl, "nominal", 1.0) or 1.0))
                   for v in getattr(compiled.declarations, "variables", ())
                   if v.name in states] if states else []
        smallest = min((n for n in nominal if n > 0), default=1.0)
        dae.cache[key] = min(1e-8, rtol * smallest)
    return dae.cache[key]


def _units_by_name(dae: CasadiDAE, flat: Any) -> dict[str, str]:
    """The declared unit of every variable, parameter and input of the flat model, by name;
    made once per model (kept in ``dae.cache``)."""
    seen = dae.cache.get("units by name")
    if seen is None or seen[0] is not flat:
        by_table = getattr(flat.variables, "units", None)      # (a large model's, at once)
        units = by_table() if by_table is not None else \
            {v.name: v.decl.unit for v in flat.variables}
        units.update({q.name: q.decl.unit for q in (*flat.parameters, *flat.inputs)})
        seen = dae.cache["units by name"] = (flat, units)
    return seen[1]


def _kept_aliases(dae: CasadiDAE, flat: Any, obs_idx: list[int],
                  names: list[str]) -> dict[str, tuple[str, float]]:
    """The aliases of the recorded variables ``names`` (a copy; the selection is made once
    per model and output set)."""
    key = ("kept aliases", tuple(obs_idx))
    seen = dae.cache.get(key)
    if seen is None or seen[0] is not flat.aliases:
        kept = set(names)
        seen = dae.cache[key] = (flat.aliases, {a: rep for a, rep in flat.aliases.items()
                                                if rep[0] in kept})
    return dict(seen[1])


def _finite_run(dae: CasadiDAE, obs_idx: list[int], times: np.ndarray, xs: np.ndarray,
                zs: np.ndarray, p: np.ndarray) -> bool:
    """Whether every recorded value is finite, evaluating only the variables that can turn
    non-finite for finite states (:func:`bgmodelica.diagnose.unsafe_outputs`); the others
    stay lazy (computed when first read)."""
    if not (_all_finite(xs) and _all_finite(zs)):
        return False
    if "unsafe_observed" in dae.cache:
        unsafe = [k for k in obs_idx if k in dae.cache["unsafe_observed"]]
    elif 4 * len(obs_idx) < len(dae.names):     # a few outputs: analyse only those
        key = ("unsafe_of", tuple(obs_idx))
        if key not in dae.cache:
            dae.cache[key] = _unsafe(dae, obs_idx)
        unsafe = dae.cache[key]
    else:
        dae.cache["unsafe_observed"] = set(_unsafe(dae, range(len(dae.names))))
        unsafe = [k for k in obs_idx if k in dae.cache["unsafe_observed"]]
    if not unsafe or not len(times):
        return True
    with np.errstate(all="ignore"):
        return bool(np.all(np.isfinite(observer(dae, unsafe)(times, xs, zs, p))))


def _unsafe(dae: CasadiDAE, idx: Sequence[int]) -> list[int]:
    """The observed variables ``idx`` that can turn non-finite for finite states
    (:func:`bgmodelica.diagnose.unsafe_outputs`). Only those nonlinear in time, states or
    algebraic variables are analysed (a division, root, logarithm or power of something
    varying is nonlinear in it; the others are linear in what varies), found in one
    structural pass (:func:`casadi.which_depends`, second order)."""
    idx = list(idx)
    if not idx:
        return []
    whole = len(idx) == dae.observed.numel() and idx == list(range(len(idx)))
    expr = dae.observed if whole else dae.observed[idx]
    varying = ca.vertcat(dae.t, dae.x, dae.z)
    nonlinear = [k for k, yes in zip(idx, ca.which_depends(expr, varying, 2, True),
                                     strict=True) if yes]
    if not nonlinear:
        return []
    f = ca.Function("observed", [dae.t, dae.x, dae.z, dae.p],
                    [ca.densify(dae.observed[nonlinear])])
    return [nonlinear[k] for k in unsafe_outputs(f, (0, 1, 2))]


def _all_finite(a: np.ndarray) -> bool:
    """Whether every entry of ``a`` is finite: its sum is (one pass, no temporary array; a
    sum that overflows is checked entry by entry)."""
    with np.errstate(all="ignore"):
        if np.isfinite(np.sum(a)):
            return True
    return bool(np.all(np.isfinite(a)))


def _output_indices(dae: CasadiDAE, outputs: Sequence[str] | None,
                    aliases: dict[str, tuple[str, float]]) -> list[int]:
    if outputs is None:
        return list(range(len(dae.names)))
    wanted = [aliases[n][0] if n not in dae.observed_index and n in aliases else n
              for n in outputs]
    missing = [n for n, w in zip(outputs, wanted, strict=True) if w not in dae.observed_index]
    if missing:
        raise ParameterError(f"unknown output variable(s): {', '.join(missing)}")
    return sorted({dae.observed_index[w] for w in wanted})


def observer(dae: CasadiDAE, idx: list[int]) -> Callable:
    """Evaluate the observed variables ``idx`` on a grid, reading only the states and
    algebraic variables they depend on (built once per model and output set)."""
    key = ("observer", tuple(idx))
    if key not in dae.cache:
        dae.cache[key] = _make_observer(dae, idx)
    return dae.cache[key]


def _make_observer(dae: CasadiDAE, idx: list[int]) -> Callable:
    expr = ca.vertcat(*[dae.observed[k] for k in idx]) if idx else ca.SX(0, 1)
    used_x = sorted(set(ca.jacobian_sparsity(expr, dae.x).get_triplet()[1])) \
        if dae.x.numel() else []
    used_z = sorted(set(ca.jacobian_sparsity(expr, dae.z).get_triplet()[1])) \
        if dae.z.numel() else []
    used_p = sorted(set(ca.jacobian_sparsity(expr, dae.p).get_triplet()[1])) \
        if dae.p.numel() else []
    xs = ca.vertcat(*[dae.x[i] for i in used_x]) if used_x else ca.SX(0, 1)
    zs = ca.vertcat(*[dae.z[i] for i in used_z]) if used_z else ca.SX(0, 1)
    ps = ca.vertcat(*[dae.p[i] for i in used_p]) if used_p else ca.SX(0, 1)
    f = ca.Function("observe", [dae.t, xs, zs, ps], [ca.densify(expr)])
    mapped: dict[int, Fast] = {}

    def run(times, x_traj, z_traj, p):
        n = len(times)
        if n not in mapped:                      # one mapped, buffered function per length
            if len(mapped) > 8:
                mapped.clear()
            mapped[n] = Fast(f.map(n))
        out = mapped[n](times, np.asarray(x_traj[used_x, :]).T.ravel(),
                        np.asarray(z_traj[used_z, :]).T.ravel() if used_z else 0.0,
                        np.repeat(np.asarray(p)[used_p][None, :], n, axis=0).ravel())[0]
        return out.reshape(n, len(idx)).copy()

    return run


def _selection(compiled: CompiledModel, dynamic: bool, start_over: dict[str, Any],
               span: float):
    """Dynamic state selection for the event loop when the model's pivots vary with the
    state: switching (``dynamic=True``) or a check that stops with a clear error when the
    compiled choice degenerates (``dynamic=False``); None when the choice is fixed."""
    selector = _selector(compiled)
    if selector is None:
        return None
    from .events.selection import Selection

    return Selection(selector, selector.base, "switch" if dynamic else "check",
                     (lambda d: with_starts(d, start_over)) if start_over else None,
                     spacing=span / 1000.0)


def _selector(compiled: CompiledModel):
    """The dynamic state selector of a model that needs one (cached on the model), or None."""
    if not compiled.has_state_choice:
        return None
    from .dynamic_selection import StateSelector

    cached = getattr(compiled, "_selector", None)
    if cached is None:
        cached = StateSelector(compiled)
        cached = cached if cached.needed() else False
        object.__setattr__(compiled, "_selector", cached)
    return cached or None


