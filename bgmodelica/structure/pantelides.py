"""Pantelides' structural index reduction (Pantelides 1988; Cellier & Kofman ch. 7-8).

Works purely on the incidence: differentiating equation ``i`` creates a new equation whose
incidence is ``vars(i) | {der(j) for j in vars(i)}``; derivative variables are created on
demand. New equations and variables are appended at the end of their lists.

Unmatched equations are handled one at a time after a Hopcroft-Karp warm start. When no
augmenting path exists, the equations and highest-derivative variables visited by the failed
search form a minimal structurally singular subset (every one of them must be differentiated);
they are differentiated, the matching is carried over to the derivatives, and the search is
repeated from the derivative of the failing equation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .diagnosis import dulmage_mendelsohn
from .errors import IndexReductionFailed, StructurallySingular
from .graph import EquationGraph, derivative_chains, gc_paused
from .matching import Matching, maximum_matching


@dataclass
class PantelidesResult:
    """Outcome of :func:`pantelides`.

    ``matching`` pairs every highest-order equation with a highest-derivative variable
    (differentiated equations and variables that have a derivative are unmatched).
    ``new_equations``/``new_variables`` are ``(new index, index it is the derivative of)`` in
    creation order: a derivative always comes after its source.

    ``index`` follows Pryce's structural-index convention: the largest number of times an
    equation was differentiated, plus one if some variable remains algebraic (appears with no
    derivative at all). So an ODE has index 0, a semi-explicit index-1 DAE index 1, the
    Cartesian pendulum index 3.
    """

    graph: EquationGraph
    matching: Matching
    new_equations: list[tuple[int, int]]
    new_variables: list[tuple[int, int]]
    equation_order: list[int]
    variable_order: list[int]
    max_equation_differentiations: int
    index: int


def _family_check(
    graph: EquationGraph, var_order: list[int], base: list[int], highest: Matching
) -> None:
    """Raise StructurallySingular unless active equations match variable families 1:1.

    This is the condition (a transversal of Pryce's signature matrix) under which Pantelides'
    algorithm terminates. The highest-derivative matching is a valid warm start since each
    family has exactly one highest-derivative variable.
    """
    families = np.flatnonzero(np.asarray(var_order, dtype=np.int64) == 0)
    fam_of_base = np.full(graph.n_vars, -1, dtype=np.int64)
    fam_of_base[families] = np.arange(families.size)
    fam_arr = fam_of_base[np.asarray(base, dtype=np.int64)]
    active = graph.active_equations()
    if len(active) == families.size:           # the warm start may already be perfect
        start_vars = np.asarray(highest.eq_to_var, dtype=np.int64)[active]
        if np.all(start_vars >= 0) and (not start_vars.size or np.bincount(
                fam_arr[start_vars], minlength=families.size).max() == 1):
            return
    fam = fam_arr.tolist()
    family_vars = families.tolist()
    eq_vars = graph.eq_vars
    fam_eqs = [[fam[v] for v in eq_vars[i]] for i in active]
    start = Matching.empty(len(active), len(family_vars))
    for k, i in enumerate(active):
        v = highest.eq_to_var[i]
        if v != -1:
            start.eq_to_var[k] = fam[v]
            start.var_to_eq[fam[v]] = k
    m = maximum_matching(fam_eqs, len(family_vars), initial=start)
    if m.size == len(active) == len(family_vars):
        return
    dm = dulmage_mendelsohn(fam_eqs, len(family_vars), m)
    raise StructurallySingular(
        None,
        overdetermined_eqs=sorted(active[i] for i in dm.overdetermined_eqs),
        overdetermined_vars=sorted(family_vars[k] for k in dm.overdetermined_vars),
        underdetermined_eqs=sorted(active[i] for i in dm.underdetermined_eqs),
        underdetermined_vars=sorted(family_vars[k] for k in dm.underdetermined_vars),
    )


@gc_paused()
def pantelides(graph: EquationGraph, max_differentiations: int | None = None) -> PantelidesResult:
    """Run Pantelides' algorithm on a copy of ``graph``.

    The input may already contain differentiated equations (e.g. a previous result with a
    refined incidence): only highest-order equations and highest-derivative variables are
    matched, so running it on its own output changes nothing.

    ``max_differentiations`` bounds the differentiation order of any equation (default: a
    generous bound that a structurally nonsingular system never reaches); exceeding it raises
    :class:`IndexReductionFailed`. A system whose equations cannot be matched to distinct
    variable families (counting ``x``, ``der(x)``, ... as one) raises
    :class:`StructurallySingular` with the Dulmage-Mendelsohn parts in equation and base-variable
    indices.
    """
    g = graph.copy()
    g.validate()
    _, var_order, base = derivative_chains(g.var_derivative, "variable")
    _, eq_order, _ = derivative_chains(g.eq_derivative, "equation")
    eq_vars = g.eq_vars
    var_der = g.var_derivative
    eq_der = g.eq_derivative

    highest = [d == -1 for d in var_der]
    active = [d == -1 for d in eq_der]
    m = maximum_matching(eq_vars, g.n_vars, highest, eq_allowed=active)
    _family_check(g, var_order, base, m)
    eq_to_var, var_to_eq = m.eq_to_var, m.var_to_eq
    if max_differentiations is None:
        max_var_order = max(var_order, default=0)
        max_differentiations = (len(eq_vars) + 1) * max(1, max_var_order) + max(
            eq_order, default=0)

    new_equations: list[tuple[int, int]] = []
    new_variables: list[tuple[int, int]] = []
    eq_stamp = [0] * len(eq_vars)
    var_stamp = [0] * g.n_vars
    stamp = 0

    pending = [i for i in range(len(eq_vars)) if active[i] and eq_to_var[i] == -1]
    for k in pending:
        while True:
            stamp += 1
            ok, col_eqs, col_vars = _search(k, eq_vars, var_der, var_to_eq, eq_to_var,
                                            eq_stamp, var_stamp, stamp)
            if ok:
                break
            # Differentiate the minimal structurally singular subset found.
            for v in col_vars:
                nv = len(var_der)
                var_der[v] = nv
                var_der.append(-1)
                var_to_eq.append(-1)
                var_stamp.append(0)
                var_order.append(var_order[v] + 1)
                new_variables.append((nv, v))
            for e in col_eqs:
                ne = len(eq_vars)
                order = eq_order[e] + 1
                if order > max_differentiations:
                    raise IndexReductionFailed(
                        f"equation {e} would need differentiation order {order} "
                        f"(limit {max_differentiations})"
                    )
                vs = eq_vars[e]
                eq_vars.append(list(dict.fromkeys(vs + [var_der[j] for j in vs])))
                eq_der[e] = ne
                eq_der.append(-1)
                eq_to_var.append(-1)
                eq_stamp.append(0)
                eq_order.append(order)
                new_equations.append((ne, e))
            for e in col_eqs:
                v = eq_to_var[e]
                if v != -1:
                    ne, nv = eq_der[e], var_der[v]
                    eq_to_var[ne] = nv
                    var_to_eq[nv] = ne
                    eq_to_var[e] = -1
                    var_to_eq[v] = -1
            k = eq_der[k]

    g.n_vars = len(var_der)
    max_eq = max(eq_order, default=0)
    has_algebraic = any(var_order[j] == 0 and var_der[j] == -1 for j in range(g.n_vars))
    return PantelidesResult(
        graph=g,
        matching=Matching(eq_to_var, var_to_eq),
        new_equations=new_equations,
        new_variables=new_variables,
        equation_order=eq_order,
        variable_order=var_order,
        max_equation_differentiations=max_eq,
        index=max_eq + (1 if has_algebraic else 0),
    )


def _search(
    root: int,
    eq_vars: list[list[int]],
    var_der: list[int],
    var_to_eq: list[int],
    eq_to_var: list[int],
    eq_stamp: list[int],
    var_stamp: list[int],
    stamp: int,
) -> tuple[bool, list[int], list[int]]:
    """Augmenting-path DFS from ``root`` over highest-derivative variables.

    Returns ``(True, [], [])`` after augmenting, else ``(False, colored eqs, colored vars)``.
    """
    eq_stamp[root] = stamp
    col_eqs = [root]
    col_vars: list[int] = []
    us = [root]
    vs: list[int] = []
    ptr = [0]
    fresh = True
    while us:
        u = us[-1]
        au = eq_vars[u]
        if fresh:
            # Look-ahead: a free highest-derivative variable of u ends the search at once.
            for v in au:
                if var_der[v] == -1 and var_to_eq[v] == -1:
                    vs.append(v)
                    for k, uu in enumerate(us):
                        eq_to_var[uu] = vs[k]
                        var_to_eq[vs[k]] = uu
                    return True, [], []
        i = ptr[-1]
        nxt = -1
        while i < len(au):
            v = au[i]
            i += 1
            if var_der[v] != -1 or var_stamp[v] == stamp:
                continue
            var_stamp[v] = stamp
            col_vars.append(v)
            w = var_to_eq[v]
            if eq_stamp[w] != stamp:
                eq_stamp[w] = stamp
                col_eqs.append(w)
                vs.append(v)
                nxt = w
                break
        ptr[-1] = i
        if nxt >= 0:
            us.append(nxt)
            ptr.append(0)
            fresh = True
        else:
            us.pop()
            ptr.pop()
            if vs:
                vs.pop()
            fresh = False
    return False, col_eqs, col_vars
