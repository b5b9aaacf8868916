"""The compiled (scipy) matching and BLT ordering used for large systems agree with the
pure-Python algorithms: same matching size, same blocks, a valid solve order."""

from __future__ import annotations

import random

import pytest

from bgmodelica.structure import block_lower_triangular, maximum_matching
from bgmodelica.structure.compiled import (
    LARGE,
    compiled_blocks,
    compiled_matching,
    derivative_bases,
    remap_rows,
)


def _square_system(n: int, extra: int, seed: int) -> list[list[int]]:
    """n equations in n unknowns with a hidden perfect matching plus random extra edges
    (which create algebraic loops of various sizes)."""
    rng = random.Random(seed)
    perm = list(range(n))
    rng.shuffle(perm)
    rows = [{perm[i]} for i in range(n)]
    for _ in range(extra):
        rows[rng.randrange(n)].add(rng.randrange(n))
    return [sorted(r) for r in rows]


@pytest.mark.parametrize("seed", range(6))
def test_compiled_matching_is_maximum(seed: int) -> None:
    rng = random.Random(seed)
    n_eq, n_var = 300, 280
    rows = [sorted(rng.sample(range(n_var), rng.randint(0, 3))) for _ in range(n_eq)]
    eq_to_var, var_to_eq = compiled_matching(rows, n_var)
    reference = maximum_matching(rows, n_var)
    assert sum(v >= 0 for v in eq_to_var) == reference.size
    for i, v in enumerate(eq_to_var):
        if v >= 0:
            assert v in rows[i] and var_to_eq[v] == i
    assert sum(e >= 0 for e in var_to_eq) == reference.size


@pytest.mark.parametrize("seed", range(6))
def test_compiled_blocks_match_tarjan(seed: int) -> None:
    rows = _square_system(400, 450, seed)
    matching = maximum_matching(rows, 400)
    assert matching.size == 400
    groups = compiled_blocks(rows, matching.var_to_eq)
    assert groups is not None
    python = block_lower_triangular(rows, 400, matching)      # below LARGE: Tarjan in Python
    assert sorted(map(tuple, groups)) == sorted(tuple(b.eqs) for b in python)
    assert any(len(g) > 1 for g in groups)                     # loops were exercised
    done: set[int] = set()                                     # every block's needs are met
    for g in groups:
        solved = {matching.eq_to_var[e] for e in g}
        assert all(v in solved or matching.var_to_eq[v] in done for e in g for v in rows[e])
        done.update(g)


def test_large_systems_take_the_compiled_path() -> None:
    n = LARGE + 10
    rows = [[i, i - 1] if i else [0] for i in range(n)]        # a lower bidiagonal chain
    matching = maximum_matching(rows, n)
    assert matching.size == n
    blocks = block_lower_triangular(rows, n, matching)
    assert [b.eqs for b in blocks] == [[i] for i in range(n)]
    assert [b.vars for b in blocks] == [[i] for i in range(n)]


@pytest.mark.parametrize("seed", range(4))
def test_remap_rows_equals_the_set_comprehension(seed: int) -> None:
    rng = random.Random(seed)
    n_in, n_out = 200, 60
    rows = [[rng.randrange(n_in) for _ in range(rng.randint(0, 6))] for _ in range(150)]
    mapping = [rng.randrange(-1, n_out) for _ in range(n_in)]
    expected = [sorted({mapping[j] for j in row} - {-1}) for row in rows]
    assert remap_rows(rows, mapping) == expected
    assert remap_rows([], mapping) == []
    assert remap_rows([[], []], mapping) == [[], []]


def test_derivative_bases_follow_whole_chains() -> None:
    # 0 <- der 3 <- der 5 (x, der(x), der(der(x))); 1 alone; 2 <- der 4
    der_of = [-1, -1, -1, 0, 2, 3]
    assert derivative_bases(der_of).tolist() == [0, 1, 2, 0, 2, 0]
    assert derivative_bases([]).tolist() == []
