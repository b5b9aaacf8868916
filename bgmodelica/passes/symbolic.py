"""The symbolic helpers the passes hand to the structural algorithms (CasADi SX underneath)."""

from __future__ import annotations

from collections.abc import Sequence
from itertools import chain

import casadi as ca
import numpy as np

from ..core.flatmodel import Picked

#: a sum over more terms than this is a long row (see :func:`incidence`)
LONG_ROW = 64


def long_rows(equations) -> set[int]:
    """Positions of the flat equations that are long sums (``FlatEquation.terms``)."""
    return {k for k, e in enumerate(equations) if e.terms > LONG_ROW}


def incidence(residuals: Sequence[ca.SX], symbols: Sequence[ca.SX],
              long: set[int] | None = None) -> list[list[int]]:
    """For each residual, the indices (ascending) of the ``symbols`` it depends on.

    One Jacobian-sparsity pass over the residuals, except the ``long`` ones (positions of
    long sums, e.g. the current balance of a ground node joined to every section of a
    ladder): CasADi's pass sweeps every instruction once per 64 rows, so a single row of n
    terms makes it quadratic (5.5 s instead of 0.3 s for 150,000 equations). Those rows are
    read from their symbols instead."""
    if not residuals:
        return []
    if not symbols:
        return [[] for _ in residuals]
    return _incidence(residuals, symbols, None, None, long)


def _incidence(residuals: Sequence[ca.SX], symbols: Sequence[ca.SX], stacked: ca.SX | None,
               sym_vec: ca.SX | None, long: set[int] | None) -> list[list[int]]:
    """:func:`incidence`, reusing the residuals and symbols already stacked when given."""
    long = {k for k in (long or ()) if k < len(residuals)}
    sym_vec = ca.vertcat(*symbols) if sym_vec is None else sym_vec
    if not long:
        expr = stacked if stacked is not None else ca.vertcat(*residuals)
        return _sparsity_rows(expr, sym_vec)
    rows: list[list[int]] = [[] for _ in range(len(residuals))]
    ordered = sorted(long)                     # their own pass: few rows, one sweep each 64
    short = [k for k in range(len(residuals)) if k not in long]
    for part in (ordered, short):
        if part:
            expr = stacked[part] if stacked is not None \
                else ca.vertcat(*[residuals[k] for k in part])
            for k, row in zip(part, _sparsity_rows(expr, sym_vec), strict=True):
                rows[k] = row
    return rows


#: from this many rows or columns on, :func:`_sparsity_rows` looks for dense columns first
#: (CasADi's slow-down starts above 2**18 of either)
DENSE_CHECK_SIZE = 2**17
#: rows sampled to find dense columns, and the share of them that makes a column dense
DENSE_SAMPLE, DENSE_SHARE = 4096, 1 / 256


def _sparsity_rows(expr: ca.SX, sym_vec: ca.SX) -> list[list[int]]:
    """Column indices (ascending) of every row of the Jacobian sparsity of ``expr``: the
    transposed pattern's compressed columns, sliced (no loop over nonzeros).

    CasADi's pass slows down sharply on patterns of more than 2**18 rows or columns with a
    dense column (a symbol used by a fair share of all rows, such as the node every section
    of a ladder is tied to): 77 s instead of 1.2 s for 500,000 rows. Large patterns
    therefore get their dense columns (found on a sample of rows) in a pass of their own,
    and the two are merged."""
    large = max(expr.numel(), sym_vec.numel()) >= DENSE_CHECK_SIZE
    dense = _dense_columns(expr, sym_vec) if large else None
    if dense is None or not dense.size:
        pattern = ca.jacobian_sparsity(expr, sym_vec).T
        cols, starts = pattern.row(), pattern.colind()
        return [cols[a:b] for a, b in zip(starts[:-1], starts[1:], strict=True)]
    from scipy.sparse import csr_matrix

    n_rows, n_cols = expr.numel(), sym_vec.numel()
    is_dense = np.zeros(n_cols, dtype=bool)
    is_dense[dense] = True
    rest = np.flatnonzero(~is_dense)
    parts = []
    for columns in (rest, dense):
        pattern = ca.jacobian_sparsity(expr, sym_vec[columns.tolist()]).T
        indices = columns[np.asarray(pattern.row(), dtype=np.int64)]
        parts.append(csr_matrix((np.ones(indices.size), indices,
                                 np.asarray(pattern.colind(), dtype=np.int64)),
                                shape=(n_rows, n_cols)))
    merged = (parts[0] + parts[1]).tocsr()
    merged.sort_indices()
    cols, starts = merged.indices.tolist(), merged.indptr.tolist()
    return [cols[a:b] for a, b in zip(starts[:-1], starts[1:], strict=True)]


def _dense_columns(expr: ca.SX, sym_vec: ca.SX) -> np.ndarray:
    """Columns used by at least :data:`DENSE_SHARE` of :data:`DENSE_SAMPLE` rows spread
    evenly over ``expr`` (a handful at most; their total use is bounded by the nonzeros)."""
    n_rows = expr.numel()
    sample = np.unique(np.linspace(0, n_rows - 1, min(DENSE_SAMPLE, n_rows)).astype(np.int64))
    pattern = ca.jacobian_sparsity(expr[sample.tolist()], sym_vec)
    counts = np.bincount(np.asarray(pattern.get_triplet()[1], dtype=np.int64),
                         minlength=sym_vec.numel())
    return np.flatnonzero(counts >= max(2, int(DENSE_SHARE * sample.size)))


def model_incidence(model) -> list[list[int]]:
    """:func:`incidence` of a flat model's equations in its variables, computed once per
    model (the balance check and index reduction both need it; on large models it costs a
    Jacobian sparsity pass over every equation). Recomputed if either list was replaced or
    changed size."""
    key = (model.equations, len(model.equations), model.variables, len(model.variables))
    memo = model.__dict__.get("_incidence_memo")
    if memo is not None and all(a is b if isinstance(a, list) else a == b
                                for a, b in zip(memo[0], key, strict=True)):
        return memo[1]
    if not model.equations:
        rows: list[list[int]] = []
    elif not model.variables:
        rows = [[] for _ in model.equations]
    else:
        rows = _incidence(Picked(model.equations, "residual"),
                          Picked(model.variables, "sx"), model.stacked_residuals(),
                          model.stacked_variables(), long_rows(model.equations))
    model.__dict__["_incidence_memo"] = (key, rows)
    return rows


def time_derivative(residual: ca.SX, syms: Sequence[ca.SX], rates: Sequence[ca.SX],
                    time: ca.SX) -> ca.SX:
    """d/dt of ``residual`` given the time derivatives ``rates`` of ``syms``."""
    out = ca.jacobian(residual, time) if ca.depends_on(residual, time) else ca.SX(0)
    if syms:
        out = out + ca.jtimes(residual, ca.vertcat(*syms), ca.vertcat(*rates))
    return ca.simplify(out) if out.numel() == 1 else out


def solve_linear_scalar(residual: ca.SX, var: ca.SX, variables: set[int] | None = None,
                        discrete: frozenset[int] = frozenset()) -> ca.SX | None:
    """``var`` from ``residual(var) = 0`` when the residual is linear in ``var``, else None.

    With ``variables`` (SX hashes of the model's variables), only solve when the coefficient
    of ``var`` is free of variables, so the division can never be by a vanishing quantity
    (the safe choice for tearing). Likewise not when the coefficient vanishes for some
    value of the ``discrete`` symbols it reads (see :func:`may_vanish`): ``x = if s > 1
    then s - 1 else 0`` does not determine ``s`` while the second branch is active.
    """
    if residual.is_op(ca.OP_SUB):
        lhs, rhs = residual.dep(0), residual.dep(1)
        if ca.is_equal(lhs, var) and not ca.depends_on(rhs, var):
            return rhs
        if ca.is_equal(rhs, var) and not ca.depends_on(lhs, var):
            return lhs
    a = ca.jacobian(residual, var)
    if ca.depends_on(a, var):
        return None
    if a.is_zero():
        return None
    if variables is not None and any(s.element_hash() in variables for s in ca.symvar(a)):
        return None
    if discrete and may_vanish(a, discrete):
        return None
    b = ca.substitute(residual, var, ca.SX(0))
    return -b / a


#: :func:`may_vanish` tries every 0/1 combination of up to this many discrete symbols
MAX_BRANCH_SYMBOLS = 8


def may_vanish(coefficient: ca.SX, discrete: frozenset[int]) -> bool:
    """Whether ``coefficient`` is identically zero for some 0/1 values of the symbols in it
    whose element hash is in ``discrete`` (relation values, modes: the branch selectors of
    piecewise expressions). Exact up to :data:`MAX_BRANCH_SYMBOLS` such symbols (each
    combination is substituted and folded to a constant or not); beyond, any dependence on
    them counts as vanishing."""
    syms = [s for s in ca.symvar(coefficient) if s.element_hash() in discrete]
    if not syms:
        return False
    if len(syms) > MAX_BRANCH_SYMBOLS:
        return True
    column = ca.vertcat(*syms)
    n = len(syms)
    for k in range(2 ** n):
        value = ca.DM([(k >> i) & 1 for i in range(n)])
        if ca.substitute(coefficient, column, value).is_zero():
            return True
    return False


def solve_linear_block(residuals: Sequence[ca.SX], vars_: Sequence[ca.SX],
                       max_size: int = 40) -> ca.SX | None:
    """Solution of a square block linear in ``vars_`` (symbolic), or None if nonlinear/large."""
    if len(vars_) > max_size:
        return None
    r, v = ca.vertcat(*residuals), ca.vertcat(*vars_)
    a = ca.jacobian(r, v)
    if ca.depends_on(a, v):
        return None
    b = ca.substitute(r, v, ca.DM.zeros(v.numel()))
    return ca.solve(a, -b)


def solve_scalar_blocks(residuals: Sequence[ca.SX], vars_: Sequence[ca.SX],
                        long: set[int] | None = None, r_all: ca.SX | None = None,
                        v_all: ca.SX | None = None, rows: Sequence[Sequence[int]] | None = None,
                        ) -> tuple[list[ca.SX | None], ca.SX, list[int]]:
    """Solve each ``residuals[k] = 0`` for ``vars_[k]`` where it is linear in it (else None);
    ``long``: positions of long sums (see :func:`incidence`); ``r_all``/``v_all``: the same
    residuals and variables already stacked, if the caller has them; ``rows``: the incidence
    of the residuals in ``vars_`` (by position), if the caller knows it.

    Vectorized: the pairs are colored so that no residual of a color depends on another
    variable of that color; then one Jacobian and one substitution per color give every
    coefficient ``a`` and remainder ``b`` (``r = a*v + b``), and ``v = -b/a``.

    Returns the solutions, and the same as one column with each solution's position in it
    (``-1`` where None), so that callers can restack them without a scalar per element.
    """
    n = len(residuals)
    if n == 0:
        return [], ca.SX(0, 1), []
    r_all = ca.vertcat(*residuals) if r_all is None else r_all
    v_all = ca.vertcat(*vars_) if v_all is None else v_all
    if rows is None:
        rows = _incidence(residuals, vars_, r_all, v_all, long)
    color = _coloring(n, rows)
    out: list[ca.SX | None] = [None] * n
    position = [-1] * n
    columns, offset = [], 0
    for c in range(int(color.max()) + 1):
        members = np.flatnonzero(color == c).tolist()
        r = r_all[members]
        v = v_all[members]
        a = ca.jtimes(r, v, ca.DM.ones(len(members)))      # diagonal: no cross terms
        b = ca.substitute(r, v, ca.DM.zeros(len(members)))
        column = -b / a
        sol = ca.vertsplit(column) if len(members) > 1 else [column]
        solvable = np.zeros(len(members), dtype=bool)
        solvable[ca.sparsify(a).sparsity().row()] = True  # a = 0: not solvable for v
        solvable[ca.jacobian_sparsity(a, v).get_triplet()[0]] = False    # nonlinear in v
        for m in np.flatnonzero(solvable).tolist():
            out[members[m]] = sol[m]
            position[members[m]] = offset + m
        columns.append(column)
        offset += len(members)
    return out, ca.vertcat(*columns), position


#: rounds of topological peeling before :func:`_coloring` switches to Jones-Plassmann
PEEL_ROUNDS = 8


def _coloring(n: int, rows: Sequence[Sequence[int]]) -> np.ndarray:
    """Colors of ``n`` pairs such that no residual depends on another variable of its own
    color; pairs without neighbours, most of them in large models, all get color 0.

    Vectorized, a few numpy operations over the remaining edges per color. First the pairs
    are peeled in dependency order (color c: every pair whose residual needs only variables
    of colors below c), which gives the fewest colors for the shallow dependencies of most
    models (each color costs one Jacobian and one substitution). After :data:`PEEL_ROUNDS`
    rounds, or on a cycle, the rest is colored by Jones-Plassmann: in each round every pair
    whose priority beats those of all its uncolored neighbours takes the round's color; the
    priorities are a fixed pseudo-random permutation, so a long chain takes a few rounds."""
    lengths = np.fromiter(map(len, rows), dtype=np.int64, count=n)
    ii = np.repeat(np.arange(n), lengths)
    jj = np.fromiter(chain.from_iterable(rows), dtype=np.int64, count=int(lengths.sum()))
    cross = ii != jj
    ii, jj = ii[cross], jj[cross]               # residual ii needs variable jj
    color = np.full(n, -1, dtype=np.int64)
    c = 0
    while ii.size and c < PEEL_ROUNDS:
        blocked = np.zeros(n, dtype=bool)
        blocked[ii] = True                      # needs a variable not colored yet
        pick = (color < 0) & ~blocked
        if not pick.any():                      # only cycles left
            break
        color[pick] = c
        keep = ~(pick[ii] | pick[jj])
        ii, jj = ii[keep], jj[keep]
        c += 1
    src, dst = np.concatenate((ii, jj)), np.concatenate((jj, ii))   # both directions
    priority = np.random.default_rng(0).permutation(n)
    while src.size:
        blocked = np.zeros(n, dtype=bool)
        blocked[src[priority[dst] > priority[src]]] = True
        pick = (color < 0) & ~blocked
        color[pick] = c
        keep = ~(pick[src] | pick[dst])
        src, dst = src[keep], dst[keep]
        c += 1
    color[color < 0] = c                        # no uncolored neighbour left
    return color


def fails_in_branch(residuals: Sequence[ca.SX], unknowns: Sequence[ca.SX], solution: ca.SX,
                    discrete: frozenset[int], tries: int = 2 ** MAX_BRANCH_SYMBOLS) -> bool:
    """Whether the symbolic ``solution`` of a block linear in ``unknowns`` divides by zero in
    some branch where the block itself is regular: at random values of the other symbols,
    for every 0/1 combination of the ``discrete`` ones in its matrix (at most ``tries``,
    sampled beyond), the matrix has full rank but the solution is not finite."""
    r, v = ca.vertcat(*residuals), ca.vertcat(*unknowns)
    a = ca.jacobian(r, v)
    if not any(s.element_hash() in discrete for s in ca.symvar(a)):
        return False
    b = ca.substitute(r, v, ca.DM.zeros(v.numel()))
    syms = ca.symvar(ca.vertcat(ca.vec(a), b, solution))
    f = ca.Function("bgm_branch", [ca.vertcat(*syms)], [a, b, solution])
    in_a = {s.element_hash() for s in ca.symvar(a)}
    picked = np.array([s.element_hash() in discrete and s.element_hash() in in_a
                       for s in syms])
    other_discrete = np.array([s.element_hash() in discrete for s in syms]) & ~picked
    n = int(picked.sum())
    rng = np.random.default_rng(2024)
    combos = range(2 ** n) if 2 ** n <= tries else rng.integers(0, 2 ** n, tries).tolist()
    x = rng.uniform(0.5, 1.5, len(syms))
    x[other_discrete] = rng.integers(0, 2, int(other_discrete.sum()))
    for k in combos:
        x[picked] = [(k >> i) & 1 for i in range(n)]
        with np.errstate(all="ignore"):
            m, rhs, sol = (np.asarray(y, dtype=float) for y in f(x))
        if not (np.all(np.isfinite(m)) and np.all(np.isfinite(rhs))) \
                or np.linalg.matrix_rank(m) < v.numel():
            continue
        if not np.all(np.isfinite(sol)):
            return True
    return False
