"""Connection sets as linear rows on the array path.

In a connection set the potentials are equal and the flows sum to zero (Modelica's
connection semantics, as :mod:`bgmodelica.core.flatten_connections` writes them for the
scalar pipeline): the first member's potential equals each other member's (``a - b = 0``),
the flows of a set of two are ``a + b = 0``, and a larger set (or an unconnected connector)
gets one sum. Each kind is one :class:`LinearRows` over the model's columns, made with numpy
from the sets' nodes, never a Python object per scalar. The two-term rows are alias links,
in the order the scalar pipeline finds them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class LinearRows:
    """``size`` scalar equations ``sum(coefs[k] * column cols[k]) = 0`` over the rows
    ``rows[k]``. ``links``: for rows of two variables ``a + c*b`` (``a``, ``b`` their
    columns, one pair per row), the alias links ``a = -c*b`` as ``(a, b, -c)`` arrays."""

    rows: np.ndarray
    cols: np.ndarray
    coefs: np.ndarray
    size: int
    origin: str
    links: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    @property
    def shape(self) -> tuple[int]:
        return (self.size,)

    def __len__(self) -> int:
        return self.size


def set_rows(nodes: np.ndarray, cuts: np.ndarray, columns: np.ndarray,
             flows: np.ndarray) -> list[LinearRows]:
    """The equations of connection sets whose connectors are all of one kind.

    ``nodes``/``cuts``: the sets (:func:`~bgmodelica.core.flatten_connections.
    connection_set_arrays`; node ``2*connector + side``, side 1 seen from outside);
    ``columns[c, j]``: the column of variable ``j`` of connector ``c``; ``flows[j]``:
    whether variable ``j`` is a flow. Potential equalities first, then the flows of sets
    of two, then the sums, each variable by variable."""
    starts = np.concatenate(([0], cuts)).astype(np.int64)
    sizes = np.diff(np.concatenate((starts, [nodes.size])))
    set_of = np.repeat(np.arange(starts.size), sizes)
    conn = nodes >> 1
    sign = np.where(nodes & 1, -1.0, 1.0)
    is_first = np.zeros(nodes.size, dtype=bool)
    is_first[starts] = True
    others = np.flatnonzero(~is_first)
    first_of_other = starts[set_of[others]]
    pair_sets = np.flatnonzero(sizes == 2)
    sum_nodes = np.flatnonzero(sizes[set_of] != 2)
    out: list[LinearRows] = []
    for j in np.flatnonzero(~flows).tolist():
        a, b = columns[conn[first_of_other], j], columns[conn[others], j]
        out.append(_pairs(a, b, -np.ones(a.size), "connection sets: equal potentials"))
    for j in np.flatnonzero(flows).tolist():
        m0, m1 = starts[pair_sets], starts[pair_sets] + 1
        a, b = columns[conn[m0], j], columns[conn[m1], j]
        out.append(_pairs(a, b, sign[m0] * sign[m1], "connection sets: flows of two"))
    for j in np.flatnonzero(flows).tolist():
        if sum_nodes.size:
            _, rows = np.unique(set_of[sum_nodes], return_inverse=True)
            out.append(LinearRows(rows.astype(np.int64), columns[conn[sum_nodes], j],
                                  sign[sum_nodes], int(rows.max()) + 1,
                                  "connection sets: sums of flows"))
    return [rows for rows in out if rows.size]


def _pairs(a: np.ndarray, b: np.ndarray, coef: np.ndarray, origin: str) -> LinearRows:
    """Rows ``a + coef*b = 0``, one per pair."""
    n = a.size
    rows = np.repeat(np.arange(n, dtype=np.int64), 2)
    cols = np.column_stack((a, b)).ravel()
    coefs = np.column_stack((np.ones(n), coef)).ravel()
    return LinearRows(rows, cols, coefs, n, origin, (a, b, -coef))
