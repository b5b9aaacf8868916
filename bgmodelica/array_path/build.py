"""Solve the blocks of a lowered model in order and assemble its :class:`CasadiDAE`.

Each block is solved for its unknowns as one MX operation: a residual ``r`` linear in its
own unknowns ``u`` with a coefficient that does not depend on them gives
``u = -r(u = 0) / (dr/du)``, the coefficient being the directional derivative along a seed
that is 1 on ``u`` (each row uses only its own unknown of the block, see
:mod:`bgmodelica.structure.explicit_order`). Solutions are substituted block after block,
and the result is evaluated once on the SX symbols the rest of the tool works with: the ODE
``der(x) = f(t, x, p)`` and the observation of every variable.
"""

from __future__ import annotations

from itertools import compress, repeat
from operator import attrgetter

import casadi as ca
import numpy as np

from ..backends.casadi_dae import CSE_UP_TO, CasadiDAE
from ..core.flatmodel import FlatVariable
from ..core.variables import TIME
from ..structure.explicit_order import ExplicitOrder
from .aliases import Aliases
from .collect import Collected
from .lowering import Lowered

_NAME, _DECL = attrgetter("name"), attrgetter("decl")


def solve_blocks(low: Lowered, order: ExplicitOrder, unknown: np.ndarray) -> ca.MX | str:
    """Every column of ``x`` as an MX expression of the states, ``p`` and ``t`` (the
    unknowns, columns ``unknown``, replaced by their solutions), or why a block does not
    solve explicitly."""
    n = low.n
    starts = np.concatenate([[0], np.cumsum(low.sizes)]).astype(np.int64)
    current = low.x
    coefficients: list[ca.MX] = []        # those that might cancel (see _cancelled)
    pairs = low.rows * (low.n + low.n_p + 1) + low.cols
    values, counts = np.unique(pairs, return_counts=True)
    twice = np.zeros(int(starts[-1]), dtype=bool)      # rows using a column twice
    twice[values[counts > 1] // (low.n + low.n_p + 1)] = True
    for b, rows in order.steps():
        r = low.blocks[b]
        here = np.arange(starts[b], starts[b + 1]) if rows is None else starts[b] + rows
        if rows is not None:
            r = r[rows.tolist()]
        mine = unknown[order.unknown_of[here]]
        seed = ca.DM(_column(n, np.sort(mine)), 1.0)
        coefficient = ca.jtimes(r, low.x, seed)
        if coefficient.nnz() != r.numel():
            return f"block {b}: an unknown's coefficient is structurally zero"
        if ca.jtimes(coefficient, low.x, seed).nnz():
            return f"block {b}: not linear in its unknowns"
        if twice[here].any():
            coefficients.append(coefficient)
        # -r/coefficient with the block's own unknowns read as 0: they still are symbols
        # of x here, which :func:`assemble` evaluates with structural zeros in place of
        # every unknown, so their terms drop out exactly
        solution = ca.substitute(-r / coefficient, low.x, current)
        current = ca.MX(current)
        current[mine.tolist()] = solution
    if _cancelled(low, coefficients):
        return "an unknown's terms cancel in the equation solving it (a singular system)"
    return current


def _cancelled(low: Lowered, coefficients: list[ca.MX]) -> bool:
    """Whether a coefficient is zero at a random point: its terms cancel (``p.v - n.v`` of a
    part with both pins on one node, once they are one variable), which the incidence, made
    of the operands' columns, does not show. Only rows using a column twice can cancel so;
    their blocks' coefficients are checked. A zero at a random point is a zero everywhere
    (with probability one), and the scalar pipeline, which sees the cancellation, decides."""
    if not coefficients:
        return False
    rng = np.random.default_rng(7)
    values = ca.Function("coefficients", [low.x, low.p, low.t], coefficients)(
        rng.uniform(0.5, 1.5, low.n), rng.uniform(0.5, 1.5, low.n_p), rng.uniform(0.5, 1.5))
    values = values if isinstance(values, (list, tuple)) else [values]
    return any(bool((np.asarray(v) == 0).any()) for v in values)


def _column(n: int, rows: np.ndarray) -> ca.Sparsity:
    """The sparsity of an ``n``-vector with entries at ``rows`` (ascending)."""
    return ca.Sparsity(n, 1, [0, int(rows.size)], rows.tolist())


def assemble(col: Collected, low: Lowered, solved: ca.MX, states: np.ndarray,
             aliases: Aliases | None = None) -> CasadiDAE:
    """The :class:`CasadiDAE` of the model: the same names, orders, states and parameters
    as the scalar pipeline's. Its SX symbols are one column ``v``: the states, then the
    parameters (the other variables are observations). ``aliases``: the eliminated ones."""
    n, n_p = low.n, low.n_p
    n_x = states.size
    order = col.order
    kept = aliases.keep.tolist() if aliases is not None else list(range(n))
    column = ca.SX.sym("v", n_x + n_p)
    x, p = column[:n_x], column[n_x:]
    state_list = states.tolist()
    # the unknowns are structural zeros: a block's solution reads its own as 0 (see
    # solve_blocks), and every other was replaced by its solution
    x_in = ca.SX(ca.Sparsity(n, 1, [0, n_x], state_list), x)
    derivatives = [j + 1 for j in state_list]                   # der(x) follows x
    f = ca.Function("array_path", [low.x, low.p, low.t],
                    [solved[derivatives], solved[kept] if aliases is not None else solved])
    ode, observed = f(x_in, p, TIME.sx)
    if n_x + len(kept) <= CSE_UP_TO:
        both = ca.cse(ca.vertcat(ode, observed))
        ode, observed = both[:n_x], both[n_x:]
    kept_vars = order if aliases is None else [order[j] for j in kept]
    names = col.names if aliases is None else [col.names[j] for j in kept]
    decls = list(map(_DECL, kept_vars))
    merged = aliases.starts if aliases is not None else {}
    if merged:                                   # representatives given an alias's start
        at = {j: k for k, j in enumerate(kept)}
        starts = [float(d.start) for d in decls]
        flags = [bool(d.fixed) for d in decls]
        for j, (start, fixed) in merged.items():
            starts[at[j]], flags[at[j]] = start, fixed
    else:
        starts, flags = list(map(attrgetter("start"), decls)), \
            list(map(attrgetter("fixed"), decls))
    fixed = [(k, float(starts[k])) for k in compress(range(len(kept)), flags)]
    position = dict(zip(kept, range(len(kept)), strict=True)) if aliases is not None else None
    state_pos = state_list if position is None else [position[j] for j in state_list]
    owners = repeat("") if col.param_owners is None else col.param_owners
    parameters = list(map(FlatVariable, col.param_names, repeat(None),
                          map(_DECL, col.params), owners, repeat(-1), repeat(-1),
                          zip(repeat(column), range(n_x, n_x + n_p))))
    n_free = n_p - col.n_inputs                 # parameters, then the inputs
    parameters, inputs = parameters[:n_free], parameters[n_free:]
    return CasadiDAE(
        x=x, z=ca.SX(0, 1), p=p if n_p else ca.SX(0, 1),
        t=TIME.sx, ode=ode, alg=ca.SX(0, 1), observed=observed,
        names=names, state_names=[names[k] for k in state_pos], algebraic_names=[],
        parameters=parameters, inputs=inputs,
        x_start=np.fromiter(map(float, map(starts.__getitem__, state_pos)), float, n_x),
        z_start=np.zeros(0), fixed=fixed,
        observed_index=dict(zip(names, range(len(names)), strict=True)),
        n_variables=len(names), differentiated={names[k] for k in state_pos},
        aliases=dict(aliases.names) if aliases is not None else {})
