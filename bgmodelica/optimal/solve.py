"""``optimize``: pose the problem, warm-start from a simulation, solve by collocation, check
by re-simulation, refine the mesh until they agree."""

from __future__ import annotations

import math
import time as _time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .collocation import Solution, Trajectory, solve
from .problem import Bounds, OptimizationError, Problem, make_problem
from .result import OptimalControl

#: IPOPT statuses taken as a solution
_SOLVED = {"Solve_Succeeded", "Solved_To_Acceptable_Level"}


def optimize(model: Any, controls: Mapping[str, Bounds | None] | Sequence[str], *,
             initial: Mapping[str, float] | None = None,
             final: Mapping[str, float] | None = None, stop_time: float | None = None,
             minimize_time: bool = False, lagrange: str | None = None,
             mayer: str | None = None, path: Mapping[str, Bounds] | None = None,
             params: Mapping[str, Any] | None = None, intervals: int = 40,
             tol: float = 1e-4, max_refinements: int = 4, units: str = "error",
             max_iter: int = 3000) -> OptimalControl:
    """The controls that steer ``model`` (a component, compiled model or MODEL reference)
    optimally.

    controls: top-level inputs to optimize, ``{name: (low, high)}`` (None or a list of names:
    unbounded); the inputs not named keep their values (``params``). initial: values of
    states (or other variables) at t = 0 [their units]; the other states start as in
    ``simulate`` (start values, initial equations). final: values at the final time (other
    states are free). stop_time: the fixed horizon [s]; ``minimize_time=True`` makes the
    horizon the objective (``stop_time`` then is its first guess). lagrange: text of the
    running cost integrated over the horizon (``"U1^2 + U2^2"``), mayer: text of a cost at the
    final time; both in the model's variable, parameter and input names. path: ``{expression:
    (low, high)}`` held along the trajectory. params: parameter / input overrides.

    Solved by Radau collocation (:mod:`bgmodelica.optimal.collocation`) on ``intervals``
    equal intervals, warm-started by a simulation with constant controls; the optimal
    controls (piecewise constant) are then fed to ``simulate`` as a table and the mesh is
    refined where the states drift apart, up to ``max_refinements`` times, until the largest
    state deviation is below ``tol``. Raises :class:`OptimizationError` for a model with
    events, a minimum-time problem with unbounded controls, or a problem IPOPT finds no
    solution to (its diagnosis in the message)."""
    from ..compiler import CompiledModel, compile

    t_start = _time.perf_counter()
    compiled = model if isinstance(model, CompiledModel) else compile(model, units=units)
    if minimize_time:
        guess_t, horizon = stop_time, None
    else:
        if stop_time is None:
            raise OptimizationError("give a horizon (stop_time, --stop-time T) or minimize "
                                    "time")
        guess_t, horizon = stop_time, stop_time
    if intervals < 1:
        raise OptimizationError(f"intervals {intervals}: need at least 1")
    problem = make_problem(compiled, controls, initial=initial, final=final,
                           stop_time=horizon, lagrange=lagrange, mayer=mayer, path=path,
                           params=params, time_guess=guess_t)
    mesh = np.linspace(0.0, 1.0, intervals + 1)
    guess = warm_start(problem, mesh)
    history = []
    for attempt in range(max_refinements + 1):
        sol = solve(problem, guess, max_iter=max_iter)
        _check(sol, problem)
        resim, error, _ = resimulate(problem, sol.trajectory)
        history.append({"intervals": len(sol.trajectory.mesh) - 1, "objective": sol.objective,
                        "resimulation_error": error, "iterations": sol.iterations,
                        "seconds": sol.seconds})
        if error <= tol or attempt == max_refinements:
            break
        mesh = refine(sol.trajectory.mesh, local_errors(problem, sol.trajectory), tol)
        guess = interpolate(sol.trajectory, mesh)
    return OptimalControl(problem, sol, resim, error, history,
                          _time.perf_counter() - t_start)


def _check(sol: Solution, problem: Problem) -> None:
    """Refuse a run IPOPT did not solve, with its diagnosis in one line: the final
    conditions the re-simulated last iterate misses, else the worst constraint groups."""
    if sol.status in _SOLVED:
        return
    misses = _final_misses(problem, sol.trajectory)
    worst = [(k, v) for k, v in sol.violation.items() if v > 1e-6]
    named = [(k, v) for k, v in worst if k not in ("collocation", "algebraic equations")]
    why = "; ".join(f"{k} violated by {v:.3g}" for k, v in (named or worst)[:3])
    if misses:
        why = "its last iterate re-simulated reaches " + ", ".join(misses)
    if sol.status in ("Infeasible_Problem_Detected", "Restoration_Failed",
                      "Error_In_Step_Computation"):
        head = "the constraints cannot all be met"
        if problem.final and any(math.isfinite(b) for lo_hi in problem.bounds for b in lo_hi):
            head += " within the control bounds"
    elif sol.status == "Maximum_Iterations_Exceeded":
        head = f"no convergence in {sol.iterations} iterations"
    else:
        head = "the solver stopped"
    raise OptimizationError(
        f"no solution for {problem.compiled.name}: {head} (IPOPT: {sol.status}"
        + (f"; {why}" if why else "") + ")")


def _final_misses(problem: Problem, traj: Trajectory) -> list[str]:
    """``"rotor.phi = 8.1 (not 10)"`` for each final condition the model, driven by the
    controls of ``traj``, misses (none if it cannot be simulated)."""
    from ..errors import ModelError

    if not problem.final:
        return []
    try:
        res, _, _ = resimulate(problem, traj)
    except ModelError:
        return []
    out = []
    for c in problem.final:
        name = c.name
        got = float(res[name][-1])
        if abs(got - c.lo) > 1e-6 * max(1.0, abs(c.lo)):
            out.append(f"{name} = {got:.6g} (not {c.lo:g})")
    return out


def warm_start(problem: Problem, mesh: np.ndarray) -> Trajectory:
    """A first guess: a simulation with constant controls (their start values, clipped to
    the bounds), the states with a final value shifted linearly to reach it; the start values
    held if the simulation fails."""
    from ..errors import ModelError
    from ..simulate import simulate

    dae = problem.dae
    T = problem.time_guess
    traj = Trajectory(mesh, T, np.zeros((3 * (len(mesh) - 1) + 1, dae.x.numel())),
                      np.zeros((3 * (len(mesh) - 1), dae.z.numel())),
                      np.tile(problem.p[problem.slots], (len(mesh) - 1, 2)))
    times = traj.times()
    try:
        sim = simulate(problem.compiled, stop_time=T, interval=T / max(200, len(times)),
                       params={**problem.params, **problem.start,
                               **dict(zip(problem.controls, problem.p[problem.slots],
                                          strict=True))},
                       outputs=dae.state_names + dae.algebraic_names)
        traj.X = np.column_stack([np.interp(times, sim.time, sim[n]) for n in dae.state_names])
        if dae.z.numel():
            traj.Z = np.column_stack([np.interp(times[1:], sim.time, sim[n])
                                      for n in dae.algebraic_names])
    except ModelError:
        traj.X[:] = problem.x0
        traj.Z[:] = problem.z0
    if not np.all(np.isfinite(traj.X)) or not np.all(np.isfinite(traj.Z)):
        traj.X[:] = problem.x0
        traj.Z[:] = problem.z0
    for i, target in _final_states(problem).items():
        traj.X[:, i] += (times / T) * (target - traj.X[-1, i])
    problem.scale_x = np.maximum(np.max(np.abs(traj.X), axis=0), 1.0)
    return traj


def _final_states(problem: Problem) -> dict[int, float]:
    """The states with a final value: index -> value."""
    dae = problem.dae
    out = {}
    for c in problem.final:
        for i in range(dae.x.numel()):
            for sign in (1.0, -1.0):
                if _same(c.expr, sign * dae.x[i]):
                    out[i] = sign * c.lo
    return out


def _same(a: Any, b: Any) -> bool:
    import casadi as ca

    return bool(ca.is_equal(ca.simplify(a - b), ca.SX(0), 2))


def resimulate(problem: Problem, traj: Trajectory) -> tuple[Any, float, np.ndarray]:
    """Simulate the model driven by the piecewise-constant optimal controls (a table input):
    the result, the largest state deviation from the collocation trajectory at the mesh
    points, and the deviation at each mesh point."""
    from ..simulate import simulate

    edges = traj.T * traj.mesh
    tables = {name: traj.control_table(i) for i, name in enumerate(problem.controls)}
    res = simulate(problem.compiled, stop_time=traj.T, interval=traj.T,
                   params={**problem.params, **problem.start}, inputs=tables,
                   rtol=1e-10, atol=1e-12)
    names = problem.dae.state_names
    at = np.searchsorted(res.time, edges - 1e-12 * max(traj.T, 1.0))
    at = np.clip(at, 0, len(res.time) - 1)
    sim_x = np.column_stack([res[n][at] for n in names])
    col_x = traj.X[0::3]
    drift = np.max(np.abs(sim_x - col_x), axis=1)
    return res, float(np.max(drift)) if len(drift) else 0.0, drift


def local_errors(problem: Problem, traj: Trajectory) -> np.ndarray:
    """The largest state error made on each interval: the model integrated over the interval
    (CVODES, or IDAS for a DAE) from the collocation start, with its constant controls,
    against the collocation end point; intervals are integrated at once (a mapped
    integrator, kept on the problem)."""
    import casadi as ca

    dae = problem.dae
    n = len(traj.mesh) - 1
    if problem.interval_integrator is None:
        problem.interval_integrator = _interval_integrator(problem)
    h = traj.T * np.diff(traj.mesh)
    args = np.vstack([traj.T * traj.mesh[:-1], h, traj.U.T])
    out = problem.interval_integrator.map(n)(x0=traj.X[0:-1:3].T,
                                            z0=traj.Z[0::3].T if dae.z.numel() else 0,
                                            p=args)
    end = np.asarray(ca.DM(out["xf"])).T
    return np.max(np.abs(end - traj.X[3::3]), axis=1)


def _interval_integrator(problem: Problem):
    """``x(1)`` of ``dx/ds = h f(t0 + h s, x, z, p(ua + s (ub - ua)))``, ``0 = g``:
    parameters (t0, h, ua, ub)."""
    import casadi as ca

    from .collocation import control_parameters

    dae = problem.dae
    ua = ca.SX.sym("ua", len(problem.slots))
    ub = ca.SX.sym("ub", len(problem.slots))
    t0, h, s = ca.SX.sym("t0"), ca.SX.sym("h"), ca.SX.sym("s")
    p = control_parameters(problem, ua + s * (ub - ua))
    ode, alg = ca.substitute([dae.ode, dae.alg], [dae.t, dae.p], [t0 + h * s, p])
    spec = {"x": dae.x, "p": ca.vertcat(t0, h, ua, ub), "t": s, "ode": h * ode}
    if dae.z.numel():
        spec.update(z=dae.z, alg=alg)
    method = "idas" if dae.z.numel() else "cvodes"
    return ca.integrator("interval", method, spec, 0.0, 1.0,
                         {"abstol": 1e-12, "reltol": 1e-10, "max_num_steps": 100000})


def refine(mesh: np.ndarray, errors: np.ndarray, tol: float) -> np.ndarray:
    """Bisect the intervals whose local error exceeds an equal share ``tol / 4N`` of the
    tolerance (at least the worst one)."""
    pick = errors > tol / (4 * len(errors))
    pick[int(np.argmax(errors))] = True
    mids = 0.5 * (mesh[:-1] + mesh[1:])[pick]
    return np.sort(np.concatenate([mesh, mids]))


def interpolate(traj: Trajectory, mesh: np.ndarray) -> Trajectory:
    """``traj`` carried onto another mesh (linear in time; controls from the covering
    interval's line)."""
    new = Trajectory(mesh, traj.T, np.zeros(0), np.zeros(0), np.zeros(0))
    old_t, new_t = traj.times(), new.times()
    new.X = np.column_stack([np.interp(new_t, old_t, traj.X[:, i])
                             for i in range(traj.X.shape[1])])
    new.Z = np.column_stack([np.interp(new_t[1:], old_t[1:], traj.Z[:, i])
                             for i in range(traj.Z.shape[1])]) if traj.Z.shape[1] \
        else np.zeros((len(new_t) - 1, 0))
    mids = 0.5 * (mesh[:-1] + mesh[1:])
    k = np.clip(np.searchsorted(traj.mesh, mids) - 1, 0, len(traj.U) - 1)
    nu = traj.U.shape[1] // 2
    ua, ub = traj.U[k, :nu], traj.U[k, nu:]
    frac = [(mesh[:-1] - traj.mesh[k]) / (traj.mesh[k + 1] - traj.mesh[k]),
            (mesh[1:] - traj.mesh[k]) / (traj.mesh[k + 1] - traj.mesh[k])]
    new.U = np.hstack([ua + f[:, None] * (ub - ua) for f in frac])
    return new


__all__ = ["optimize", "OptimizationError"]
