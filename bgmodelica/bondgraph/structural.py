"""Structural controllability and observability of a causal bond graph.

Paper Theorems 1 and 2 (Sueur & Dauphin-Tanguy): the model is structurally state controllable
(observable) if

1. every storage element in integral causality in the BGI is *causally connected* to a source
   (to a detector): a causal path leads from the source's output to the element's state
   (from the state to the detector's input), through junctions, R, TF, GY and other storage
   elements; and
2. the rank condition holds: rank [A B] = n (rank [A; C] = n). Structurally it reads on the
   BGD: put every storage element in derivative causality, the sources (detectors) being
   dualized if necessary; each storage element of the BGI left in integral causality lowers
   the structural rank by one.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .causality import BGD, Causality, assign_causality, path_to, reach, signal_graph
from .graph import Graph


@dataclass
class StructuralProperty:
    """Controllability (or observability) verdict.

    ok: both conditions hold. states: storage elements in integral causality (the BGI
    states). unconnected: those without a causal path to a source (detector). bgd_integral:
    storage left in integral causality in the BGD with dualized sources (detectors).
    rank: structural rank of [A B] (of [A; C]); n: number of states. paths: state ->
    list of bonds of one causal path (source first / detector last).
    """

    kind: str
    ok: bool
    states: list[str]
    connected_to: dict[str, str] = field(default_factory=dict)
    unconnected: list[str] = field(default_factory=list)
    bgd_integral: list[str] = field(default_factory=list)
    rank: int = 0
    n: int = 0
    paths: dict[str, list[int]] = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {"kind": self.kind, "ok": self.ok, "states": self.states,
                "connected_to": dict(self.connected_to), "unconnected": self.unconnected,
                "bgd_integral": self.bgd_integral, "rank": self.rank, "n": self.n,
                "paths": {k: list(v) for k, v in self.paths.items()}}


def _bonds_on(path: list[tuple]) -> list[int]:
    out: list[int] = []
    for v in path:
        if v[0] in ("e", "f") and (not out or out[-1] != v[1]):
            out.append(v[1])
    return out


def controllability(graph: Graph, bgi: Causality | None = None) -> StructuralProperty:
    """Structural state controllability (Theorem 1 plus the BGD rank condition)."""
    bgi = bgi or assign_causality(graph)
    sg = signal_graph(bgi)
    sources = [("u", n.name) for n in graph.of_kind("Se", "Sf") if not n.zero]
    states = bgi.integral
    out = StructuralProperty("controllability", True, list(states), n=len(states))
    for x in states:
        best: list[tuple] = []
        for s in sources:
            p = path_to(reach(sg, [s]), ("x", x))
            if p and (not best or len(p) < len(best)):
                best = p
        if best:
            out.connected_to[x] = best[0][1]
            out.paths[x] = _bonds_on(best)
        else:
            out.unconnected.append(x)
    bgd = assign_causality(graph, BGD, dualize={"Se", "Sf"}, check=False)
    out.bgd_integral = [x for x in states if bgd.storage.get(x) == "integral"]
    out.rank = len(states) - len(out.bgd_integral)
    out.ok = not out.unconnected and not out.bgd_integral
    return out


def observability(graph: Graph, bgi: Causality | None = None) -> StructuralProperty:
    """Structural state observability (Theorem 2 plus the BGD rank condition)."""
    bgi = bgi or assign_causality(graph)
    sg = signal_graph(bgi)
    detectors = [("y", n.name) for n in graph.of_kind("De", "Df")]
    states = bgi.integral
    out = StructuralProperty("observability", True, list(states), n=len(states))
    for x in states:
        best: list[tuple] = []
        for d in detectors:
            p = path_to(reach(sg, [d], reverse=True), ("x", x))
            if p and (not best or len(p) < len(best)):
                best = p
        if best:
            out.connected_to[x] = best[0][1]
            out.paths[x] = _bonds_on(best[::-1])
        else:
            out.unconnected.append(x)
    bgd = assign_causality(graph, BGD, dualize={"De", "Df"}, check=False)
    out.bgd_integral = [x for x in states if bgd.storage.get(x) == "integral"]
    out.rank = len(states) - len(out.bgd_integral)
    out.ok = not out.unconnected and not out.bgd_integral
    return out
