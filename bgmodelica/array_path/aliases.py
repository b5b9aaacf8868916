"""Alias equations (``a == b``, ``a == -b`` between variables) on the array path, eliminated
as the scalar pipeline eliminates them (:mod:`bgmodelica.passes.alias`): the same links in
the same order, the same ranking of representatives and the same signed classes
(:func:`bgmodelica.structure.alias.alias_classes`), the same merge of fixed start values.
An equation whose rows are only partly alias links (``y == k`` with a parameter ``k`` in
a group of ``a == b``) keeps its other rows. A model where the elimination would do more
(a cycle of links, an alias of a differentiated variable, conflicting fixed starts) goes
the scalar way.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import repeat
from operator import attrgetter, is_, is_not, methodcaller
from typing import Any

import numpy as np

from ..core.arrays import ArrayEquation
from ..core.expr import alias_signs
from ..core.flatten_arrays import _rows, alias_form
from ..structure.alias import alias_classes
from .collect import Collected
from .connections import LinearRows
from .scalars import ScalarGroup

_DECL, _DER, _DER_OF = attrgetter("decl"), attrgetter("der"), attrgetter("der_of")
_STATE_SELECT, _FIXED = attrgetter("state_select"), attrgetter("fixed")


@dataclass
class Aliases:
    """The eliminated columns and what they read as: column ``k`` is ``sign[k] *
    column target[k]``; ``keep`` are the columns left (ascending), ``dropped`` the alias
    equations (index in ``Collected.equations`` -> which of its rows), ``names`` the
    eliminated names
    with their representatives and signs, ``starts`` the merged ``(start, fixed)`` of the
    representatives whose start values changed."""

    keep: np.ndarray
    target: np.ndarray
    sign: np.ndarray
    dropped: dict[int, np.ndarray]
    names: dict[str, tuple[str, float]]
    starts: dict[int, tuple[float, bool]]


def find_aliases(col: Collected) -> Aliases | str | None:
    """The alias elimination of a collected model; None without aliases, a reason string
    when it must be left to the scalar pipeline."""
    order, pos = col.order, col.pos
    n = len(order)
    plain = np.zeros(n + len(col.params) + 1, dtype=bool)   # variables that may be linked
    plain[:n] = ~col.traits.is_der if col.traits is not None else \
        np.fromiter(map(is_, map(_DER_OF, order), repeat(None)), bool, n)
    heads: list[np.ndarray] = []
    tails: list[np.ndarray] = []
    factors: list[np.ndarray] = []
    linked_rows: dict[int, np.ndarray] = {}   # equation -> which of its rows are links

    def add(k: int, a: np.ndarray, b: np.ndarray, factor: float | np.ndarray,
            mask: np.ndarray | bool = True) -> None:
        ok = plain[a] & plain[b] & (a != b) & mask
        linked_rows[k] = ok
        heads.append(a[ok])
        tails.append(b[ok])
        factors.append(np.broadcast_to(factor, a.shape)[ok].astype(float))

    # the scalar pipeline's order: connection sets, scalar equations grouped by shape (first
    # seen first), then the array equations
    for k, eq in enumerate(col.equations):
        if isinstance(eq, LinearRows) and eq.links is not None:
            add(k, *eq.links)
    for k, eq in enumerate(col.equations):
        if isinstance(eq, ScalarGroup):
            signs = alias_signs(*eq.key)
            if signs:
                a, b = (np.array([_column(pos, leaves[j], n) for leaves in eq.leaves],
                                 dtype=np.int64) for j in (0, 1))
                add(k, a, b, -signs[1] / signs[0],
                    np.array([not any(c) for c in eq.consts], dtype=bool))
    for k, eq in enumerate(col.equations):
        if isinstance(eq, ArrayEquation):
            found = _array_link(eq, col)
            if found is not None:
                add(k, *found)
    links_a = np.concatenate(heads) if heads else np.zeros(0, dtype=np.int64)
    if not links_a.size:
        return None
    links_b, signs_ = np.concatenate(tails), np.concatenate(factors)
    dropped = {k: ok for k, ok in linked_rows.items() if ok.any()}
    names_of = col.names
    ranks = _ranks(col, links_a, links_b)
    links = zip(links_a.tolist(), links_b.tolist(), signs_.tolist(), strict=True)
    classes = alias_classes(n, links, ranks)
    if classes.redundant:
        return "alias equations close a cycle"
    rep = np.asarray(classes.rep, dtype=np.int64)
    members = np.flatnonzero(rep != np.arange(n)).tolist()
    if col.traits is not None and col.traits.has_der[members].any() or col.traits is None \
            and any(map(is_not, map(_DER, map(order.__getitem__, members)), repeat(None))):
        return "an alias of a differentiated variable"
    starts = _merged_starts(col, classes.rep, classes.sign, members)
    if isinstance(starts, str):
        return starts
    keep = np.ones(n, dtype=bool)
    keep[members] = False
    name_of, sign_of = names_of.__getitem__, classes.sign.__getitem__
    names = dict(zip(map(name_of, members),
                     zip(map(name_of, rep[members].tolist()), map(sign_of, members),
                         strict=True), strict=True))
    return Aliases(np.flatnonzero(keep), rep, np.asarray(classes.sign, dtype=float), dropped,
                   names, starts)


def _column(pos: Any, sym: Any, n: int) -> int:
    """The column of a scalar leaf (``n``, past the variables, for a parameter or time)."""
    try:
        k = pos.of(sym)
    except KeyError:
        return n
    return k if k < n else n


def _array_link(eq: ArrayEquation, col: Collected) -> tuple[np.ndarray, np.ndarray, float] | None:
    """The columns of ``sa*a + sb*b = 0`` between two arrays of leaves, element by element
    (broadcast to the equation's shape), and the factor ``-sb/sa``; None for any other
    form (:func:`~bgmodelica.core.flatten_arrays.alias_form`)."""
    form = alias_form(eq)
    if form is None:
        return None
    sa, sb, arrays = form
    shape = eq.shape
    a, b = (np.broadcast_to(np.asarray(_rows(arr.items, col.pos, col.memo), dtype=np.int64)
                            .reshape(arr.shape), shape).ravel() for arr in arrays)
    return a, b, -sb / sa


def _ranks(col: Collected, heads: np.ndarray, tails: np.ndarray) -> list[int]:
    """:func:`bgmodelica.passes.alias._ranks` on the collected columns: the dense rank of
    (has a derivative, state priority, fixed start, fewer dots, shorter name) among the
    linked variables, 0 for the others."""
    n = len(col.order)
    mask = np.zeros(n, dtype=bool)
    mask[heads] = True
    mask[tails] = True
    linked = np.flatnonzero(mask)
    keys = _rank_keys(col, linked)
    keys -= keys.min(axis=0)                 # one integer, ordered as the tuples are
    code = np.zeros(linked.size, dtype=np.int64)
    for column in keys.T:
        code = code * (int(column.max()) + 1) + column
    _, dense = np.unique(code, return_inverse=True)
    out = np.zeros(n, dtype=np.int64)
    out[linked] = dense.ravel()
    return out.tolist()


def _rank_keys(col: Collected, linked: np.ndarray) -> np.ndarray:
    """The rank key of each linked column, one row each."""
    t = col.traits
    if t is not None:
        return np.column_stack((t.has_der[linked], t.state_select[linked], t.fixed[linked],
                                -t.dots[linked], -t.length[linked])).astype(np.int64)
    at = linked.tolist()
    syms = list(map(col.order.__getitem__, at))
    decls = list(map(_DECL, syms))
    texts = list(map(col.names.__getitem__, at))
    return np.column_stack((
        np.fromiter(map(is_not, map(_DER, syms), repeat(None)), np.int64, len(at)),
        np.fromiter(map(int, map(_STATE_SELECT, decls)), np.int64, len(at)),
        np.fromiter(map(bool, map(_FIXED, decls)), np.int64, len(at)),
        -np.fromiter(map(methodcaller("count", "."), texts), np.int64, len(at)),
        -np.fromiter(map(len, texts), np.int64, len(at))))


def _merged_starts(col: Collected, rep: list[int], sign: list[float],
                   members: list[int]) -> dict[int, tuple[float, bool]] | str:
    """:func:`bgmodelica.passes.alias._merge_metadata` for start values: each member's fixed
    start carried to its representative (a conflict is left to the scalar pipeline, which
    names it), or a nonzero guess to a representative starting at 0 without a fixed one."""
    order, t = col.order, col.traits
    current: dict[int, tuple[float, bool]] = {}
    # only members with a fixed or nonzero start change their representative's start
    if t is not None:
        at = np.asarray(members, dtype=np.int64)
        matter = np.flatnonzero(t.fixed[at] | (t.start[at] != 0)).tolist()
    else:
        decls = list(map(_DECL, map(order.__getitem__, members)))
        matter = np.flatnonzero(
            np.fromiter(map(_FIXED, decls), bool, len(decls))
            | (np.fromiter(map(attrgetter("start"), decls), float, len(decls)) != 0)).tolist()
    for k in matter:
        i = members[k]
        dv = order[i].decl
        r = rep[i]
        r_start, r_fixed = current.get(r, (float(order[r].decl.start), bool(order[r].decl.fixed)))
        if dv.fixed:
            start = sign[i] * dv.start
            if r_fixed and abs(r_start - start) > 1e-12 * (1 + abs(start)):
                return "conflicting fixed start values of aliases"
            current[r] = (float(start), True)
        elif not r_fixed and r_start == 0 and dv.start != 0:
            current[r] = (float(sign[i] * dv.start), r_fixed)
    return current
