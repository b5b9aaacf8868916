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

from .causality import BGD, Causality, assign_causality
from .errors import BondError
from .graph import Graph
from .signal_flow import path_to, reach, signal_graph


@dataclass
class StructuralProperty:
    """Controllability (or observability) verdict.

    ok: both conditions hold. states: storage elements in integral causality (the BGI
    states). unconnected: those without a causal path to a source (detector). bgd_integral:
    storage left in integral causality in the BGD with dualized sources (detectors).
    rank: structural rank of [A B] (of [A; C]); n: number of states. connected_to: state ->
    the sources (detectors) causally connected to it, nearest first; paths: state -> the
    bonds of the shortest such causal path (source first / detector last).
    """

    kind: str
    ok: bool
    states: list[str]
    connected_to: dict[str, list[str]] = field(default_factory=dict)
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


def _connect(graph: Graph, bgi: Causality, ends: list[tuple], reverse: bool,
             out: StructuralProperty) -> None:
    sg = signal_graph(bgi)
    trees = [(e, reach(sg, [e], reverse=reverse)) for e in ends]
    for x in out.states:
        found = []
        for e, tree in trees:
            p = path_to(tree, ("x", x))
            if p:
                found.append((len(p), e[1], p))
        found.sort(key=lambda t: t[0])
        if found:
            out.connected_to[x] = [name for _, name, _ in found]
            best = found[0][2]
            out.paths[x] = _bonds_on(best[::-1] if reverse else best)
        else:
            out.unconnected.append(x)


def _names(graph: Graph, kinds: tuple[str, ...], only: list[str] | None, what: str
           ) -> list[str]:
    names = [n.name for n in graph.of_kind(*kinds) if not n.zero]
    if only is None:
        return names
    missing = [x for x in only if x not in names]
    if missing:
        raise BondError(f"{', '.join(missing)}: not {what} of {graph.name} "
                        f"(it has: {', '.join(names) or 'none'})", missing[0])
    return list(only)


def controllability(graph: Graph, bgi: Causality | None = None,
                    inputs: list[str] | None = None) -> StructuralProperty:
    """Structural state controllability (Theorem 1 plus the BGD rank condition).
    ``inputs``: the sources that count as control inputs (default: every source)."""
    bgi = bgi or assign_causality(graph)
    sources = _names(graph, ("Se", "Sf"), inputs, "a source")
    out = StructuralProperty("controllability", True, list(bgi.integral),
                             n=len(bgi.integral))
    _connect(graph, bgi, [("u", s) for s in sources], False, out)
    fixed = [n.name for n in graph.of_kind("Se", "Sf") if n.name not in sources]
    bgd = assign_causality(graph, BGD, dualize={"Se", "Sf"}, check=False, keep=fixed)
    out.bgd_integral = [x for x in out.states if bgd.storage.get(x) == "integral"]
    out.rank = out.n - len(out.bgd_integral)
    out.ok = not out.unconnected and not out.bgd_integral
    return out


def observability(graph: Graph, bgi: Causality | None = None,
                  outputs: list[str] | None = None) -> StructuralProperty:
    """Structural state observability (Theorem 2 plus the BGD rank condition).
    ``outputs``: the detectors that count as measurements (default: every detector)."""
    bgi = bgi or assign_causality(graph)
    detectors = _names(graph, ("De", "Df"), outputs, "a detector")
    out = StructuralProperty("observability", True, list(bgi.integral), n=len(bgi.integral))
    _connect(graph, bgi, [("y", d) for d in detectors], True, out)
    fixed = [n.name for n in graph.of_kind("De", "Df") if n.name not in detectors]
    bgd = assign_causality(graph, BGD, dualize={"De", "Df"}, check=False, keep=fixed)
    out.bgd_integral = [x for x in out.states if bgd.storage.get(x) == "integral"]
    out.rank = out.n - len(out.bgd_integral)
    out.ok = not out.unconnected and not out.bgd_integral
    return out
