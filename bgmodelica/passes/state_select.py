"""``state_select`` declarations that cannot be honoured, named with their variables.

- Two variables made equal (or opposite) by an alias equation are one variable after alias
  elimination: ``ALWAYS`` on one and ``NEVER`` on the other contradict each other.
- ``ALWAYS`` on a variable that is never differentiated (not even by index reduction): it
  cannot be a state.
- ``NEVER`` on a variable that the structure forces to be a state (its derivative cannot be
  made a dummy derivative).
"""

from __future__ import annotations

from ..core.flatmodel import FlatModel
from ..core.variables import StateSelect
from ..errors import StateSelectError


def _find(parent: list[int], a: int) -> int:
    while parent[a] != a:
        parent[a] = parent[parent[a]]
        a = parent[a]
    return a


def _extremes(variables) -> list[int]:
    """Indices of the variables declared ALWAYS or NEVER (one attribute read each)."""
    extreme = (StateSelect.ALWAYS, StateSelect.NEVER)
    return [i for i, s in enumerate([getattr(v.decl, "state_select", 0) for v in variables])
            if s in extreme]


def check_alias_state_select(model: FlatModel) -> None:
    """Raise :class:`StateSelectError` when aliased variables have ALWAYS and NEVER."""
    variables = model.variables
    marked = _extremes(variables)
    if len(marked) < 2:
        return
    parent = list(range(len(variables)))
    for eq in model.equations:
        if eq.alias is not None:
            a, b, _ = eq.alias
            ra, rb = _find(parent, a), _find(parent, b)
            if ra != rb:
                parent[ra] = rb
    always: dict[int, int] = {}
    never: dict[int, int] = {}
    for i in marked:
        target = always if variables[i].state_select == StateSelect.ALWAYS else never
        target.setdefault(_find(parent, i), i)
    for root, i in always.items():
        if root in never:
            a, b = variables[i], variables[never[root]]
            raise StateSelectError(
                f"conflicting state_select: {a.origin} has StateSelect.ALWAYS but {b.origin}, "
                f"which an equation makes equal to it (up to sign), has StateSelect.NEVER; "
                "they become one variable: make the two declarations agree")


def check_states(reduced) -> None:
    """Raise :class:`StateSelectError` when the chosen states contradict ALWAYS / NEVER."""
    variables = reduced.model.variables
    states = set(reduced.states)
    for j in _extremes(variables):
        v = variables[j]
        if v.der_of >= 0:
            continue
        ss = v.state_select
        if ss == StateSelect.ALWAYS and j not in states:
            why = ("it is never differentiated (der of it appears in no equation, even after "
                   "index reduction)") if v.der < 0 else "its derivative had to be a dummy"
            raise StateSelectError(
                f"{v.origin} has StateSelect.ALWAYS but cannot be a state: {why}; remove "
                "StateSelect.ALWAYS or write its equations with der()")
        if ss == StateSelect.NEVER and j in states:
            raise StateSelectError(
                f"{v.origin} has StateSelect.NEVER but must be a state: der({v.name}) is "
                "integrated and no equation lets it be computed otherwise; remove "
                "StateSelect.NEVER (or use AVOID)")
