"""The signal-flow graph of a causal bond graph: effort and flow of every bond, storage
states, sources and detectors as nodes, the causal dependencies as edges
(:func:`signal_graph`); its zero-order (algebraic) loops (:func:`zero_order_paths`) and the
causal paths the structural analysis follows (:func:`reach`, :func:`path_to`)."""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from typing import TYPE_CHECKING

from .graph import JUNCTIONS, STORAGE, SWITCHES, TWO_PORTS, strong_bond

if TYPE_CHECKING:
    from .causality import Causality


@dataclass
class SignalGraph:
    """Causal signal-flow graph: nodes ("e", bond), ("f", bond), ("x", storage),
    ("u", source), ("y", detector), ("ext", adapter); edges (src, dst, algebraic?, element)."""

    edges: list[tuple[tuple, tuple, bool, str]]

    def successors(self, algebraic_only: bool = False) -> dict[tuple, list[tuple]]:
        out: dict[tuple, list[tuple]] = {}
        for s, d, alg, _ in self.edges:
            if alg or not algebraic_only:
                out.setdefault(s, []).append(d)
                out.setdefault(d, [])
        return out


def signal_graph(c: Causality) -> SignalGraph:
    """Signal-flow graph of a causal bond graph (see :class:`SignalGraph`)."""
    g, eto = c.graph, c.effort_to
    inc = g.incidence()
    edges: list[tuple[tuple, tuple, bool, str]] = []

    def add(s, d, alg, el):
        edges.append((s, d, alg, el))

    for n in g.nodes.values():
        bonds = [b for b in inc[n.name] if b.number in eto]
        name = n.name
        if n.kind in JUNCTIONS:
            strong = strong_bond(n, bonds, eto)
            if strong is None:
                continue
            s = strong.number
            for b in bonds:
                if b.number == s:
                    continue
                if n.kind == "0":
                    add(("e", s), ("e", b.number), True, name)
                    add(("f", b.number), ("f", s), True, name)
                else:
                    add(("f", s), ("f", b.number), True, name)
                    add(("e", b.number), ("e", s), True, name)
            continue
        if n.kind in TWO_PORTS:
            if len(bonds) != 2:
                continue
            a, b = bonds
            a_in, b_in = eto[a.number] == name, eto[b.number] == name
            if n.kind in ("TF", "MTF"):
                if a_in == b_in:
                    continue
                x, y = (a, b) if a_in else (b, a)          # effort in at x, out at y
                add(("e", x.number), ("e", y.number), True, name)
                add(("f", y.number), ("f", x.number), True, name)
            else:
                if a_in != b_in:
                    continue
                v_in, v_out = ("e", "f") if a_in else ("f", "e")
                add((v_in, a.number), (v_out, b.number), True, name)
                add((v_in, b.number), (v_out, a.number), True, name)
            continue
        if not bonds:
            continue
        k = bonds[0].number
        into = eto[k] == name
        if n.kind == "Se" and not into and not n.zero:
            add(("u", name), ("e", k), True, name)
        elif n.kind == "Sf" and into and not n.zero:
            add(("u", name), ("f", k), True, name)
        elif n.kind == "De":
            add(("e", k), ("y", name), True, name)
        elif n.kind == "Df":
            add(("f", k), ("y", name), True, name)
        elif n.kind == "R" or n.kind in SWITCHES:
            if into:
                add(("e", k), ("f", k), True, name)
            else:
                add(("f", k), ("e", k), True, name)
        elif n.kind in STORAGE:
            integral = c.storage.get(name) == "integral"
            v_in = "e" if into else "f"
            v_out = "f" if into else "e"
            add((v_in, k), ("x", name), not integral, name)
            add(("x", name), (v_out, k), integral, name)
        elif n.kind == "X":
            v_in = "e" if into else "f"
            v_out = "f" if into else "e"
            add((v_in, k), ("ext", name), False, name)
            add(("ext", name), (v_out, k), False, name)
    return SignalGraph(edges)


def _sccs(succ: dict[tuple, list[tuple]]) -> list[list[tuple]]:
    """Tarjan's strongly connected components (iterative)."""
    index: dict[tuple, int] = {}
    low: dict[tuple, int] = {}
    on: set[tuple] = set()
    stack: list[tuple] = []
    out: list[list[tuple]] = []
    counter = 0
    for root in succ:
        if root in index:
            continue
        work = [(root, iter(succ[root]))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            advanced = False
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(succ[w])))
                    advanced = True
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                out.append(comp)
    return out


def zero_order_paths(c: Causality) -> list[dict]:
    """Algebraic loops of the causal graph: strongly connected sets of effort/flow signals
    linked by algebraic (non-integrating) relations. Each: ``{"bonds": [...], "elements":
    [...], "resistors": [...]}`` (resistors: the R and Sw elements on the loop)."""
    sg = signal_graph(c)
    comps = [comp for comp in _sccs(sg.successors(algebraic_only=True)) if len(comp) > 1]
    out = []
    for comp in comps:
        members = set(comp)
        bonds = sorted({v[1] for v in comp if v[0] in ("e", "f")})
        elements = []
        for s, d, alg, el in sg.edges:
            if alg and s in members and d in members and el not in elements:
                elements.append(el)
        resistors = [e for e in elements if c.graph.nodes[e].kind in ("R", *SWITCHES)]
        out.append({"bonds": bonds, "elements": elements, "resistors": resistors})
    return out


def reach(sg: SignalGraph, starts: list[tuple], reverse: bool = False) -> dict[tuple, tuple]:
    """Breadth-first reachability over every edge; returns node -> predecessor."""
    succ: dict[tuple, list[tuple]] = {}
    for s, d, _, _ in sg.edges:
        if reverse:
            s, d = d, s
        succ.setdefault(s, []).append(d)
    parent: dict[tuple, tuple] = {s: s for s in starts}
    queue = deque(starts)
    while queue:
        v = queue.popleft()
        for w in succ.get(v, ()):
            if w not in parent:
                parent[w] = v
                queue.append(w)
    return parent


def path_to(parent: dict[tuple, tuple], target: tuple) -> list[tuple]:
    """Node sequence from a BFS start to ``target`` (empty if unreachable)."""
    if target not in parent:
        return []
    out = [target]
    while parent[out[-1]] != out[-1]:
        out.append(parent[out[-1]])
    return out[::-1]
