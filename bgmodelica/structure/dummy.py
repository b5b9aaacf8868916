"""Dummy-derivative state selection (Mattsson & Soederlind 1993).

Input is a graph after :func:`~bgmodelica.structure.pantelides.pantelides`. Level 1 rows
``h1`` are the highest-order differentiated equations; the candidate columns ``z1`` are the
highest-derivative variables (order >= 1) occurring in them. At each level ``|h_i|`` columns
forming a structurally nonsingular block are chosen (greedily, in dummy-preference order); then
``h_{i+1}`` are the differentiated equations whose derivative is in ``h_i`` and ``z_{i+1}`` the
variables whose derivative was chosen. Every chosen column becomes a dummy derivative (an
algebraic variable); a variable whose derivative exists and is not a dummy is a state.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from .diagnosis import dulmage_mendelsohn
from .errors import StateSelectionError, StructurallySingular
from .graph import EquationGraph, derivative_chains, gc_paused
from .matching import preferred_column_matching

NEVER, AVOID, DEFAULT, PREFER, ALWAYS = -2, -1, 0, 1, 2

Selector = Callable[[int, list[int], list[int], list[int]], Sequence[int]]


@dataclass
class DummyDerivativeResult:
    """Outcome of :func:`dummy_derivatives`.

    ``dummies`` are derivative variables that become algebraic (level by level);
    ``states`` (sorted) the variables whose derivative exists and is not a dummy; ``levels``
    the ``(rows, candidates, chosen)`` of each level, candidates in dummy-preference order;
    ``has_choice`` tells whether some level had more candidates than rows (so the selection may
    have to change at run time, e.g. the Cartesian pendulum).
    """

    dummies: list[int]
    states: list[int]
    levels: list[tuple[list[int], list[int], list[int]]]
    has_choice: bool


@gc_paused()
def dummy_derivatives(
    graph: EquationGraph,
    priority: Sequence[int] | None = None,
    select: Selector | None = None,
) -> DummyDerivativeResult:
    """Choose dummy derivatives and hence the states.

    ``priority[v]`` is the state-selection priority of base (order-0) variable ``v``, like
    Modelica's stateSelect: -2 never, -1 avoid, 0 default, 1 prefer, 2 always (missing entries
    count as 0; it may be shorter than ``graph.n_vars`` since created derivatives are never
    base variables). Candidate ``c = der(s)`` is ranked as a dummy by, in order:
    the priority of ``s`` (if ``s`` is itself a derivative: ``min(avoid, priority of its
    base)``, so derivatives are kept as states only when needed), then the priority inherited by
    an order-0 ``s`` through an alias equation ``s = der(b)`` (two incident variables), then
    higher derivative order first, then index. ``der(s)`` is never made a dummy when ``s`` has
    ``always`` priority; if unavoidable :class:`StateSelectionError` names ``s``.

    ``select(level, rows, candidates, default)`` may override the choice of each level (levels
    start at 1); it must return ``len(rows)`` distinct candidates forming a structurally
    nonsingular block, else :class:`StateSelectionError` is raised.
    """
    n = graph.n_vars
    var_der = graph.var_derivative
    eq_vars = graph.eq_vars
    if all(d == -1 for d in graph.eq_derivative):     # nothing differentiated: no dummies
        derivative_chains(var_der, "variable")           # still reject malformed chains
        states = [v for v in range(n) if var_der[v] != -1]
        return DummyDerivativeResult([], states, [], False)
    var_int, var_order, base = derivative_chains(var_der, "variable")
    eq_int, eq_order, _ = derivative_chains(graph.eq_derivative, "equation")
    prio_list = list(priority) if priority is not None else []

    def prio(v: int) -> int:
        b = base[v]
        return max(NEVER, min(ALWAYS, prio_list[b])) if b < len(prio_list) else DEFAULT

    inherited: dict[int, int] = {}
    for i, vs in enumerate(eq_vars):
        if eq_order[i] != 0:
            continue
        if len(vs) < 2:
            continue
        pair = list(vs) if len(vs) == 2 else list(dict.fromkeys(vs))
        if len(pair) != 2 or pair[0] == pair[1]:
            continue
        for a, b in (pair, pair[::-1]):
            if var_order[a] == 1 and var_order[b] == 0 and base[a] != b:
                inherited[b] = max(inherited.get(b, NEVER), prio(a))

    def key(c: int) -> tuple[int, int, int, int]:
        s = var_int[c]
        if var_order[s] == 0:
            p1 = prio(s)
            p2 = inherited.get(s, p1)
        else:
            p2 = prio(s)
            p1 = min(AVOID, p2)
        return (p1, p2, -var_order[c], c)

    def forbidden(c: int) -> bool:
        s = var_int[c]
        return var_order[s] == 0 and prio(s) == ALWAYS

    rows = [i for i in range(graph.n_eqs) if graph.eq_derivative[i] == -1 and eq_order[i] >= 1]
    allowed: set[int] | None = None
    dummies: list[int] = []
    levels: list[tuple[list[int], list[int], list[int]]] = []
    has_choice = False
    level = 1
    while rows:
        seen: set[int] = set()
        cands: list[int] = []
        for r in rows:
            for v in eq_vars[r]:
                if v in seen:
                    continue
                seen.add(v)
                if var_order[v] >= 1 and (
                    var_der[v] == -1 if allowed is None else v in allowed
                ):
                    cands.append(v)
        cands.sort(key=lambda c: (forbidden(c), key(c)))
        default = _choose(level, rows, cands, eq_vars, forbidden, base)
        chosen = default
        if select is not None:
            chosen = list(select(level, list(rows), list(cands), list(default)))
            _validate(level, rows, cands, chosen, eq_vars, forbidden, base)
        levels.append((rows, cands, chosen))
        has_choice = has_choice or len(cands) > len(rows)
        dummies.extend(chosen)
        allowed = {var_int[c] for c in chosen if var_order[c] >= 2}
        rows = sorted(eq_int[r] for r in rows if eq_order[r] >= 2)
        level += 1

    dummy_set = set(dummies)
    states = [v for v in range(n) if var_der[v] != -1 and var_der[v] not in dummy_set]
    return DummyDerivativeResult(dummies, states, levels, has_choice)


def _local(rows: list[int], cols: list[int], eq_vars: list[list[int]]) -> list[list[int]]:
    loc = {c: k for k, c in enumerate(cols)}
    return [[loc[v] for v in dict.fromkeys(eq_vars[r]) if v in loc] for r in rows]


def _choose(
    level: int,
    rows: list[int],
    cands: list[int],
    eq_vars: list[list[int]],
    forbidden: Callable[[int], bool],
    base: list[int],
) -> list[int]:
    local = _local(rows, cands, eq_vars)
    usable = [k for k, c in enumerate(cands) if not forbidden(c)]
    m = preferred_column_matching(local, len(cands), usable)
    if m.size == len(rows):
        return [cands[k] for k in usable if m.var_to_eq[k] != -1]
    m = preferred_column_matching(local, len(cands), range(len(cands)))
    if m.size == len(rows):
        always = sorted({base[c] for c in cands if forbidden(c)})
        raise StateSelectionError(
            f"level {level}: variables {always} have stateSelect=always but cannot all be "
            "states", always)
    dm = dulmage_mendelsohn(local, len(cands), m)
    raise StructurallySingular(
        f"level {level} of dummy-derivative selection: differentiated equations "
        f"{[rows[i] for i in dm.overdetermined_eqs]} cannot be matched to distinct "
        "candidate derivatives (inconsistent incidence after index reduction?)",
        overdetermined_eqs=[rows[i] for i in dm.overdetermined_eqs],
        overdetermined_vars=[cands[k] for k in dm.overdetermined_vars],
    )


def _validate(
    level: int,
    rows: list[int],
    cands: list[int],
    chosen: list[int],
    eq_vars: list[list[int]],
    forbidden: Callable[[int], bool],
    base: list[int],
) -> None:
    cand_set = set(cands)
    bad = [c for c in chosen if c not in cand_set]
    if bad:
        raise StateSelectionError(f"select() at level {level} returned non-candidates {bad}", bad)
    if len(set(chosen)) != len(chosen) or len(chosen) != len(rows):
        raise StateSelectionError(
            f"select() at level {level} must return {len(rows)} distinct candidates, "
            f"got {chosen}", chosen)
    bad = [c for c in chosen if forbidden(c)]
    if bad:
        raise StateSelectionError(
            f"select() at level {level} chose {bad} as dummies, but variables "
            f"{sorted({base[c] for c in bad})} have stateSelect=always", bad)
    local = _local(rows, chosen, eq_vars)
    m = preferred_column_matching(local, len(chosen), range(len(chosen)))
    if m.size != len(rows):
        raise StateSelectionError(
            f"select() at level {level} returned {chosen}: structurally singular for rows "
            f"{rows}", chosen)
