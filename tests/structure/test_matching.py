from __future__ import annotations

import random

import pytest

from bgmodelica.structure import Matching, augment, maximum_matching, preferred_column_matching


def assert_valid(eq_vars: list[list[int]], n_vars: int, m: Matching) -> None:
    assert len(m.eq_to_var) == len(eq_vars) and len(m.var_to_eq) == n_vars
    for i, v in enumerate(m.eq_to_var):
        if v != -1:
            assert v in eq_vars[i]
            assert m.var_to_eq[v] == i
    for v, i in enumerate(m.var_to_eq):
        if i != -1:
            assert m.eq_to_var[i] == v


def test_textbook_example() -> None:
    # Greedy matches e0-v0, e1-v1 and blocks e2; HK must reroute to a perfect matching.
    eq_vars = [[0, 1], [1, 2], [0], [2, 3]]
    m = maximum_matching(eq_vars, 4)
    assert_valid(eq_vars, 4, m)
    assert m.size == 4
    assert m.eq_to_var[2] == 0 and m.eq_to_var[0] == 1


def test_deficient_and_allowed() -> None:
    eq_vars = [[0], [0], [1, 2]]
    m = maximum_matching(eq_vars, 3)
    assert m.size == 2
    m = maximum_matching(eq_vars, 3, var_allowed=[True, False, False])
    assert m.size == 1 and m.eq_to_var[2] == -1
    m = maximum_matching(eq_vars, 3, eq_allowed=[False, True, True])
    assert m.eq_to_var[0] == -1 and m.eq_to_var[1] == 0


def test_warm_start_long_augmenting_path() -> None:
    # Path graph: eq i ~ {i, i+1}, last eq ~ {0}; initial eq i -> i leaves a path of length n.
    n = 20000
    eq_vars = [[i, i + 1] for i in range(n - 1)] + [[0]]
    initial = Matching(list(range(n - 1)) + [-1], list(range(n - 1)) + [-1])
    m = maximum_matching(eq_vars, n, initial=initial)
    assert m.size == n
    assert_valid(eq_vars, n, m)
    m2 = initial.copy()
    assert augment(n - 1, eq_vars, m2)
    assert m2.size == n
    assert_valid(eq_vars, n, m2)


def test_warm_start_drops_disallowed_pairs() -> None:
    eq_vars = [[0, 1], [1]]
    initial = Matching([1, -1], [-1, 0])
    m = maximum_matching(eq_vars, 2, var_allowed=[True, True], initial=initial)
    assert m.size == 2 and m.eq_to_var == [0, 1]
    m = maximum_matching(eq_vars, 2, var_allowed=[True, False], initial=initial)
    assert m.eq_to_var == [0, -1]


def test_augment_fails_leaves_matching() -> None:
    eq_vars = [[0], [0]]
    m = maximum_matching(eq_vars, 1)
    before = m.copy()
    assert not augment(1, eq_vars, m)
    assert m == before


def test_preferred_column_matching_is_lexicographic() -> None:
    # rows: r0 ~ {a,b}, r1 ~ {b,c}; columns 0=a, 1=b, 2=c.
    rows = [[0, 1], [1, 2]]
    m = preferred_column_matching(rows, 3, [1, 0, 2])
    assert sorted(v for v in m.eq_to_var) == [0, 1]
    m = preferred_column_matching(rows, 3, [2, 1, 0])
    assert sorted(m.eq_to_var) == [1, 2]
    # a later column still joins when an augmenting path re-routes an earlier one
    m = preferred_column_matching([[0], [0, 1]], 3, [1, 2, 0])
    assert sorted(m.eq_to_var) == [0, 1]
    # columns not in the preference are never used
    m = preferred_column_matching(rows, 3, [0, 1])
    assert sorted(m.eq_to_var) == [0, 1]
    m = preferred_column_matching(rows, 3, [0])
    assert m.size == 1


def _random_graph(rng: random.Random, n_eqs: int, n_vars: int, p: float) -> list[list[int]]:
    return [[v for v in range(n_vars) if rng.random() < p] for _ in range(n_eqs)]


def test_random_graphs_against_networkx() -> None:
    nx = pytest.importorskip("networkx")
    rng = random.Random(1234)
    for trial in range(150):
        n_eqs = rng.randint(1, 40)
        n_vars = rng.randint(1, 40)
        p = rng.choice([0.03, 0.08, 0.15, 0.4])
        eq_vars = _random_graph(rng, n_eqs, n_vars, p)
        m = maximum_matching(eq_vars, n_vars)
        assert_valid(eq_vars, n_vars, m)
        g = nx.Graph()
        g.add_nodes_from(("e", i) for i in range(n_eqs))
        g.add_nodes_from(("v", j) for j in range(n_vars))
        g.add_edges_from((("e", i), ("v", j)) for i, vs in enumerate(eq_vars) for j in vs)
        ref = nx.bipartite.hopcroft_karp_matching(g, top_nodes=[("e", i) for i in range(n_eqs)])
        assert m.size == len(ref) // 2, trial


def test_random_preferred_matching_is_maximum_and_greedy() -> None:
    nx = pytest.importorskip("networkx")
    rng = random.Random(99)
    for _ in range(60):
        n_rows, n_cols = rng.randint(1, 12), rng.randint(1, 15)
        rows = _random_graph(rng, n_rows, n_cols, 0.25)
        order = list(range(n_cols))
        rng.shuffle(order)
        m = preferred_column_matching(rows, n_cols, order)
        assert_valid(rows, n_cols, m)
        assert m.size == maximum_matching(rows, n_cols).size
        chosen = {v for v in m.eq_to_var if v != -1}

        def rank(cols: set[int], rows: list[list[int]] = rows, n_rows: int = n_rows) -> int:
            g = nx.Graph()
            g.add_nodes_from(("r", i) for i in range(n_rows))
            g.add_edges_from((("r", i), ("c", c)) for i, vs in enumerate(rows) for c in vs
                             if c in cols)
            top = [("r", i) for i in range(n_rows)]
            return len(nx.bipartite.hopcroft_karp_matching(g, top_nodes=top)) // 2

        # Greedy basis: each prefix of the order contributes exactly its rank increase.
        for k in range(1, n_cols + 1):
            prefix = set(order[:k])
            assert len(chosen & prefix) == rank(prefix)
