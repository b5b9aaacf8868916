"""Consistent initialization of a :class:`CasadiDAE`.

Fixed start values are hard conditions, every other start value is a guess. A fixed state
gives its value directly; a fixed non-state (e.g. a variable demoted by index reduction) is a
condition on the states through the observation map. Free states without a condition keep
their start values (reported in ``notes``); conditions that over-determine the states are
accepted when the solution of the others satisfies them (a note: the pendulum released at
x = 0, y = -1), and raise :class:`InitializationError` with their names otherwise.
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
    """Consistent initial states and algebraic variables; ``p``: the parameter vector with
    the parameters the initial equations determine (``fixed=False``) solved."""

    x0: np.ndarray
    z0: np.ndarray
    notes: list[str] = field(default_factory=list)
    p: np.ndarray | None = None


@dataclass
class InitStructure:
    """Which states the initial conditions determine (independent of parameter values).

    x0: start values with the fixed states set; free: indices of the states solved together
    with z from ``conditions`` ``(observed index, value)`` and the model's ``n_initial``
    initial equations (``dae.initial``, rows ``initial_rows``; all when None); notes:
    states left at their start values; surplus: conditions beyond those that determine the
    states (residual expression, label, value), to hold at the solution (else ``surplus_error``);
    params: positions in ``p`` of the parameters solved with them (``fixed=False``)."""

    x0: np.ndarray
    free: list[int]
    conditions: list[tuple[int, float]]
    notes: list[str]
    n_initial: int = 0
    initial_rows: list[int] | None = None
    surplus: list[tuple[ca.SX, str, float]] = field(default_factory=list)
    surplus_error: str = ""
    params: list[int] = field(default_factory=list)

    def known_params(self, n_p: int) -> list[int]:
        """Positions in ``p`` of the parameters that are inputs of the initialization."""
        solved = set(self.params)
        return [k for k in range(n_p) if k not in solved]

    def rows(self) -> list[int]:
        """The initial equations used to solve for the states."""
        return list(range(self.n_initial)) if self.initial_rows is None else self.initial_rows

    def labels(self, dae: CasadiDAE) -> list[str]:
        """What each condition row is: a fixed start value or an initial equation."""
        out = [f"fixed start value {dae.names[k]} = {v:g}" for k, v in self.conditions]
        given = list(getattr(dae, "initial_labels", None) or [])
        return out + [given[i] if i < len(given) else f"initial equation {i}"
                      for i in self.rows()]


def _n_initial(dae: CasadiDAE) -> int:
    initial = getattr(dae, "initial", None)
    return int(initial.numel()) if initial is not None else 0


def init_structure(dae: CasadiDAE) -> InitStructure:
    """Match the fixed start values and initial equations to the states (raise
    :class:`InitializationError` naming them when they over-determine them)."""
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
    n_init = _n_initial(dae)
    st = InitStructure(x0, [], conditions, [], n_init)
    free = [i for i in range(len(x0)) if i not in fixed_states]
    params = dae.initial_parameters if n_init else []
    nz = dae.z.numel()
    exprs = [dae.observed[k] for k, _ in conditions] + [dae.initial[i] for i in range(n_init)]
    if exprs:
        xf = ca.vertcat(*[dae.x[i] for i in free]) if free else ca.SX(0, 1)
        pf = ca.vertcat(*[dae.p[k] for k in params]) if params else ca.SX(0, 1)
        sp = ca.jacobian_sparsity(ca.vertcat(_alg(dae), *exprs),
                                  ca.vertcat(xf, dae.z, pf)) if free or nz or params else None
        rows: list[list[int]] = [[] for _ in range(nz + len(exprs))]
        if sp is not None:
            for r, c in zip(*sp.get_triplet(), strict=True):
                rows[r].append(c)
        # the model's own equations first, on the algebraic variables they determine (so
        # that every algebraic variable stays matched): conditions compete for the rest
        nf = len(free)
        n_cols = nf + nz + len(params)
        first = maximum_matching([[c for c in r if nf <= c < nf + nz] for r in rows[:nz]]
                                 + [[] for _ in exprs], n_cols)
        match = maximum_matching(rows, n_cols, initial=first)
        surplus = [i for i in range(len(exprs)) if match.eq_to_var[nz + i] < 0]
        if surplus:          # kept aside: to hold at the solution of the others
            labelled = list(zip(exprs, st.labels(dae), strict=True))
            st.surplus_error = _overdetermined(dae, labelled, surplus, rows, match, free,
                                               fixed_states)
            nc = len(conditions)
            value = [conditions[i][1] if i < nc else 0.0 for i in range(len(exprs))]
            st.surplus = [(exprs[i] - value[i], labelled[i][1], value[i]) for i in surplus]
            st.conditions = [c for i, c in enumerate(conditions) if i not in surplus]
            st.initial_rows = [i for i in range(n_init) if nc + i not in surplus]
        unmatched = [free[c] for c in range(nf) if match.var_to_eq[c] < 0]
        st.params = [k for c, k in enumerate(params) if match.var_to_eq[nf + nz + c] >= 0]
    else:
        unmatched = list(free)
    if len(st.params) < len(params):
        names = [dae.parameters[k].name for k in params if k not in set(st.params)]
        st.notes.append("no initial equation determines parameter(s) " + ", ".join(names)
                        + " (fixed=false); their start values were used")
    if unmatched:
        st.notes.append("no fixed start value or initial equation for state(s) "
                        + ", ".join(dae.state_names[i] for i in unmatched)
                        + "; their start values were used")
        free = [i for i in free if i not in set(unmatched)]
    st.free = free
    return st


def _init_residual(dae: CasadiDAE, st: InitStructure) -> ca.Function:
    """``g(w, [x_pinned, p_known, t])``: conditions, initial equations and algebraic
    equations, w = [x_free, z, p_solved] (``st.params``, ``st.known_params``)."""
    unknown = ca.vertcat(*[dae.x[i] for i in st.free], dae.z, *[dae.p[k] for k in st.params])
    cond = [dae.observed[k] - v for k, v in st.conditions] \
        + [dae.initial[i] for i in st.rows()]
    pinned = [i for i in range(len(st.x0)) if i not in set(st.free)]
    known = ca.vertcat(*[dae.x[i] for i in pinned]) if pinned else ca.SX(0, 1)
    p_known = dae.p if not st.params else \
        ca.vertcat(*[dae.p[k] for k in st.known_params(dae.p.numel())])
    return ca.Function("init_g", [unknown, ca.vertcat(known, p_known, dae.t)],
                       [ca.vertcat(*cond, _alg(dae))])


def _alg(dae: CasadiDAE) -> ca.SX:
    """The algebraic equations as a column (an empty one without algebraic variables)."""
    return dae.alg if dae.alg.numel() else ca.SX(0, 1)


def initial_state_function(dae: CasadiDAE, p: np.ndarray, t0: float = 0.0,
                           tol: float = 1e-12) -> ca.Function | None:
    """``(t, p) -> x0`` solving the initial conditions symbolically (code-generatable
    ``fast_newton``, started from the solution for ``p``), for FMUs whose initial state must
    follow their parameters as native simulation does; None when the initial state is fixed
    (no conditions through the model's equations)."""
    st = init_structure(dae)
    if not st.conditions and not st.rows():
        return None
    sol = initialize(dae, p, t0)
    g = _init_residual(dae, st)
    solver = ca.rootfinder("init_solve", "fast_newton", g, {"abstol": tol, "max_iter": 50})
    pinned = [i for i in range(len(st.x0)) if i not in set(st.free)]
    t = ca.MX.sym("t")
    pm = ca.MX.sym("p", dae.p.numel())
    guess = np.concatenate([sol.x0[st.free], sol.z0, sol.p[st.params]])
    known = st.known_params(dae.p.numel())
    w = solver(ca.DM(guess), ca.vertcat(ca.DM(st.x0[pinned]),
                                        pm[known] if st.params else pm, t))
    parts = [None] * len(st.x0)
    for k, i in enumerate(st.free):
        parts[i] = w[k]
    for i in pinned:
        parts[i] = ca.MX(float(st.x0[i]))
    return ca.Function("initial_state", [t, pm], [ca.vertcat(*parts)], ["t", "p"], ["x0"])


def initialize(dae: CasadiDAE, p: np.ndarray, t0: float = 0.0,
               tol: float = 1e-10) -> InitialValues:
    """Solve the initial-value problem at ``t0`` for parameter vector ``p``.

    The conditions are the fixed start values and the model's initial equations
    (``dae.initial``, Modelica ``initial equation``), together with the algebraic equations;
    they must determine the states independently (balance checked by a matching: conditions
    left unmatched raise :class:`InitializationError` naming them and the variables they
    compete for); states without a condition keep their start values (a note). Parameters
    declared ``fixed=False`` are solved with them, their values in ``p`` the guesses: ``p``
    is updated in place with the solution (also in the result's ``p``)."""
    st, made = _prepared(dae)
    x0, free = st.x0.copy(), st.free
    z0 = dae.z_start.copy()
    n_cond = len(st.conditions) + len(st.rows())
    if not n_cond and dae.z.numel() == 0:
        return _surplus_checked(dae, st, p, t0, InitialValues(x0, z0, list(st.notes), p))
    p = np.asarray(p, dtype=float)
    guess = np.concatenate([x0[free], z0, p[st.params]])
    if "g" not in made:
        from ..events.fast import Fast

        made["pinned"] = [i for i in range(len(x0)) if i not in set(free)]
        made["g"] = _init_residual(dae, st)
        made["fast g"] = Fast(made["g"])
    pinned, g = made["pinned"], made["g"]
    known = p[st.known_params(len(p))] if st.params else p
    args = np.concatenate([x0[pinned], known, [t0]])
    r0 = made["fast g"](guess, args)[0].copy()
    if r0.size and np.max(np.abs(r0)) > tol:
        solver = ca.rootfinder("init", "newton", g, {"abstol": tol, "max_iter": 100,
                                                     "error_on_fail": False})
        sol = np.asarray(solver(guess, args)).ravel()
        r1 = np.asarray(g(sol, args)).ravel()
        ok = _converged(r1, tol)
        if not ok:
            sol, r1, ok = _trust_region(g, guess, args, sol, r1, tol)
        if not ok:
            with np.errstate(invalid="ignore"):
                worst = int(np.argmax(np.where(np.isfinite(r1), np.abs(r1), np.inf)))
            labels = st.labels(dae)
            what = (labels[worst] if worst < n_cond
                    else dae.algebraic_names[worst - n_cond])
            size = np.max(np.abs(r1)) if np.all(np.isfinite(r1)) else np.nan
            hint = ("; the initial equations or fixed start values may contradict each other "
                    "or the model" if st.rows() else "")
            raise InitializationError(
                f"initialization did not converge: residual {size:.3g} at "
                f"{what}; give better start values (guesses) for the algebraic variables"
                + hint)
        guess = sol
    x0[free] = guess[:len(free)]
    z0 = guess[len(free):len(guess) - len(st.params)]
    if st.params:
        p[st.params] = guess[len(guess) - len(st.params):]
    return _surplus_checked(dae, st, p, t0, InitialValues(x0, z0, list(st.notes), p))


def _prepared(dae: CasadiDAE) -> tuple[InitStructure, dict]:
    """:func:`init_structure` of ``dae`` (not to be changed: ``x0`` is copied before use)
    and a dict for what is made from it (the residual function), kept in ``dae.cache`` for
    these start values and equations (a copy with other start values makes its own)."""
    made_for = (dae.fixed, dae.x_start, dae.initial, dae.observed, dae.alg, dae.parameters)
    seen = dae.cache.get("init structure")
    if seen is None or any(a is not b for a, b in zip(seen[0], made_for, strict=True)):
        seen = dae.cache["init structure"] = (made_for, init_structure(dae), {})
    return seen[1], seen[2]


def _converged(r: np.ndarray, tol: float) -> bool:
    return bool(np.all(np.isfinite(r)) and np.max(np.abs(r), initial=0.0) <= max(1e3 * tol, 1e-8))


#: largest initialization problem the trust-region fallback takes on (it is dense)
TRUST_REGION_SIZE = 400


def _trust_region(g: ca.Function, guess: np.ndarray, args: np.ndarray, sol: np.ndarray,
                  r1: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray, bool]:
    """A second attempt when Newton's method failed (implicit equations far from their
    start values, e.g. time constants of 1e-5 s): Powell's trust-region method on the
    unknowns scaled by their start values and the residuals by their Jacobian rows at the
    start. Returns the better solution, its residual and whether it converged (judged on
    the scaled residuals)."""
    if not 0 < guess.size <= TRUST_REGION_SIZE:
        return sol, r1, False
    from scipy.optimize import root

    scale = np.where(np.abs(guess) > 0, np.abs(guess), 1.0)
    jac = g.factory("init_jac", ["i0", "i1"], ["jac:o0:i0"])
    with np.errstate(all="ignore"):
        j0 = np.abs(np.asarray(jac(guess, args)) * scale).max(axis=1)
    rows = np.where(np.isfinite(j0) & (j0 > 0), 1.0 / j0, 1.0)

    def residual(y: np.ndarray) -> np.ndarray:
        return np.asarray(g(y * scale, args)).ravel() * rows

    def jacobian(y: np.ndarray) -> np.ndarray:
        return np.asarray(jac(y * scale, args)) * scale * rows[:, None]

    with np.errstate(all="ignore"):
        out = root(residual, guess / scale, jac=jacobian, method="hybr")
        found = out.x * scale
        r2 = np.asarray(g(found, args)).ravel()
    if _converged(r2 * rows, tol) and np.all(np.isfinite(r2)):
        return found, r2, True
    return sol, r1, False


def _surplus_checked(dae: CasadiDAE, st: InitStructure, p: np.ndarray, t0: float,
                     init: InitialValues) -> InitialValues:
    """``init`` with a note when over-specifying conditions hold at it; raise
    :class:`InitializationError` (the over-determined message) when one does not."""
    if not st.surplus:
        return init
    f = ca.Function("init_surplus", [dae.x, dae.z, dae.p, dae.t],
                    [ca.vertcat(*[e for e, _, _ in st.surplus])])
    with np.errstate(all="ignore"):
        r = np.asarray(f(init.x0, init.z0, p, t0), dtype=float).ravel()
    scale = np.array([max(1.0, abs(v)) for _, _, v in st.surplus])
    bad = ~(np.abs(r) <= 1e-6 * scale)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise InitializationError(f"{st.surplus_error} ({st.surplus[k][1]} is off by "
                                  f"{r[k]:.3g} at the solution of the others)")
    init.notes.append("; ".join(label for _, label, _ in st.surplus) + " over-specifies the "
                      "initial state; it agrees with the other conditions and was accepted")
    return init


def _overdetermined(dae: CasadiDAE, conditions: list[tuple[ca.SX, str]], surplus: list[int],
                    rows: list[list[int]], match, free: list[int], fixed_states: set[int]
                    ) -> str:
    """The message for conditions that over-determine the initial values: the surplus
    conditions, the other conditions they compete with and the variables involved (the
    over-determined part of the Dulmage-Mendelsohn decomposition)."""
    from ..structure.diagnosis import dulmage_mendelsohn

    nz = dae.z.numel()
    unknown_names = [dae.state_names[i] for i in free] + list(dae.algebraic_names)
    dm = dulmage_mendelsohn(rows, len(free) + nz, match)
    involved = [conditions[e - nz][1] for e in dm.overdetermined_eqs
                if e >= nz and e - nz not in surplus]
    variables = [unknown_names[v] for v in dm.overdetermined_vars]
    pinned = [dae.state_names[i] for i in sorted(fixed_states)
              if any(ca.depends_on(conditions[s][0], dae.x[i]) for s in surplus)]
    variables += [f"{n} (fixed start value)" for n in pinned]
    fixed_starts = [conditions[s][1] for s in surplus if conditions[s][1].startswith("fixed")]
    text = ("the initial conditions are over-determined: "
            + "; ".join(conditions[s][1] for s in surplus)
            + (f" -- competing with {'; '.join(involved)}" if involved else "")
            + (f" -- for {', '.join(variables)}" if variables else " -- it depends on no "
               "free state or algebraic variable")
            + f" (states: {', '.join(dae.state_names) or 'none'}). ")
    if fixed_starts:
        text += "Set fixed=False on these or on the states they conflict with"
    else:
        text += ("Remove one of the conflicting initial equations, or set fixed=False on the "
                 "start values they conflict with")
    return text
