"""Explicit block order on integer incidence: blocks of equations that solve one scalar at a
time, in order, or the reason they do not."""

from __future__ import annotations

import numpy as np
import pytest

from bgmodelica.structure.explicit_order import MAX_LEVELS, explicit_order


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


def test_blocks_that_depend_on_each_other_both_ways_are_solved_in_parts():
    # block 0: e0 uses u0, u3 and e1 uses u1, u2; block 1: e2 uses u2, u0; block 2: e3 uses
    # u3. Block by block this is a cycle (0 needs 1 and 2, 1 needs 0); row by row it is not.
    rows = np.array([0, 0, 1, 1, 2, 2, 3])
    cols = np.array([0, 3, 1, 2, 2, 0, 3])
    order = explicit_order(4, rows, cols, [2, 1, 1])
    assert [(b, None if r is None else r.tolist()) for b, r in order.steps()] == \
        [(2, None), (0, [0]), (1, None), (0, [1])]


def _chain(depth: int) -> tuple[list[int], list[int]]:
    """``depth`` one-row blocks, row k using the unknown of row k - 1."""
    rows = list(range(depth)) + list(range(1, depth))
    return rows, list(range(depth)) + list(range(depth - 1))


def test_a_deep_system_is_ordered_block_by_block():
    rows, cols = _chain(MAX_LEVELS + 10)
    n = len(set(rows))
    order = explicit_order(n, np.array(rows[::-1]), np.array(cols[::-1]), [1] * n)
    assert order.blocks == list(range(n)) and order.rows is None


def test_a_deep_system_with_blocks_in_a_cycle_is_refused():
    # the chain makes the system deeper than MAX_LEVELS; then block A (rows a0, a1) and block
    # B (row b) with a1 using b and b using a0 are a cycle block by block
    rows, cols = _chain(MAX_LEVELS + 10)
    n = len(set(rows))
    a0, a1, b = n, n + 1, n + 2
    rows += [a0, a1, a1, b, b]
    cols += [a0, a1, b, b, a0]
    found = explicit_order(n + 3, np.array(rows), np.array(cols), [1] * n + [2, 1])
    assert isinstance(found, str) and "cycle" in found


def test_a_long_recurrence_is_refused():
    n = 100                                   # u_k = f(u_(k-1)) within one block
    rows = np.concatenate([np.arange(n), np.arange(1, n)])
    cols = np.concatenate([np.arange(n), np.arange(n - 1)])
    found = explicit_order(n, rows, cols, [n])
    assert isinstance(found, str) and "recurrence" in found


def test_an_empty_system_has_its_blocks_in_order():
    order = explicit_order(0, np.zeros(0), np.zeros(0), [0, 0])
    assert order.blocks == [0, 1] and order.unknown_of.size == 0
