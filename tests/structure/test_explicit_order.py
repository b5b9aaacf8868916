"""Explicit block order on integer incidence: blocks of equations that solve one scalar at a
time, in order, or the reason they do not."""

from __future__ import annotations

import numpy as np
import pytest

from bgmodelica.structure.explicit_order import explicit_order


def test_a_triangular_chain_is_ordered_block_after_block():
    # block 0: e0 uses u0; block 1: e1 uses u0, u1 and e2 uses u0, u2; block 2: e3 uses u1, u3
    rows = np.array([0, 1, 1, 2, 2, 3, 3])
    cols = np.array([0, 0, 1, 0, 2, 1, 3])
    order = explicit_order(4, rows, cols, [1, 2, 1])
    assert not isinstance(order, str)
    assert order.unknown_of.tolist() == [0, 1, 2, 3]
    assert order.blocks == [0, 1, 2]


def test_blocks_written_out_of_order_are_sorted():
    # block 0 uses what block 1 solves
    order = explicit_order(2, np.array([0, 0, 1]), np.array([0, 1, 1]), [1, 1])
    assert order.blocks == [1, 0]


@pytest.mark.parametrize(("rows", "cols", "sizes", "why"), [
    ([0, 1], [0, 0], [1, 1], "no perfect matching"),
    ([0, 0, 1, 1], [0, 1, 0, 1], [1, 1], "algebraic loop"),
    ([0, 0, 1, 1, 2, 2, 3], [0, 3, 1, 2, 2, 0, 3], [2, 1, 1], "cycle"),
])
def test_systems_that_do_not_solve_explicitly_say_why(rows, cols, sizes, why):
    found = explicit_order(sum(sizes), np.array(rows), np.array(cols), sizes)
    assert isinstance(found, str) and why in found


def test_a_block_using_its_own_unknowns_is_split_into_levels():
    # one block of three: e0 solves u0, e1 solves u1 from u0, e2 solves u2 from u0 and u1;
    # then a block of one using u2
    rows = np.array([0, 1, 1, 2, 2, 2, 3, 3])
    cols = np.array([0, 0, 1, 0, 1, 2, 2, 3])
    order = explicit_order(4, rows, cols, [3, 1])
    assert not isinstance(order, str)
    assert [(b, None if r is None else r.tolist()) for b, r in order.steps()] == \
        [(0, [0]), (0, [1]), (0, [2]), (1, None)]


def test_a_sum_over_the_other_rows_of_its_block_comes_last():
    # rows 0..3 solve u0..u3 alone; row 4 solves u4 from all of them (a ground node's sum)
    rows = np.array([0, 1, 2, 3, 4, 4, 4, 4, 4])
    cols = np.array([0, 1, 2, 3, 0, 1, 2, 3, 4])
    order = explicit_order(5, rows, cols, [5])
    assert [(b, r.tolist()) for b, r in order.steps()] == [(0, [0, 1, 2, 3]), (0, [4])]


def test_a_long_recurrence_is_refused():
    n = 100                                   # u_k = f(u_(k-1)) within one block
    rows = np.concatenate([np.arange(n), np.arange(1, n)])
    cols = np.concatenate([np.arange(n), np.arange(n - 1)])
    found = explicit_order(n, rows, cols, [n])
    assert isinstance(found, str) and "recurrence" in found


def test_an_empty_system_has_its_blocks_in_order():
    order = explicit_order(0, np.zeros(0), np.zeros(0), [0, 0])
    assert order.blocks == [0, 1] and order.unknown_of.size == 0
