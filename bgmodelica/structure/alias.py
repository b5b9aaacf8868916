"""Signed alias classes on integer variables (union-find with a sign per edge).

``a = s*b`` links are merged into classes; each class has one representative ``r`` and every
member ``m`` satisfies ``m = sign[m] * r``. Pure integer work: no symbolic library here.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass


@dataclass
class AliasClasses:
    """``rep[v]`` is the representative of ``v`` and ``sign[v]`` the factor ``v = sign*rep``.

    ``redundant`` lists the links (by position in the input) that closed a cycle and so were not
    used: the caller keeps those equations as ordinary equations.
    """

    rep: list[int]
    sign: list[float]
    redundant: list[int]


def alias_classes(n_vars: int, links: Iterable[tuple[int, int, float]],
                  rank: Sequence[int]) -> AliasClasses:
    """Merge links ``(a, b, s)`` meaning ``var a = s * var b`` (``s`` is +1 or -1).

    ``rank[x] > rank[y]`` says that ``x`` should represent a class rather than ``y``; on a
    tie the root of ``b``'s class represents the merged class.
    """
    parent = list(range(n_vars))
    sign = [1.0] * n_vars            # v = sign[v] * parent[v]
    redundant: list[int] = []

    def find(v: int) -> int:
        path = []
        while parent[v] != v:
            path.append(v)
            v = parent[v]
        root, acc = v, 1.0
        for node in reversed(path):   # compress from the root downwards
            acc *= sign[node]
            sign[node] = acc
            parent[node] = root
        return root

    for k, (a, b, s) in enumerate(links):
        pa, pb = parent[a], parent[b]
        ra = a if pa == a else (pa if parent[pa] == pa else find(a))
        rb = b if pb == b else (pb if parent[pb] == pb else find(b))
        if ra == rb:
            redundant.append(k)
            continue
        sa, sb = sign[a] if a != ra else 1.0, sign[b] if b != rb else 1.0
        # a = sa*ra, b = sb*rb, a = s*b  =>  ra = (s*sb/sa) * rb
        factor = s * sb / sa
        if rank[ra] > rank[rb]:
            parent[rb], sign[rb] = ra, 1.0 / factor
        else:
            parent[ra], sign[ra] = rb, factor
    rep, out_sign = [0] * n_vars, [1.0] * n_vars
    for v in range(n_vars):
        p = parent[v]
        r = v if p == v else (p if parent[p] == p else find(v))
        rep[v], out_sign[v] = r, (sign[v] if v != r else 1.0)
    return AliasClasses(rep, out_sign, redundant)
