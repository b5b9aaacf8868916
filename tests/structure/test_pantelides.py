from __future__ import annotations

import pytest

from bgmodelica.structure import (
    EquationGraph,
    IndexReductionFailed,
    PantelidesResult,
    StructurallySingular,
    pantelides,
)

# Cartesian pendulum and coupled inertias variable indices (see conftest.py).
X, Y, VX, VY, T, DX, DY, DVX, DVY = range(9)
PHI1, W1, PHI2, W2, TAU, DPHI1, DW1, DPHI2, DW2 = range(9)


def assert_consistent(r: PantelidesResult) -> None:
    g = r.graph
    g.validate()
    m = r.matching
    active = g.active_equations()
    highest = [v for v in range(g.n_vars) if g.var_derivative[v] == -1]
    assert len(active) == len(highest)
    for i in range(g.n_eqs):
        v = m.eq_to_var[i]
        if i in active:
            assert v in g.eq_vars[i] and g.var_derivative[v] == -1 and m.var_to_eq[v] == i
        else:
            assert v == -1
    assert r.equation_order == g.eq_orders()
    assert r.variable_order == g.var_orders()
    for ne, e in r.new_equations:
        assert g.eq_derivative[e] == ne and ne > e
        expected = set(g.eq_vars[e]) | {g.var_derivative[j] for j in g.eq_vars[e]}
        assert set(g.eq_vars[ne]) == expected
    for nv, v in r.new_variables:
        assert g.var_derivative[v] == nv


def test_pendulum_index_3(pendulum: EquationGraph) -> None:
    r = pantelides(pendulum)
    assert_consistent(r)
    assert r.index == 3 and r.max_equation_differentiations == 2
    g = r.graph
    # the constraint is differentiated twice, x'=vx and y'=vy once
    assert r.new_equations == [(5, 4), (6, 5), (7, 0), (8, 1)]
    assert r.new_variables == [(9, DX), (10, DY)]  # x'' and y''
    assert g.eq_orders() == [0, 0, 0, 0, 0, 1, 2, 1, 1]
    assert set(g.eq_vars[6]) == {X, Y, DX, DY, 9, 10}
    assert set(g.eq_vars[7]) == {DX, 9, VX, DVX}
    assert set(g.eq_vars[8]) == {DY, 10, VY, DVY}
    assert pendulum.n_eqs == 5  # input untouched


def test_inertias_index_2(inertias: EquationGraph) -> None:
    r = pantelides(inertias)
    assert_consistent(r)
    assert r.index == 2 and r.max_equation_differentiations == 1
    assert r.new_equations == [(5, 4)]
    assert r.new_variables == []
    assert r.matching.eq_to_var[5] in (6, 8) and r.matching.var_to_eq[TAU] != -1
    assert {W1, W2} <= set(r.graph.eq_vars[5])


def test_index_1_and_idempotence(rc_circuit: EquationGraph, pendulum: EquationGraph) -> None:
    r = pantelides(rc_circuit)
    assert_consistent(r)
    assert r.index == 1 and r.new_equations == [] and r.new_variables == []
    assert r.graph == rc_circuit
    for g in (rc_circuit, pendulum):
        once = pantelides(g)
        twice = pantelides(once.graph)
        assert twice.new_equations == [] and twice.new_variables == []
        assert twice.graph == once.graph
        assert twice.index == once.index
        assert twice.matching.size == once.matching.size


def test_ode_has_index_0() -> None:
    # x' = -x  (x=0, dx=1)
    r = pantelides(EquationGraph([[1, 0]], 2, [1, -1]))
    assert r.index == 0


def test_overdetermined_raises() -> None:
    # x = 1, x = 2 (x algebraic), y' = y
    g = EquationGraph([[0], [0], [2, 1]], 3, [-1, 2, -1])
    with pytest.raises(StructurallySingular) as info:
        pantelides(g)
    assert info.value.overdetermined_eqs == [0, 1]
    assert info.value.overdetermined_vars == [0]


def test_derivative_contradiction_raises() -> None:
    # x = 1 and x' = 2: two equations for the single family {x, x'}
    g = EquationGraph([[0], [1]], 2, [1, -1])
    with pytest.raises(StructurallySingular) as info:
        pantelides(g)
    assert info.value.overdetermined_eqs == [0, 1] and info.value.overdetermined_vars == [0]


def test_underdetermined_raises() -> None:
    # x' = y + z, with y and z algebraic and no other equation
    g = EquationGraph([[3, 1, 2], [0, 1]], 4, [3, -1, -1, -1])
    with pytest.raises(StructurallySingular) as info:
        pantelides(g)
    assert info.value.underdetermined_vars
    assert set(info.value.underdetermined_vars) <= {0, 1, 2}


def test_differentiation_budget(pendulum: EquationGraph) -> None:
    with pytest.raises(IndexReductionFailed):
        pantelides(pendulum, max_differentiations=1)
    assert pantelides(pendulum, max_differentiations=2).index == 3


def test_refined_incidence_is_accepted(pendulum: EquationGraph) -> None:
    r = pantelides(pendulum)
    g = r.graph.copy()
    # a symbolic layer may drop entries that vanish after differentiation (here: none needed)
    g.eq_vars[6] = [X, Y, DX, DY, 9, 10]
    again = pantelides(g)
    assert again.new_equations == [] and again.index == 3


def test_chain_of_index_3_constraints_scales() -> None:
    # many independent pendulums: structure must stay local
    n = 300
    eqs: list[list[int]] = []
    n_vars = 9 * n
    var_der = [-1] * n_vars
    for k in range(n):
        o = 9 * k
        x, y, vx, vy, t, dx, dy, dvx, dvy = range(o, o + 9)
        var_der[x], var_der[y], var_der[vx], var_der[vy] = dx, dy, dvx, dvy
        eqs += [[dx, vx], [dy, vy], [dvx, t, x], [dvy, t, y], [x, y]]
    r = pantelides(EquationGraph(eqs, n_vars, var_der))
    assert r.index == 3 and len(r.new_equations) == 4 * n and len(r.new_variables) == 2 * n
