"""Equations of a collected model as CasADi MX blocks, with their scalar incidence.

The model's scalars are three MX symbols: ``x`` (the variables, each followed by its time
derivative: the order of the scalar pipeline), ``p`` (the parameters) and ``t``. An array
equation becomes one MX column of whole-vector operations on slices of them, so its size
costs nothing here. The incidence (which scalars each scalar equation uses) is read off the
same slices with numpy: the union of the operands' elements, row by row, as CasADi's sparsity
propagation through element-wise operations would find it.
"""

from __future__ import annotations

from itertools import chain
from typing import Any

import casadi as ca
import numpy as np

from ..core.arrays import ArrayExpr
from ..core.expr import Expr, apply_op, lower_group, lower_tree
from ..core.flatten import _count
from ..core.flatten_arrays import _rows
from .aliases import Aliases
from .collect import Collected
from .connections import LinearRows
from .scalars import ScalarGroup


class Lowered:
    """The blocks of a collected model: ``blocks[k]`` is the MX residual column of equation
    ``k`` (``sizes[k]`` scalar equations); ``rows``/``cols`` the incidence pairs, rows
    numbered over all blocks, columns over ``x`` (variables and derivatives).

    With ``aliases``, every column is read as its representative (``sign * x[target]``)
    as it is lowered, and the alias equations are left out: the blocks never read an
    eliminated column, and no block carries a map of the whole column."""

    def __init__(self, col: Collected, aliases: Aliases | None = None) -> None:
        n, n_p = len(col.order), len(col.params)
        self.n, self.n_p = n, n_p
        total = n + n_p + 1                    # columns of ``all``: x, p, t
        self.target = np.arange(total, dtype=np.int64)
        self.sign = np.ones(total)
        if aliases is not None:
            self.target[:n] = aliases.target
            self.sign[:n] = aliases.sign
        self.x, self.p, self.t = ca.MX.sym("x", n), ca.MX.sym("p", n_p), ca.MX.sym("t")
        self.all = ca.vertcat(self.x, self.p, self.t)
        self.pos, self.memo = col.pos, col.memo
        self.blocks: list[ca.MX] = []
        self.sizes: list[int] = []
        rows: list[np.ndarray] = []
        cols: list[np.ndarray] = []
        start = 0
        for eq in col.equations:
            if isinstance(eq, LinearRows):
                self._linear(eq, start, rows, cols)
                start += eq.size
                continue
            if isinstance(eq, ScalarGroup):
                self._group(eq, start, rows, cols)
                start += len(eq)
                continue
            shape = eq.shape                   # an array equation (scalar ones are grouped)
            size = int(np.prod(shape))
            left, lmaps = self.lower(eq.lhs, shape)
            right, rmaps = self.lower(eq.rhs, shape)
            self._add(left - right, size)
            for m in (*lmaps, *rmaps):
                rows.append(np.arange(start, start + size, dtype=np.int64))
                cols.append(np.broadcast_to(m, (size,)))
            start += size
        self.rows = np.concatenate(rows) if rows else np.zeros(0, dtype=np.int64)
        self.cols = np.concatenate(cols) if cols else np.zeros(0, dtype=np.int64)
        if aliases is not None:
            self._drop(aliases.dropped)

    def _add(self, res: Any, size: int) -> None:
        """A block: the residual ``res`` as an MX column of ``size`` rows."""
        if not isinstance(res, ca.MX):
            res = ca.MX(res)
        if res.numel() != size:
            res = ca.repmat(res, size, 1)
        self.blocks.append(res)
        self.sizes.append(size)

    def _linear(self, eq: LinearRows, start: int, rows: list, cols: list) -> None:
        """Linear rows (connection sets) as one sparse matrix product."""
        total = self.n + self.n_p + 1
        read = self.target[eq.cols]
        entry, at = np.unique(eq.rows * total + read, return_inverse=True)
        coefs = np.zeros(entry.size)                 # a column read twice: its terms summed
        np.add.at(coefs, at, eq.coefs * self.sign[eq.cols])
        matrix = ca.DM.triplet((entry // total).tolist(), (entry % total).tolist(),
                               ca.DM(coefs.tolist()), eq.size, total)
        self.blocks.append(ca.mtimes(matrix, self.all))
        self.sizes.append(eq.size)
        rows.append(eq.rows + start)
        cols.append(read)

    def _group(self, group: ScalarGroup, start: int, rows: list, cols: list) -> None:
        """Scalar equations of one shape as one block on their leaves' columns."""
        size = len(group)
        width = len(group.leaves[0])
        flat = chain.from_iterable(group.leaves)
        idx = np.fromiter(map(self.pos.of, flat), np.int64,      # (of: without filling the
                          size * width).reshape(size, width)      # dict of a leaf model)
        leaf_vecs = [self._take(idx[:, j]) for j in range(idx.shape[1])]
        idx = self.target[idx]
        const_vecs: list[Any] = []
        for j in range(len(group.consts[0])):
            values = [c[j] for c in group.consts]
            const_vecs.append(values[0] if values.count(values[0]) == size else ca.DM(values))
        shape_l, shape_r = group.key
        n_l, c_l = _count(shape_l, "L"), _count(shape_l, "C")
        self._add(lower_group(shape_l, leaf_vecs[:n_l], const_vecs[:c_l])
                  - lower_group(shape_r, leaf_vecs[n_l:], const_vecs[c_l:]), size)
        rows.append(np.repeat(np.arange(start, start + size, dtype=np.int64), idx.shape[1]))
        cols.append(idx.ravel())

    def _drop(self, dropped: dict[int, np.ndarray]) -> None:
        """Drop the alias equations (``dropped``: block -> which of its rows)."""
        starts = np.concatenate([[0], np.cumsum(self.sizes)]).astype(np.int64)
        row_kept = np.ones(int(starts[-1]), dtype=bool)
        blocks, sizes = [], []
        for k, block in enumerate(self.blocks):
            mask = dropped.get(k)
            if mask is None:
                blocks.append(block)
                sizes.append(self.sizes[k])
                continue
            row_kept[starts[k]:starts[k + 1]] = ~mask
            if not mask.all():
                keep = np.flatnonzero(~mask)
                blocks.append(block[keep.tolist()])
                sizes.append(int(keep.size))
        renumber = np.cumsum(row_kept) - 1
        used = row_kept[self.rows]
        self.rows, self.cols = renumber[self.rows[used]], self.cols[used]
        self.blocks, self.sizes = blocks, sizes

    def lower(self, x: Any, want: tuple[int, ...]) -> tuple[Any, list[np.ndarray]]:
        """``x`` as an MX column of shape ``want`` (C order) and, per operand array, the
        column index of each of its elements (broadcast the same way)."""
        if isinstance(x, ArrayExpr):
            if x.node is None:
                idx = np.asarray(_rows(x.items, self.pos, self.memo), dtype=np.int64)
                col, maps = self._take(idx), [self.target[idx]]
            else:
                op, args = x.node
                parts = [self.lower(a, x.shape) for a in args]
                col = apply_op(op, [c for c, _ in parts])
                maps = [np.broadcast_to(m, (x.size,)) if m.size == 1 else m
                        for _, ms in parts for m in ms]
            have = x.shape
            if have != want and x.size != 1:
                bidx = np.broadcast_to(np.arange(x.size).reshape(have), want).ravel()
                col = col[bidx.tolist()]
                maps = [m[bidx] for m in maps]
            return col, maps
        if isinstance(x, np.ndarray):
            return ca.DM(np.broadcast_to(x.astype(float), want).ravel()), []
        if isinstance(x, Expr):
            leaves: list[int] = []
            out = self._scalar(x, leaves)
            return out, [np.array([k], dtype=np.int64) for k in leaves]
        return float(x), []

    def _take(self, idx: np.ndarray) -> ca.MX:
        """The columns ``idx`` as read (each its representative, signed): a slice when
        they are evenly spaced (most are: slices of declared arrays), a list of indices
        otherwise."""
        sign = self.sign[idx]
        idx = self.target[idx]
        step = int(idx[1] - idx[0]) if idx.size > 1 else 0
        if step > 0 and (np.diff(idx) == step).all():
            read = self.all[int(idx[0]):int(idx[-1]) + 1:step]
        else:
            read = self.all[idx.tolist()]
        if (sign == 1.0).all():
            return read
        if (sign == sign[0]).all():
            return float(sign[0]) * read
        return read * ca.DM(sign)

    def _scalar(self, e: Any, leaves: list[int]) -> Any:
        """A scalar expression tree as MX (its leaves' columns appended to ``leaves``)."""
        def leaf(sym: Any) -> ca.MX:
            k = self.pos.of(sym)
            read = int(self.target[k])
            leaves.append(read)
            sign = float(self.sign[k])
            return self.all[read] if sign == 1.0 else sign * self.all[read]

        return lower_tree(e, leaf)
