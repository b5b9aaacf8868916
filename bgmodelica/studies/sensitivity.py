"""Trajectory sensitivities d(variable)/d(parameter).

**Forward sensitivities** (:func:`forward_run`, the default of ``simulate(...,
sensitivities=[...])``) differentiate the integration itself: the CasADi integrator of the
compiled DAE is differentiated in forward mode (``jtimes`` of the integrator's outputs), which
CasADi carries out with CVODES / IDAS forward sensitivity equations integrated alongside the
states under the same error control. The initial sensitivities follow from the
initialization by the implicit function theorem (a state fixed by its start value has zero
sensitivity; states and algebraic variables determined by fixed start values of other
variables or by the algebraic equations get ``-G_u^-1 G_p``), and every observed variable
(aliases, derivatives, algebraic outputs) gets ``h_x S_x + h_z S_z + h_p`` at each output
point.

Models with events (relations, ``when``, ``sample``, tables), time-varying inputs or dynamic
state selection are refused by the forward method: CasADi's derivative of an integration does
not account for the jumps of the states and of the event times, so it would be silently
wrong. For them, :func:`finite_difference_sensitivities` (``sensitivity_method="fd"``) gives
central finite differences of whole simulations, labelled as such in
``result.meta["sensitivity_method"]``.
"""

from __future__ import annotations

import time as _time
from collections.abc import Sequence
from typing import Any

import casadi as ca
import numpy as np

from ..errors import ModelError, ParameterError, SimulationError

FORWARD = "forward sensitivities (CasADi forward AD of the CVODES/IDAS integration)"


class SensitivityError(ModelError):
    """Sensitivities cannot be computed as asked (events with the forward method, a name that
    is not a free parameter or input)."""


def parameter_indices(dae: Any, names: Sequence[str]) -> list[int]:
    """Positions in ``p`` of the parameters / inputs ``names`` (aliases followed)."""
    from ..overrides import did_you_mean, resolve_alias

    pnames = [q.name for q in dae.parameters] + [u.name for u in dae.inputs]
    pset = set(pnames)
    out = []
    if isinstance(names, str):
        names = [names]
    if not list(names):
        raise SensitivityError("sensitivities: name at least one parameter")
    for key in names:
        name, _sign = resolve_alias(key, dae.aliases or {}, pset, dae.observed_index)
        if name not in pset:
            if name in dae.observed_index:
                raise SensitivityError(
                    f"sensitivities: {key!r} is a variable, not a parameter; sensitivities are "
                    "taken with respect to free parameters and model inputs")
            flat_bound = [q.name for q in getattr(getattr(dae.sorted, "model", None),
                                                  "parameters", [])]
            if key in flat_bound:
                raise SensitivityError(
                    f"sensitivities: {key!r} is bound to an expression of other parameters; "
                    "take the sensitivities with respect to those")
            raise SensitivityError(f"sensitivities: {key!r} is not a parameter or input of "
                                   f"the model{did_you_mean(key, pnames)}")
        if _sign != 1.0:
            raise SensitivityError(f"sensitivities: {key!r} is a negated alias of {name}; "
                                   f"use {name}")
        out.append(pnames.index(name))
    if len(set(out)) != len(out):
        raise SensitivityError("sensitivities: a parameter is named twice")
    return out


def refuse_events(dae: Any, inputs: Any = None, selection: Any = None) -> None:
    why = ("it has events (relations, when, sample or tables)" if dae.hybrid is not None
           else "it has time-varying inputs" if inputs is not None
           else "it needs dynamic state selection" if selection is not None else None)
    if why:
        raise SensitivityError(
            f"forward sensitivities refused: {why}, and the derivative of an integration "
            "through events computed by CasADi ignores the jumps of the states and of the "
            "event times (it would be wrong). Use sensitivity_method='fd' (central finite "
            "differences of whole simulations, labelled as such)")


# -- initial sensitivities -------------------------------------------------------------------

def _init_partition(dae: Any) -> tuple[list[int], list[tuple[int, float]]]:
    """The states initialization solves for (the others keep a constant start value) and the
    fixed start values of non-states (conditions), as :func:`initialize` decides them."""
    from ..structure import maximum_matching

    state_pos = {n: k for k, n in enumerate(dae.state_names)}
    fixed_states, conditions = set(), []
    for k, value in dae.fixed:
        name = dae.names[k]
        if name in state_pos:
            fixed_states.add(state_pos[name])
        else:
            conditions.append((k, value))
    free = [i for i in range(dae.x.numel()) if i not in fixed_states]
    if not conditions:
        return [], conditions
    nz = dae.z.numel()
    cond_expr = ca.vertcat(*[dae.observed[k] for k, _ in conditions])
    xf = ca.vertcat(*[dae.x[i] for i in free]) if free else ca.SX(0, 1)
    rows: list[list[int]] = [[] for _ in range(nz + len(conditions))]
    if free or nz:
        sp = ca.jacobian_sparsity(ca.vertcat(dae.alg, cond_expr), ca.vertcat(xf, dae.z))
        for r, c in zip(*sp.get_triplet(), strict=True):
            rows[r].append(c)
    first = maximum_matching(rows[:nz] + [[] for _ in conditions], len(free) + nz)
    match = maximum_matching(rows, len(free) + nz, initial=first)
    solved = [free[c] for c in range(len(free)) if match.var_to_eq[c] >= 0]
    return solved, conditions


def initial_sensitivities(dae: Any, x0: np.ndarray, z0: np.ndarray, p: np.ndarray, t0: float,
                          wrt: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """d(x0)/d(p[wrt]) and d(z0)/d(p[wrt]) of the consistent initial point."""
    nx, nz, ns = dae.x.numel(), dae.z.numel(), len(wrt)
    key = ("sens-init", tuple(k for k, _ in dae.fixed))     # start overrides change it
    if key not in dae.cache:
        solved, conditions = _init_partition(dae)
        if not solved and not nz:
            dae.cache[key] = None
        else:
            u = ca.vertcat(*[dae.x[i] for i in solved], dae.z)
            g = ca.vertcat(*[dae.observed[k] - v for k, v in conditions], dae.alg) \
                if conditions else dae.alg
            f = ca.Function("init_jac", [dae.x, dae.z, dae.p, dae.t],
                            [ca.jacobian(g, u), ca.jacobian(g, dae.p)])
            dae.cache[key] = (solved, f)
    entry = dae.cache[key]
    sx, sz = np.zeros((nx, ns)), np.zeros((nz, ns))
    if entry is None:
        return sx, sz
    solved, f = entry
    gu, gp = (np.asarray(a, dtype=float) for a in f(x0, z0, p, t0))
    rhs = -gp[:, wrt]
    try:
        du = np.linalg.solve(gu, rhs) if gu.shape[0] == gu.shape[1] \
            else np.linalg.lstsq(gu, rhs, rcond=None)[0]
    except np.linalg.LinAlgError:
        raise SensitivityError("initial sensitivities: the initialization system is singular "
                               "at the initial point") from None
    sx[solved] = du[:len(solved)]
    sz[:] = du[len(solved):]
    return sx, sz


# -- forward sensitivities of a run -------------------------------------------------------------

def _sens_function(dae: Any, solver: str, grid: np.ndarray, opts: dict, ns: int):
    """``(x0, z0, p, seeds) -> (xf, zf, d vec(xf), d vec(zf))`` on ``grid[1:]``; cached for
    CVODES (IDAS needs the initial state derivative among its options: built per run)."""
    from ..simulate import _integrator

    key = ("sens-integrator", solver, tuple(map(float, grid)), ns,
           repr(sorted(opts.items())))
    cache = dae.cache.setdefault("sens-integrators", {})
    if solver == "cvodes" and key in cache:
        return cache[key]
    F = _integrator(dae, solver, grid[0], grid[1:], opts)
    nx, nz, n_p = max(dae.x.numel(), 1), dae.z.numel(), dae.p.numel()
    X0, Z0, P = ca.MX.sym("x0", nx), ca.MX.sym("z0", nz), ca.MX.sym("p", n_p)
    seeds = ca.MX.sym("seeds", nx + nz + n_p, ns)
    out = F(x0=X0, z0=Z0, p=P) if nz else F(x0=X0, p=P)
    arg = ca.vertcat(X0, Z0, P)
    xf = out["xf"]
    res = [xf, ca.jtimes(ca.vec(xf), arg, seeds)]
    if nz:
        zf = out["zf"]
        res = [xf, zf, res[1], ca.jtimes(ca.vec(zf), arg, seeds)]
    f = ca.Function("sens_run", [X0, Z0, P, seeds], res)
    if solver == "cvodes":
        if len(cache) >= 4:
            cache.pop(next(iter(cache)))
        cache[key] = f
    return f


def _xdot_sens(dae: Any, t0: float, x0, z0, p, seeds: np.ndarray) -> np.ndarray:
    """Sensitivities of x'(t0): f_x S_x + f_z S_z + f_p E (nx x ns)."""
    key = ("sens-xdot", seeds.shape[1])
    if key not in dae.cache:
        s = ca.SX.sym("s", seeds.shape[0], seeds.shape[1])
        d = ca.jtimes(dae.ode, ca.vertcat(dae.x, dae.z, dae.p), s)
        dae.cache[key] = ca.Function("xdot_sens", [dae.t, dae.x, dae.z, dae.p, s], [d])
    return np.asarray(dae.cache[key](t0, x0, z0, p, seeds), dtype=float)


def _observed_sens(dae: Any, idx: list[int], ns: int):
    key = ("sens-observed", tuple(idx), ns)
    if key not in dae.cache:
        h = ca.vertcat(*[dae.observed[k] for k in idx]) if idx else ca.SX(0, 1)
        nin = dae.x.numel() + dae.z.numel() + dae.p.numel()
        seeds = ca.SX.sym("s", nin, ns)
        dh = ca.jtimes(h, ca.vertcat(dae.x, dae.z, dae.p), seeds)
        dae.cache[key] = ca.Function("observe_sens", [dae.t, dae.x, dae.z, dae.p, seeds],
                                     [dh])
    return dae.cache[key]


def forward_run(compiled: Any, dae: Any, p: np.ndarray, grid: np.ndarray, wrt: list[int],
                obs_idx: list[int], *, rtol: float, atol: float, max_step: float | None = None,
                max_steps: int = 100000) -> tuple[np.ndarray, np.ndarray, dict[str, Any]]:
    """Observed variables ``obs_idx`` on ``grid`` (N x n) and their sensitivities to
    ``p[wrt]`` (len(wrt) x N x n), from one differentiated integration. The grid starts at the
    initial time. Smooth models only (see :func:`refuse_events`)."""
    from ..backends.casadi_init import initialize
    from ..diagnose import check_initial_point
    from ..simulate import _xdot, observer

    refuse_events(dae)
    p = np.asarray(p, dtype=float)
    t0 = float(grid[0])
    init = initialize(dae, p, t0)
    check_initial_point(dae, init.x0, init.z0, p, t0)
    nx, nz, n_p, ns, N = dae.x.numel(), dae.z.numel(), dae.p.numel(), len(wrt), len(grid)
    sx0, sz0 = initial_sensitivities(dae, init.x0, init.z0, p, t0, wrt)
    E = np.zeros((n_p, ns))
    E[wrt, np.arange(ns)] = 1.0
    solver = "cvodes" if nz == 0 else "idas"
    opts: dict[str, Any] = {"abstol": atol, "reltol": rtol, "max_num_steps": max_steps}
    if max_step is not None:
        opts["max_step_size"] = float(max_step)
    x0 = init.x0 if nx else np.zeros(1)
    nxi = max(nx, 1)
    seeds = np.vstack([sx0 if nx else np.zeros((1, ns)), sz0, E])
    if solver == "idas":            # consistent x'(t0) and its sensitivities: no IDACalcIC
        opts["calc_ic"] = False
        opts["init_xdot"] = _xdot(dae, t0, init.x0, init.z0, p)
        dxdot = _xdot_sens(dae, t0, init.x0, init.z0, p, seeds) if nx else np.zeros((1, ns))
        opts["augmented_options"] = {"init_xdot": opts["init_xdot"]
                                     + [float(v) for v in dxdot.ravel(order="F")]}
    f = _sens_function(dae, solver, grid, opts, ns)
    try:
        out = f(x0, init.z0, p, seeds)
    except RuntimeError as err:
        raise SimulationError(f"{solver.upper()} with forward sensitivities failed: "
                              f"{str(err).strip().splitlines()[-1][:300]}", t0) from None
    if nz:
        xf, zf, jx, jz = (np.asarray(a, dtype=float) for a in out)
    else:
        xf, jx = (np.asarray(a, dtype=float) for a in out)
        zf, jz = np.zeros((0, N - 1)), np.zeros((0, ns))
    X = np.hstack([x0.reshape(nxi, 1), xf.reshape(nxi, N - 1)])[:nx]
    Z = np.hstack([init.z0.reshape(nz, 1), zf.reshape(nz, N - 1)])
    # jtimes of vec(xf): rows ordered time-major within columns -> (N-1, nxi, ns)
    SX = np.concatenate([(sx0 if nx else np.zeros((1, ns)))[None],
                         jx.reshape(N - 1, nxi, ns)], axis=0)[:, :nx]          # (N, nx, ns)
    SZ = np.concatenate([sz0[None], jz.reshape(N - 1, nz, ns)], axis=0) if nz \
        else np.zeros((N, 0, ns))
    Y = np.asarray(observer(dae, obs_idx)(grid, X, Z, p))
    g = _observed_sens(dae, obs_idx, ns)
    seeds_t = np.concatenate([SX, SZ, np.broadcast_to(E, (N, n_p, ns))], axis=1)  # (N,nin,ns)
    nin = seeds_t.shape[1]
    gm = g.map(N)
    dh = np.asarray(gm(grid.reshape(1, -1), X if nx else np.zeros((0, N)),
                       Z if nz else np.zeros((0, N)), p,
                       seeds_t.transpose(1, 0, 2).reshape(nin, N * ns)), dtype=float)
    S = dh.reshape(len(obs_idx), N, ns).transpose(2, 1, 0)                     # (ns, N, n)
    stats = {"solver": solver, "n_sensitivities": ns}
    return Y, S, stats


# -- entry points ---------------------------------------------------------------------------------

def simulate_sensitivities(compiled: Any, dae: Any, p: np.ndarray, grid: np.ndarray,
                           names: Sequence[str], *, method: str = "forward",
                           outputs: Sequence[str] | None, rtol: float, atol: float,
                           max_step: float | None, max_steps: int, inputs: Any = None,
                           selection: Any = None, params: dict[str, Any] | None = None,
                           t_start: float | None = None, fd_step: float | None = None,
                           solver: str = "auto"):
    """The :class:`~bgmodelica.result.Result` of ``simulate(..., sensitivities=names)``."""
    from ..result import Result
    from ..simulate import _output_indices

    if method in ("fd", "finite-differences", "finite_differences", "central"):
        return finite_difference_sensitivities(
            compiled, names, stop_time=float(grid[-1]), start_time=float(grid[0]),
            grid=grid, params=params, outputs=outputs, rtol=rtol, atol=atol,
            max_step=max_step, max_steps=max_steps, inputs=inputs, step=fd_step,
            solver=solver)
    if method != "forward":
        raise SensitivityError(f"sensitivity_method must be 'forward' or 'fd', got {method!r}")
    refuse_events(dae, inputs, selection)
    t_start = _time.perf_counter() if t_start is None else t_start
    wrt = parameter_indices(dae, names)
    obs_idx = _output_indices(dae, outputs, compiled.reduced.model.aliases)
    Y, S, stats = forward_run(compiled, dae, p, grid, wrt, obs_idx, rtol=rtol, atol=atol,
                              max_step=max_step, max_steps=max_steps)
    pnames = [q.name for q in dae.parameters] + [u.name for u in dae.inputs]
    out_names = [dae.names[k] for k in obs_idx]
    flat = compiled.reduced.model
    units = {v.name: v.decl.unit for v in flat.variables}
    kept = set(out_names)
    aliases = {a: rep for a, rep in flat.aliases.items() if rep[0] in kept}
    params_out = {q.name: float(val) for q, val in zip(dae.parameters, p, strict=False)}
    meta = {"compile_seconds": compiled.compile_time,
            "run_seconds": _time.perf_counter() - t_start, "timings": dict(compiled.timings),
            "solver": stats["solver"], "stats": stats, "states": list(dae.state_names),
            "init_notes": [], "sensitivity_method": FORWARD,
            "sensitivities": {pnames[i]: S[k] for k, i in enumerate(wrt)}}
    given = {pnames[i]: n for i, n in zip(wrt, names, strict=True)}
    meta["sensitivities"].update({n: meta["sensitivities"][pn] for pn, n in given.items()})
    return Result(grid.copy(), Y, out_names, aliases, params_out, units, meta)


def sensitivities(model: Any, params: Sequence[str], stop_time: float = 1.0,
                  interval: float | None = None, **kw: Any):
    """``simulate(model, stop_time, interval, sensitivities=params, **kw)``."""
    from ..simulate import simulate

    return simulate(model, stop_time, interval, sensitivities=list(params), **kw)


def finite_difference_sensitivities(model: Any, names: Sequence[str], *, stop_time: float,
                                    start_time: float = 0.0, interval: float | None = None,
                                    grid: np.ndarray | None = None,
                                    params: dict[str, Any] | None = None,
                                    outputs: Sequence[str] | None = None, rtol: float = 1e-6,
                                    atol: float = 1e-8, max_step: float | None = None,
                                    max_steps: int = 100000, inputs: Any = None,
                                    step: float | None = None, solver: str = "auto"):
    """Central finite differences ``(y(p + h e_i) - y(p - h e_i)) / 2h`` of whole simulations,
    for any model (events included), on the output grid (the right limit at an event on the
    grid). ``step``: relative step h / max(|p_i|, 1e-8) (default ``rtol ** (1/3)``). The result
    is the unperturbed run on the grid with ``meta["sensitivities"]`` and
    ``meta["sensitivity_method"]`` saying "central finite differences"."""
    from ..compiler import CompiledModel
    from ..compiler import compile as compile_model
    from ..core.units import with_units
    from ..overrides import split_overrides
    from ..result import Result
    from ..simulate import simulate
    from ..validate import output_grid
    from .sweeps import on_grid

    compiled = model if isinstance(model, CompiledModel) else compile_model(model)
    dae = compiled.dae
    params = with_units(dict(params or {}), compiled)
    wrt = parameter_indices(dae, names)
    pnames = [q.name for q in dae.parameters] + [u.name for u in dae.inputs]
    p_over, _ = split_overrides(dae, params)
    p = dae.p_vector(p_over)
    if grid is None:
        grid = output_grid(start_time, stop_time, interval)
    grid = np.asarray(grid, dtype=float)
    h_rel = float(step) if step is not None else max(rtol, 1e-15) ** (1.0 / 3.0)
    run = {"stop_time": float(grid[-1]), "start_time": float(grid[0]), "rtol": rtol,
           "atol": atol, "max_step": max_step, "max_steps": max_steps, "inputs": inputs,
           "solver": solver}
    interval_ = float(grid[1] - grid[0]) if len(grid) > 1 else None
    t_start = _time.perf_counter()
    base = simulate(compiled, interval=interval_, params=params, outputs=outputs, **run)
    out_names = list(base.names)
    Y = on_grid(base, out_names, grid)
    sens: dict[str, np.ndarray] = {}
    steps = {}
    for i, name in zip(wrt, names, strict=True):
        h = h_rel * max(abs(p[i]), 1e-8)
        ys = []
        for sgn in (1.0, -1.0):
            over = dict(params)
            for k in list(over):         # the name as given may be an alias of pnames[i]
                if k in (name, pnames[i]):
                    del over[k]
            over[pnames[i]] = p[i] + sgn * h
            r = simulate(compiled, interval=interval_, params=over, outputs=out_names, **run)
            ys.append(on_grid(r, out_names, grid))
        sens[pnames[i]] = (ys[0] - ys[1]) / (2.0 * h)
        sens[name] = sens[pnames[i]]
        steps[pnames[i]] = h
    meta = dict(base.meta)
    meta["run_seconds"] = _time.perf_counter() - t_start
    meta["sensitivity_method"] = (f"central finite differences (relative step {h_rel:.3g}, "
                                  f"{2 * len(wrt) + 1} simulations)")
    meta["sensitivity_steps"] = steps
    meta["sensitivities"] = sens
    return Result(grid.copy(), Y, out_names, dict(base.aliases), dict(base.parameters),
                  dict(base.units), meta)


def sensitivity_of(result: Any, name: str, param: str) -> np.ndarray:
    """d(name)/d(param) along ``result.time`` from ``result.meta["sensitivities"]``."""
    table = result.meta.get("sensitivities")
    if not table:
        raise ParameterError("the result has no sensitivities: simulate(..., "
                             "sensitivities=[...])")
    if param not in table:
        raise ParameterError(f"no sensitivities to {param!r}; computed: "
                             f"{', '.join(sorted(table))}")
    S = table[param]
    if name in result._index:
        return S[:, result._index[name]]
    if name in result.aliases:
        rep, sign = result.aliases[name]
        return sign * sensitivity_of(result, rep, param)
    if name in result.parameters:
        return np.full(len(result.time), 1.0 if name == param else 0.0)
    raise ParameterError(f"no variable {name!r} in the result")
