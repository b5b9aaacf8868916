"""The integer equation graph shared by all structural algorithms."""

from __future__ import annotations

from dataclasses import dataclass, field
from itertools import chain

import numpy as np

from .collector import gc_paused as gc_paused  # (its home before collector.py)


@dataclass
class EquationGraph:
    """Bipartite incidence of a DAE plus time-derivative links.

    ``eq_vars[i]`` lists the variables incident in equation ``i``. ``var_derivative[j]`` is
    the index of the variable that is the time derivative of variable ``j`` (or -1), and
    ``eq_derivative[i]`` the index of the equation obtained by differentiating equation ``i``
    (or -1). Empty link lists are filled with -1 on construction.
    """

    eq_vars: list[list[int]]
    n_vars: int
    var_derivative: list[int] = field(default_factory=list)
    eq_derivative: list[int] = field(default_factory=list)

    def __post_init__(self) -> None:
        if not self.var_derivative and self.n_vars:
            self.var_derivative = [-1] * self.n_vars
        if not self.eq_derivative and self.eq_vars:
            self.eq_derivative = [-1] * len(self.eq_vars)

    @property
    def n_eqs(self) -> int:
        """Number of equations."""
        return len(self.eq_vars)

    def validate(self) -> None:
        """Raise ``ValueError`` if indices are out of range or derivative links are
        inconsistent (non-injective or cyclic)."""
        n, m = self.n_vars, self.n_eqs
        if len(self.var_derivative) != n:
            raise ValueError(f"var_derivative has {len(self.var_derivative)} entries, not {n}")
        if len(self.eq_derivative) != m:
            raise ValueError(f"eq_derivative has {len(self.eq_derivative)} entries, not {m}")
        used = np.fromiter(chain.from_iterable(self.eq_vars), dtype=np.int64)
        if used.size and (used.min() < 0 or used.max() >= n):
            bad = next(i for i, vs in enumerate(self.eq_vars)
                       if vs and (min(vs) < 0 or max(vs) >= n))
            raise ValueError(f"equation {bad} references a variable out of range 0..{n - 1}")
        derivative_chains(self.var_derivative, "variable")
        derivative_chains(self.eq_derivative, "equation")

    def var_eqs(self) -> list[list[int]]:
        """Transpose: the equations each variable occurs in."""
        out: list[list[int]] = [[] for _ in range(self.n_vars)]
        for i, vs in enumerate(self.eq_vars):
            for v in vs:
                out[v].append(i)
        return out

    def var_integral(self) -> list[int]:
        """Inverse of ``var_derivative``: var -> the variable it is the derivative of, or -1."""
        return _inverse(self.var_derivative, self.n_vars, "variable")

    def eq_integral(self) -> list[int]:
        """Inverse of ``eq_derivative``: eq -> the equation it is the derivative of, or -1."""
        return _inverse(self.eq_derivative, self.n_eqs, "equation")

    def var_orders(self) -> list[int]:
        """Derivative order of every variable (0 for a variable that is no derivative)."""
        return derivative_chains(self.var_derivative, "variable")[1]

    def eq_orders(self) -> list[int]:
        """Number of differentiations that produced each equation (0 for an original one)."""
        return derivative_chains(self.eq_derivative, "equation")[1]

    def base_vars(self) -> list[int]:
        """Order-0 ancestor of every variable (itself for an order-0 variable)."""
        return derivative_chains(self.var_derivative, "variable")[2]

    def derivative_order(self, var: int) -> int:
        """How many times ``var`` is differentiated from its order-0 ancestor (O(n_vars))."""
        integral = self.var_integral()
        order = 0
        while integral[var] != -1:
            var = integral[var]
            order += 1
        return order

    def highest_derivative(self, var: int) -> int:
        """The highest existing derivative of ``var`` (``var`` itself if it has none)."""
        while self.var_derivative[var] != -1:
            var = self.var_derivative[var]
        return var

    def is_highest(self, var: int) -> bool:
        """True if ``var`` has no derivative variable."""
        return self.var_derivative[var] == -1

    def active_equations(self) -> list[int]:
        """Equations that have not been differentiated (the highest-order ones)."""
        return [i for i, d in enumerate(self.eq_derivative) if d == -1]

    def copy(self) -> EquationGraph:
        """Deep copy (lists are copied)."""
        return EquationGraph(
            [list(vs) for vs in self.eq_vars],
            self.n_vars,
            list(self.var_derivative),
            list(self.eq_derivative),
        )


def _inverse(links: list[int], n: int, what: str) -> list[int]:
    return _inverse_array(np.asarray(links, dtype=np.int64), n, what).tolist()


def _inverse_array(arr: np.ndarray, n: int, what: str) -> np.ndarray:
    """``inv[d] = i`` for every link ``i -> d`` (numpy; the checks of :func:`_inverse`)."""
    src = np.flatnonzero(arr != -1)
    dst = arr[src]
    bad = np.flatnonzero((dst < 0) | (dst >= n))
    if bad.size:
        i = int(src[bad[0]])
        raise ValueError(f"{what} {i} has derivative {int(arr[i])} out of range")
    clash = dst == src
    counts = np.bincount(dst, minlength=n)
    clash |= counts[dst] > 1
    if clash.any():
        k = np.flatnonzero(clash)
        # report the first link (in order) that repeats a target or points to itself
        first_seen = {}
        for idx in k.tolist():
            d = int(dst[idx])
            if d == int(src[idx]) or d in first_seen:
                raise ValueError(f"{what} {d} is the derivative of more than one {what}")
            first_seen[d] = idx
    inv = np.full(n, -1, dtype=np.int64)
    inv[dst] = src
    return inv


def derivative_chains(links: list[int], what: str = "variable") -> tuple[
        list[int], list[int], list[int]]:
    """For derivative links (``links[j]`` = derivative of ``j`` or -1) return
    ``(integral, order, root)``: the inverse links, the derivative order and the order-0
    ancestor of every element. Raises ``ValueError`` for non-injective or cyclic links.
    Vectorized over derivative orders (one numpy pass per order)."""
    n = len(links)
    arr = np.asarray(links, dtype=np.int64)
    inv = _inverse_array(arr, n, what)
    order = np.full(n, -1, dtype=np.int64)
    root = np.full(n, -1, dtype=np.int64)
    level = np.flatnonzero(inv == -1)
    order[level] = 0
    root[level] = level
    seen, o = level.size, 0
    while level.size:
        nxt = arr[level]
        keep = nxt != -1
        level, origin = nxt[keep], root[level[keep]]
        o += 1
        order[level] = o
        root[level] = origin
        seen += level.size
    if seen != n:
        raise ValueError(f"cyclic {what} derivative links")
    return inv.tolist(), order.tolist(), root.tolist()
