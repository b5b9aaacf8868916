"""Consistent initialization of a :class:`CasadiDAE`.

Fixed start values are hard conditions, every other start value is a guess. A fixed state
gives its value directly; a fixed non-state (e.g. a variable demoted by index reduction) is a
condition on the states through the observation map. Free states without a condition keep
their start values (reported in ``notes``); conditions that over-determine the states raise
:class:`InitializationError` with their names.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from ..errors import InitializationError
from ..structure import maximum_matching
from .casadi_dae import CasadiDAE


@dataclass
class InitialValues:
    x0: np.ndarray
    z0: np.ndarray
    notes: list[str] = field(default_factory=list)


@dataclass
class InitStructure:
    """Which states the initial conditions determine (independent of parameter values).

    x0: start values with the fixed states set; free: indices of the states solved together
    with z from ``conditions`` ``(observed index, value)``; notes: states left at their start
    values."""

    x0: np.ndarray
    free: list[int]
    conditions: list[tuple[int, float]]
    notes: list[str]


def init_structure(dae: CasadiDAE) -> InitStructure:
    """Match the fixed start values to the states (raise when they over-determine them)."""
    state_pos = {n: k for k, n in enumerate(dae.state_names)}
    x0 = dae.x_start.copy()
    fixed_states = set()
    conditions: list[tuple[int, float]] = []
    for k, value in dae.fixed:
        name = dae.names[k]
        if name in state_pos:
            x0[state_pos[name]] = value
            fixed_states.add(state_pos[name])
        else:
            conditions.append((k, value))
    free = [i for i in range(len(x0)) if i not in fixed_states]
    notes: list[str] = []
    nz = dae.z.numel()
    if conditions:
        cond_expr = ca.vertcat(*[dae.observed[k] for k, _ in conditions])
        xf = ca.vertcat(*[dae.x[i] for i in free]) if free else ca.SX(0, 1)
        sp = ca.jacobian_sparsity(ca.vertcat(dae.alg, cond_expr),
                                  ca.vertcat(xf, dae.z)) if free or nz else None
        rows: list[list[int]] = [[] for _ in range(nz + len(conditions))]
        if sp is not None:
            for r, c in zip(*sp.get_triplet(), strict=True):
                rows[r].append(c)
        # the model's own equations first: conditions compete for what they leave free
        first = maximum_matching(rows[:nz] + [[] for _ in conditions], len(free) + nz)
        match = maximum_matching(rows, len(free) + nz, initial=first)
        surplus = [conditions[i][0] for i in range(len(conditions))
                   if match.eq_to_var[nz + i] < 0]
        if surplus:
            names = ", ".join(dae.names[k] for k in surplus)
            raise InitializationError(
                f"the initial conditions are over-determined: fixed start values of {names} "
                f"cannot be met independently (states: {', '.join(dae.state_names)}). "
                "Set fixed=False on these or on the states they conflict with")
        unmatched = [free[c] for c in range(len(free)) if match.var_to_eq[c] < 0]
    else:
        unmatched = list(free)
    if unmatched:
        notes.append("no fixed start value for state(s) "
                     + ", ".join(dae.state_names[i] for i in unmatched)
                     + "; their start values were used")
        free = [i for i in free if i not in set(unmatched)]
    return InitStructure(x0, free, conditions, notes)


def _init_residual(dae: CasadiDAE, st: InitStructure) -> ca.Function:
    """``g(w, [x_pinned, p, t])``: conditions and algebraic equations, w = [x_free, z]."""
    unknown = ca.vertcat(*[dae.x[i] for i in st.free], dae.z)
    cond = ca.vertcat(*[dae.observed[k] - v for k, v in st.conditions]) if st.conditions \
        else ca.SX(0, 1)
    pinned = [i for i in range(len(st.x0)) if i not in set(st.free)]
    known = ca.vertcat(*[dae.x[i] for i in pinned]) if pinned else ca.SX(0, 1)
    return ca.Function("init_g", [unknown, ca.vertcat(known, dae.p, dae.t)],
                       [ca.vertcat(cond, dae.alg)])


def initial_state_function(dae: CasadiDAE, p: np.ndarray, t0: float = 0.0,
                           tol: float = 1e-12) -> ca.Function | None:
    """``(t, p) -> x0`` solving the initial conditions symbolically (code-generatable
    ``fast_newton``, started from the solution for ``p``), for FMUs whose initial state must
    follow their parameters as native simulation does; None when the initial state is fixed
    (no conditions through the model's equations)."""
    st = init_structure(dae)
    if not st.conditions:
        return None
    sol = initialize(dae, p, t0)
    g = _init_residual(dae, st)
    solver = ca.rootfinder("init_solve", "fast_newton", g, {"abstol": tol, "max_iter": 50})
    pinned = [i for i in range(len(st.x0)) if i not in set(st.free)]
    t = ca.MX.sym("t")
    pm = ca.MX.sym("p", dae.p.numel())
    guess = np.concatenate([sol.x0[st.free], sol.z0])
    w = solver(ca.DM(guess), ca.vertcat(ca.DM(st.x0[pinned]), pm, t))
    parts = [None] * len(st.x0)
    for k, i in enumerate(st.free):
        parts[i] = w[k]
    for i in pinned:
        parts[i] = ca.MX(float(st.x0[i]))
    return ca.Function("initial_state", [t, pm], [ca.vertcat(*parts)], ["t", "p"], ["x0"])


def initialize(dae: CasadiDAE, p: np.ndarray, t0: float = 0.0,
               tol: float = 1e-10) -> InitialValues:
    """Solve the initial-value problem at ``t0`` for parameter vector ``p``."""
    st = init_structure(dae)
    x0, free, conditions, notes = st.x0.copy(), st.free, st.conditions, list(st.notes)
    nz = dae.z.numel()
    z0 = dae.z_start.copy()
    if not conditions and nz == 0:
        return InitialValues(x0, z0, notes)
    guess = np.concatenate([x0[free], z0])
    pinned = [i for i in range(len(x0)) if i not in set(free)]
    g = _init_residual(dae, st)
    args = np.concatenate([x0[pinned], p, [t0]])
    r0 = np.asarray(g(guess, args)).ravel()
    if r0.size and np.max(np.abs(r0)) > tol:
        solver = ca.rootfinder("init", "newton", g, {"abstol": tol, "max_iter": 100,
                                                     "error_on_fail": False})
        sol = np.asarray(solver(guess, args)).ravel()
        r1 = np.asarray(g(sol, args)).ravel()
        if not np.all(np.isfinite(r1)) or np.max(np.abs(r1)) > max(1e3 * tol, 1e-8):
            worst = int(np.argmax(np.abs(r1)))
            what = (dae.names[conditions[worst][0]] if worst < len(conditions)
                    else dae.algebraic_names[worst - len(conditions)])
            raise InitializationError(
                f"initialization did not converge: residual {np.max(np.abs(r1)):.3g} at "
                f"{what}; give better start values (guesses) for the algebraic variables")
        guess = sol
    x0[free] = guess[:len(free)]
    z0 = guess[len(free):]
    return InitialValues(x0, z0, notes)
