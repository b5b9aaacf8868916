"""Dulmage-Mendelsohn decomposition: locate the over- and under-determined parts."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from .errors import StructurallySingular
from .graph import gc_paused
from .matching import Matching, maximum_matching


@dataclass
class DMDecomposition:
    """Coarse Dulmage-Mendelsohn decomposition (sorted index lists).

    The over-determined part holds the unmatched equations and everything reachable from them
    by alternating paths; the under-determined part likewise from the unmatched variables; the
    well-determined part is the rest and is perfectly matched.
    """

    overdetermined_eqs: list[int]
    overdetermined_vars: list[int]
    underdetermined_eqs: list[int]
    underdetermined_vars: list[int]
    well_eqs: list[int]
    well_vars: list[int]

    @property
    def is_nonsingular(self) -> bool:
        """True if the system is square and structurally nonsingular."""
        return not (self.overdetermined_eqs or self.underdetermined_vars)

    def error(self, message: str | None = None) -> StructurallySingular:
        """A :class:`StructurallySingular` carrying this decomposition's parts."""
        return StructurallySingular(
            message,
            overdetermined_eqs=self.overdetermined_eqs,
            overdetermined_vars=self.overdetermined_vars,
            underdetermined_eqs=self.underdetermined_eqs,
            underdetermined_vars=self.underdetermined_vars,
        )


@gc_paused()
def dulmage_mendelsohn(
    eq_vars: Sequence[Sequence[int]], n_vars: int, matching: Matching | None = None
) -> DMDecomposition:
    """Decompose the incidence ``eq_vars`` given a *maximum* matching (computed if None)."""
    if matching is None:
        matching = maximum_matching(eq_vars, n_vars)
    eq_to_var, var_to_eq = matching.eq_to_var, matching.var_to_eq
    n_eqs = len(eq_vars)

    # Over-determined: from unmatched equations, eq -> any var -> its matched equation.
    over_eq = [False] * n_eqs
    over_var = [False] * n_vars
    stack = [i for i in range(n_eqs) if eq_to_var[i] == -1]
    for i in stack:
        over_eq[i] = True
    while stack:
        i = stack.pop()
        for v in eq_vars[i]:
            if not over_var[v]:
                over_var[v] = True
                w = var_to_eq[v]
                if w != -1 and not over_eq[w]:
                    over_eq[w] = True
                    stack.append(w)

    # Under-determined: from unmatched variables, var -> any eq -> its matched variable.
    var_eqs: list[list[int]] = [[] for _ in range(n_vars)]
    for i, vs in enumerate(eq_vars):
        for v in vs:
            var_eqs[v].append(i)
    under_eq = [False] * n_eqs
    under_var = [False] * n_vars
    vstack = [v for v in range(n_vars) if var_to_eq[v] == -1]
    for v in vstack:
        under_var[v] = True
    while vstack:
        v = vstack.pop()
        for i in var_eqs[v]:
            if not under_eq[i]:
                under_eq[i] = True
                u = eq_to_var[i]
                if u != -1 and not under_var[u]:
                    under_var[u] = True
                    vstack.append(u)

    return DMDecomposition(
        overdetermined_eqs=[i for i in range(n_eqs) if over_eq[i]],
        overdetermined_vars=[v for v in range(n_vars) if over_var[v]],
        underdetermined_eqs=[i for i in range(n_eqs) if under_eq[i]],
        underdetermined_vars=[v for v in range(n_vars) if under_var[v]],
        well_eqs=[i for i in range(n_eqs) if not (over_eq[i] or under_eq[i])],
        well_vars=[v for v in range(n_vars) if not (over_var[v] or under_var[v])],
    )


def check_structurally_nonsingular(
    eq_vars: Sequence[Sequence[int]], n_vars: int, matching: Matching | None = None
) -> Matching:
    """Return a perfect matching or raise :class:`StructurallySingular` with the DM parts."""
    if matching is None or matching.size < min(len(eq_vars), n_vars):
        matching = maximum_matching(eq_vars, n_vars, initial=matching)
    if matching.size == len(eq_vars) == n_vars:
        return matching
    raise dulmage_mendelsohn(eq_vars, n_vars, matching).error()
