"""Alias equations (``a == b``, ``a == -b`` between variables) on the array path, eliminated
as the scalar pipeline eliminates them (:mod:`bgmodelica.passes.alias`): the same links in
the same order, the same ranking of representatives and the same signed classes
(:func:`bgmodelica.structure.alias.alias_classes`), the same merge of fixed start values.
A model where that elimination would do more (a cycle of links, an alias of a
differentiated variable, conflicting fixed starts, an array equation only partly of aliases)
goes the scalar way.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.arrays import ArrayEquation
from ..core.expr import alias_signs
from ..core.flatten import _side_shape
from ..core.flatten_arrays import alias_pairs
from ..structure.alias import alias_classes
from .collect import Collected


@dataclass
class Aliases:
    """The eliminated columns and what they read as: column ``k`` is ``sign[k] *
    column target[k]``; ``keep`` are the columns left (ascending), ``dropped`` the indices
    (in ``Collected.equations``) of the alias equations, ``names`` the eliminated names
    with their representatives and signs, ``starts`` the merged ``(start, fixed)`` of the
    representatives whose start values changed."""

    keep: np.ndarray
    target: np.ndarray
    sign: np.ndarray
    dropped: set[int]
    names: dict[str, tuple[str, float]]
    starts: dict[int, tuple[float, bool]]


def find_aliases(col: Collected) -> Aliases | str | None:
    """The alias elimination of a collected model; None without aliases, a reason string
    when it must be left to the scalar pipeline."""
    order, pos = col.order, col.pos
    links: list[tuple[int, int, float]] = []
    link_eq: list[int] = []            # the equation of each link
    rows_of: dict[int, list[Any]] = {}   # equation -> its links (None for an ordinary row)

    def column(sym: Any) -> int | None:
        if getattr(sym, "der_of", True) is not None or getattr(sym, "decl", None) is None \
                or sym.decl.kind != "variable":
            return None
        try:
            return pos.of(sym)
        except KeyError:
            return None

    def link(k: int, sa: float, a: Any, sb: float, b: Any) -> Any:
        ia, ib = column(a), column(b)
        if ia is None or ib is None or ia == ib:
            return None
        links.append((ia, ib, -sb / sa))
        link_eq.append(k)
        return links[-1]

    # the scalar pipeline's order: scalar equations grouped by shape (first seen first),
    # then the array equations
    groups: dict[Any, list[tuple[int, Any, list, list]]] = {}
    for k, eq in enumerate(col.equations):
        if not isinstance(eq, ArrayEquation):
            leaves: list = []
            consts: list = []
            key = (_side_shape(eq.lhs, leaves, consts), _side_shape(eq.rhs, leaves, consts))
            groups.setdefault(key, []).append((k, eq, leaves, consts))
    for key, members in groups.items():
        signs = alias_signs(*key)
        for k, _, leaves, consts in members:
            found = None if not signs or any(consts) else \
                link(k, signs[0], leaves[0], signs[1], leaves[1])
            rows_of[k] = [found]
    for k, eq in enumerate(col.equations):
        if isinstance(eq, ArrayEquation):
            pairs = alias_pairs(eq)
            if pairs is None:
                continue
            sa, sb, a, b = pairs
            rows_of[k] = [link(k, sa, la.sym, sb, lb.sym) for la, lb in zip(a, b, strict=True)]
    if not links:
        return None
    dropped = set()
    for k, rows in rows_of.items():
        found = [r is not None for r in rows]
        if all(found):
            dropped.add(k)
        elif any(found):
            return "an array equation is partly of aliases"
    n = len(order)
    classes = alias_classes(n, links, _ranks(order, links))
    if classes.redundant:
        return "alias equations close a cycle"
    rep = np.asarray(classes.rep, dtype=np.int64)
    members = np.flatnonzero(rep != np.arange(n)).tolist()
    if any(order[i].der is not None for i in members):
        return "an alias of a differentiated variable"
    starts = _merged_starts(order, classes.rep, classes.sign, members)
    if isinstance(starts, str):
        return starts
    keep = np.ones(n, dtype=bool)
    keep[members] = False
    names = {order[i].name: (order[classes.rep[i]].name, classes.sign[i]) for i in members}
    return Aliases(np.flatnonzero(keep), rep, np.asarray(classes.sign, dtype=float), dropped,
                   names, starts)


def _ranks(order: list[Any], links: list[tuple[int, int, float]]) -> list[int]:
    """:func:`bgmodelica.passes.alias._ranks` on the collected columns."""
    linked = {i for a, b, _ in links for i in (a, b)}
    keys = {}
    for i in linked:
        v = order[i]
        keys[i] = (v.der is not None, int(getattr(v.decl, "state_select", 0)),
                   bool(getattr(v.decl, "fixed", False)), -v.name.count("."), -len(v.name))
    dense = {key: k for k, key in enumerate(sorted(set(keys.values())))}
    out = [0] * len(order)
    for i, key in keys.items():
        out[i] = dense[key]
    return out


def _merged_starts(order: list[Any], rep: list[int], sign: list[float],
                   members: list[int]) -> dict[int, tuple[float, bool]] | str:
    """:func:`bgmodelica.passes.alias._merge_metadata` for start values: each member's fixed
    start carried to its representative (a conflict is left to the scalar pipeline, which
    names it), or a nonzero guess to a representative starting at 0 without a fixed one."""
    current: dict[int, tuple[float, bool]] = {}
    for i in members:
        r = rep[i]
        dv = order[i].decl
        r_start, r_fixed = current.get(r, (float(order[r].decl.start), bool(order[r].decl.fixed)))
        if dv.fixed:
            start = sign[i] * dv.start
            if r_fixed and abs(r_start - start) > 1e-12 * (1 + abs(start)):
                return "conflicting fixed start values of aliases"
            current[r] = (float(start), True)
        elif not r_fixed and r_start == 0 and dv.start != 0:
            current[r] = (float(sign[i] * dv.start), r_fixed)
    return current
