"""The CasADi functions of a hybrid model, built once from its :class:`CasadiDAE` and shared by
the event loop (and, later, the FMU runtime): indicators, the event step and the integrators.

All functions take ``(t, x, z, p)``; ``p`` ends with the discrete slots (relation values,
discrete variables, ``pre`` values, clocks, table coefficients).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from ..backends.casadi_dae import CasadiDAE
from ..core.flatmodel import HybridPart
from ..errors import EquationError, SimulationError


@dataclass
class HybridFunctions:
    """Compiled pieces of a hybrid model (see the module docstring)."""

    dae: CasadiDAE
    state_rel: list[int]        # relations located as state events (indices in relations)
    time_rel: list[int]         # relations on time alone, affine: time events computed exactly
    rel_slot: np.ndarray        # p index of each relation's value
    strict: np.ndarray          # bool per relation
    indicators: ca.Function     # (t, x, z, p) -> g of the state relations
    step: ca.Function           # (t, x, z, p) -> g_all, dgdt_all, cond, assign, reinit, pre, obs
    branch_of: list[list[int]]  # per when: indices of its branches in cond
    assign_of: list[list[tuple[int, int]]]   # per branch: (p index, position in assign)
    reinit_of: list[list[tuple[str, int]]]   # per branch: (variable name, position in reinit)
    pre_slot: np.ndarray        # p index of each pre slot
    pre_discrete: np.ndarray    # bool: the pre source is a discrete-valued variable
    discrete_obs: np.ndarray    # obs indices of equation-defined discrete variables
    alg_solver: ca.Function | None    # z from (t, x, p), DAE models only
    #: bool per branch: its condition mentions initial() (it fires at initialization even
    #: when the rest of the condition is already true, as in ``when {c, initial()}``)
    initial_branch: np.ndarray | None = None
    #: the algebraic residual, (z, [t, x, p]) -> alg (DAE models only)
    alg: ca.Function | None = None
    #: (t, x, z, p) -> the guards and arguments of the functions run at events, stacked
    calls: ca.Function | None = None
    #: per branch: its runtime calls as (function, guard position, argument positions,
    #: p indices of the outputs, text), in order
    call_of: list[list[tuple]] = field(default_factory=list)

    @property
    def relations(self):
        return self.dae.hybrid.relations if self.dae.hybrid is not None else []


def build(dae: CasadiDAE) -> HybridFunctions:
    """Build (once per DAE, cached in ``dae.cache``) the hybrid functions."""
    if "hybrid" in dae.cache:
        return dae.cache["hybrid"]
    hyb = dae.hybrid or HybridPart()
    t, x, z, p = dae.t, dae.x, dae.z, dae.p
    nb = dae.n_base
    rels = hyb.relations
    g_all = ca.vertcat(*[r.indicator for r in rels]) if rels else ca.SX(0, 1)
    dgdt = ca.jacobian(g_all, t) if rels else ca.SX(0, 1)
    state_rel, time_rel = [], []
    for k, r in enumerate(rels):
        g = r.indicator
        on_state = (x.numel() and ca.depends_on(g, x)) or (z.numel() and ca.depends_on(g, z))
        if not on_state and not ca.depends_on(dgdt[k], t):
            time_rel.append(k)
        else:
            state_rel.append(k)
    g_state = ca.vertcat(*[rels[k].indicator for k in state_rel]) if state_rel else ca.SX(0, 1)
    conds, assigns, reinits = [], [], []
    branch_of, assign_of, reinit_of = [], [], []
    for w in hyb.whens:
        ids = []
        for b in w.branches:
            ids.append(len(conds))
            conds.append(b.condition)
            assign_of.append([(nb + slot, len(assigns) + k)
                              for k, (slot, _) in enumerate(b.assignments)])
            assigns += [v for _, v in b.assignments]
            reinit_of.append([(name, len(reinits) + k) for k, (name, _) in enumerate(b.reinits)])
            reinits += [v for _, v in b.reinits]
        branch_of.append(ids)
    for name, _ in (r for ro in reinit_of for r in ro):
        _check_reinit_target(dae, name)
    for w in hyb.whens:
        for b in w.branches:
            for slot, value in b.assignments:
                if ca.depends_on(value, p[nb + slot]):
                    name = dae.discretes[slot].name
                    raise EquationError(
                        f"{w.origin}: when {b.text}: the value assigned to {name} depends on "
                        f"{name} itself through the model's equations (an algebraic loop at the "
                        f"event); assign from pre({name}) or break the loop")
    pre_src, pre_disc = [], []
    for _slot, name in hyb.pre:
        expr, discrete = _value_of(dae, name)
        pre_src.append(expr)
        pre_disc.append(discrete)
    obs = dae.observed
    discrete_obs = [dae.observed_index[n] for n in sorted(dae.discrete_names)
                    if dae.observed_index[n] < dae.n_variables]
    vec = lambda items: ca.vertcat(*items) if items else ca.SX(0, 1)  # noqa: E731
    # dense outputs: the buffered evaluation (events.fast) returns the stored entries only
    step = ca.Function("event_step", [t, x, z, p],
                       [ca.densify(e) for e in (g_all, dgdt, vec(conds), vec(assigns),
                                                 vec(reinits), vec(pre_src), obs)],
                       ["t", "x", "z", "p"],
                       ["g", "dgdt", "cond", "assign", "reinit", "pre", "obs"])
    indicators = ca.Function("indicators", [t, x, z, p], [ca.densify(g_state)])
    alg_solver = g = None
    if z.numel():
        g = ca.Function("alg", [z, ca.vertcat(t, x, p)], [dae.alg])
        alg_solver = ca.rootfinder("alg_solve", "newton", g,
                                   {"abstol": 1e-12, "max_iter": 50, "error_on_fail": False})
    out = HybridFunctions(
        dae, state_rel, time_rel,
        np.array([nb + r.slot for r in rels], dtype=int),
        np.array([r.strict for r in rels], dtype=bool), indicators, step,
        branch_of, assign_of, reinit_of,
        np.array([nb + slot for slot, _ in hyb.pre], dtype=int),
        np.array(pre_disc, dtype=bool), np.array(discrete_obs, dtype=int), alg_solver,
        alg=g)
    if hyb.initial >= 0 and conds:
        init_sym = p[nb + hyb.initial]
        out.initial_branch = np.array([bool(ca.depends_on(c, init_sym)) for c in conds])
    _runtime_calls(out, hyb, t, x, z, p, nb)
    dae.cache["hybrid"] = out
    return out


def solve_algebraic(fn: HybridFunctions, guess, args: np.ndarray) -> np.ndarray:
    """The algebraic variables for ``args`` = [t, x, p] by Newton's method from ``guess``;
    where it fails, the guess itself when its residual is the smaller (IDAS starts from it)."""
    z = np.asarray(fn.alg_solver(guess, args)).ravel()
    if not fn.alg_solver.stats()["success"] and _size(fn.alg(guess, args)) < _size(
            fn.alg(z, args)):
        return np.array(guess, dtype=float)
    return z


def _size(r) -> float:
    """Largest magnitude of a residual (inf when not finite)."""
    r = np.asarray(r, dtype=float).ravel()
    return float(np.max(np.abs(r), initial=0.0)) if np.all(np.isfinite(r)) else np.inf


def _runtime_calls(out: HybridFunctions, hyb: HybridPart, t, x, z, p, nb: int) -> None:
    """The functions a fired branch runs on numbers (:class:`~bgmodelica.core.flatmodel.
    FlatCall`): one CasADi function gives all their guards and arguments."""
    exprs: list = []
    for w in hyb.whens:
        for b in w.branches:
            entries = []
            for c in b.calls:
                g = len(exprs)
                exprs += [c.guard, *c.args]
                entries.append((c.function, g, np.arange(g + 1, g + 1 + len(c.args)),
                                np.array([nb + s for s in c.outputs], dtype=int), c.text))
            out.call_of.append(entries)
    if exprs:
        out.calls = ca.Function("runtime_args", [t, x, z, p],
                                [ca.densify(ca.vertcat(*[ca.SX(e) for e in exprs]))])


def run_calls(fn: HybridFunctions, t: float, x, z, p: np.ndarray, fired: list[int]) -> None:
    """Run the functions of the ``fired`` branches on numbers, writing their outputs into
    ``p`` (in order: each sees the outputs of those before it)."""
    for b in fired:
        for function, g, pos, slots, text in fn.call_of[b]:
            vals = np.asarray(fn.calls(t, x, z, p), dtype=float).ravel()
            if not vals[g]:
                continue
            try:
                p[slots] = function(vals[pos])
            except SimulationError:
                raise
            except Exception as err:  # noqa: BLE001 -- one line naming the call
                raise SimulationError(f"{text} at t = {t:g} s: {err}", t) from None


def _value_of(dae: CasadiDAE, name: str) -> tuple[ca.SX, bool]:
    """The SX of variable ``name`` in terms of (t, x, z, p), and whether it is discrete."""
    for k, d in enumerate(dae.discretes):
        if d.name == name:
            return dae.p[dae.n_base + k], True
    sign = 1.0
    if name not in dae.observed_index and name in dae.aliases:
        name, sign = dae.aliases[name]
    if name not in dae.observed_index:
        raise EquationError(f"pre({name}): {name} is not a variable of the model")
    k = dae.observed_index[name]
    return sign * dae.observed[k], name in dae.discrete_names


def _check_reinit_target(dae: CasadiDAE, name: str) -> None:
    rep = dae.aliases.get(name, (name, 1.0))[0]
    if rep in dae.state_names:
        return
    if rep not in dae.differentiated:
        raise EquationError(
            f"reinit({name}, ...): {name} is not a state of the model (it never appears "
            "differentiated, so it cannot be restarted); reinit() applies to variables x with "
            "der(x) in the equations")
