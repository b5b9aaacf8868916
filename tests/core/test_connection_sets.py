"""Connection sets from connect() links (``flatten_connections.connection_sets``): the same
sets, in the same order, as merging the links one by one in a union-find."""

from __future__ import annotations

import random

from bgmodelica.core.flatten_connections import connection_sets


def _reference(n: int, heads: list[int], tails: list[int], paths: list[str]) -> list[list[int]]:
    """Union-find over the nodes in the order they are first met (each link's head, then
    its tail, then every inside node); sets by their first node, members by path then
    first meeting."""
    parent: dict[int, int] = {}

    def find(x: int) -> int:
        parent.setdefault(x, x)
        while parent[x] != x:
            x = parent[x]
        return x

    for h, t in zip(heads, tails, strict=True):
        rh = find(h)
        parent[find(t)] = rh
    for k in range(n):
        find(2 * k)
    met = list(parent)                         # insertion order = first meeting
    rank = {node: i for i, node in enumerate(met)}
    sets: dict[int, list[int]] = {}
    for node in met:
        sets.setdefault(find(node), []).append(node)
    return [sorted(members, key=lambda m: (paths[m >> 1], rank[m]))
            for members in sets.values()]


def test_a_small_network_by_hand():
    # connectors 0..3; 0 and 1 inside, 2 seen from outside (node 5) linked to 0; 3 alone
    paths = ["b.p", "a.n", "top.p", "c.p"]
    sets = connection_sets(4, heads=[2, 5], tails=[0, 0], paths=paths)
    assert sets == [[2, 0, 5], [4], [6]]      # {a.n, b.p, top.p (outside)}, top.p inside, c.p


def test_no_connectors():
    assert connection_sets(0, [], [], []) == []


def test_random_networks_match_the_union_find():
    rng = random.Random(7)
    for _ in range(300):
        n = rng.randint(1, 12)
        links = rng.randint(0, 15)
        heads = [rng.randrange(2 * n) for _ in range(links)]
        tails = [rng.randrange(2 * n) for _ in range(links)]
        paths = [f"c{rng.randrange(100)}.{k}" for k in range(n)]
        assert connection_sets(n, heads, tails, paths) == _reference(n, heads, tails, paths)
