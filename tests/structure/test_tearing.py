from __future__ import annotations

import pytest

from bgmodelica.structure import Tearing, block_lower_triangular, tear


def assert_tearing(eqs: list[int], vars_: list[int], eq_vars: list[list[int]],
                   t: Tearing, solvable=lambda e, v: True) -> None:
    assert len(t.tear_vars) == len(t.residual_eqs)
    assert sorted(t.residual_eqs + [e for e, _ in t.causal]) == sorted(eqs)
    assert sorted(t.tear_vars + [v for _, v in t.causal]) == sorted(vars_)
    known = set(t.tear_vars) | (set(v for vs in eq_vars for v in vs) - set(vars_))
    for e, v in t.causal:
        assert solvable(e, v)
        assert set(eq_vars[e]) - {v} <= known
        known.add(v)


def test_three_equation_loop() -> None:
    # e0: a = f(c), e1: b = g(a), e2: c = h(b) plus a known input u=3
    eq_vars = [[0, 2, 3], [1, 0], [2, 1]]
    blocks = block_lower_triangular([[0, 2], [1, 0], [2, 1]], 3)
    assert len(blocks) == 1 and blocks[0].size == 3
    t = tear(blocks[0].eqs, blocks[0].vars, eq_vars, lambda e, v: True)
    assert_tearing([0, 1, 2], [0, 1, 2], eq_vars, t)
    assert len(t.tear_vars) == 1 and len(t.causal) == 2


def test_solvability_is_respected() -> None:
    # same loop, but e1 cannot be solved for b (e.g. b appears as sin(b))
    eq_vars = [[0, 2], [1, 0], [2, 1]]

    def solvable(e: int, v: int) -> bool:
        return (e, v) != (1, 1)

    t = tear([0, 1, 2], [0, 1, 2], eq_vars, solvable)
    assert_tearing([0, 1, 2], [0, 1, 2], eq_vars, t, solvable)
    assert len(t.tear_vars) == 1
    assert (1, 1) not in t.causal


def test_dense_block_needs_more_tears() -> None:
    n = 5
    eq_vars = [list(range(n)) for _ in range(n)]
    t = tear(list(range(n)), list(range(n)), eq_vars)
    assert_tearing(list(range(n)), list(range(n)), eq_vars, t)
    assert len(t.tear_vars) == n - 1


def test_size_one_block() -> None:
    assert tear([4], [7], {4: [7, 1]}, lambda e, v: True) == Tearing([], [], [(4, 7)])
    assert tear([4], [7], {4: [7, 1]}, lambda e, v: False) == Tearing([7], [4], [])


def test_not_square() -> None:
    with pytest.raises(ValueError):
        tear([0, 1], [0], [[0], [0]], None)
