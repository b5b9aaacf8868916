from __future__ import annotations

import random

import pytest

from bgmodelica.structure import (
    Block,
    StructurallySingular,
    block_lower_triangular,
    maximum_matching,
)


def assert_blt(eq_vars: list[list[int]], blocks: list[Block]) -> None:
    solved: set[int] = set()
    seen_eqs: list[int] = []
    for b in blocks:
        assert len(b.eqs) == len(b.vars)
        for e, v in zip(b.eqs, b.vars, strict=True):
            assert v in eq_vars[e]
        mine = set(b.vars)
        for e in b.eqs:
            assert set(eq_vars[e]) <= solved | mine
        solved |= mine
        seen_eqs += b.eqs
    assert sorted(seen_eqs) == list(range(len(eq_vars)))


def test_lower_triangular_in_scrambled_order() -> None:
    # e0 ~ {2, 1}, e1 ~ {0}, e2 ~ {0, 1}: solve e1 (x0), then e2 (x1), then e0 (x2).
    eq_vars = [[2, 1], [0], [0, 1]]
    blocks = block_lower_triangular(eq_vars, 3)
    assert [(b.eqs, b.vars) for b in blocks] == [([1], [0]), ([2], [1]), ([0], [2])]
    assert all(b.size == 1 for b in blocks)


def test_two_cycle() -> None:
    # e0 ~ {0}, e1 ~ {0, 1, 2}, e2 ~ {1, 2}, e3 ~ {2, 3}
    eq_vars = [[0], [0, 1, 2], [1, 2], [2, 3]]
    blocks = block_lower_triangular(eq_vars, 4)
    assert_blt(eq_vars, blocks)
    assert [b.eqs for b in blocks] == [[0], [1, 2], [3]]
    assert sorted(blocks[1].vars) == [1, 2]


def test_given_matching_and_singular() -> None:
    eq_vars = [[0, 1], [1]]
    m = maximum_matching(eq_vars, 2)
    assert_blt(eq_vars, block_lower_triangular(eq_vars, 2, m))
    with pytest.raises(StructurallySingular):
        block_lower_triangular([[0], [0]], 2)


def test_long_chain_is_not_recursive() -> None:
    n = 100_000
    eq_vars = [[0]] + [[i, i - 1] for i in range(1, n)]
    eq_vars[0].append(n - 1)  # one big cycle through everything
    blocks = block_lower_triangular(eq_vars, n)
    assert len(blocks) == 1 and blocks[0].size == n
    eq_vars[0].pop()
    blocks = block_lower_triangular(eq_vars, n)
    assert [b.eqs[0] for b in blocks[:3]] == [0, 1, 2]


def test_random_systems() -> None:
    rng = random.Random(7)
    for _ in range(100):
        n = rng.randint(1, 30)
        perm = list(range(n))
        rng.shuffle(perm)
        eq_vars = [[perm[i]] + [rng.randrange(n) for _ in range(rng.randint(0, 2))]
                   for i in range(n)]
        assert_blt(eq_vars, block_lower_triangular(eq_vars, n))
