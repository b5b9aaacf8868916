"""``analyze(model) -> BondGraphReport``: causality (BGI, BGD), conflicts, zero-order causal
paths, structural controllability and observability, causal equations; as text or a dict.

Switched bonds (``Sw``, hybrid bond graphs) are analysed in their mode-independent resistive
form (e = s*(Ron if on else 1), f = s*(1 if on else Goff)): one causality for every mode, and
the structural properties are those of that structure. The ideal modes (Se:0 when on, Sf:0
when off) are checked for the causality changes the resistive form avoids."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from .causality import BGD, BGI, Causality, IdealMode, assign_causality, ideal_modes
from .equations import CausalEquations, causal_equations
from .graph import DETECTORS, SOURCES, SWITCHES, Graph
from .structural import StructuralProperty, controllability, observability

__all__ = ["BondGraphReport", "analyze", "as_graph"]


def as_graph(model: Any) -> Graph:
    """A :class:`Graph` from a Graph, a BondGraph or any component containing bond graphs."""
    if isinstance(model, Graph):
        return model
    from .model import graph_of

    return graph_of(model)


@dataclass
class BondGraphReport:
    """Structural analysis of a bond graph.

    bgi: SCAP with preferred integral causality; bgd: the paper's BGD (all storage elements
    preferably in derivative causality, sources and detectors fixed). controllability /
    observability: Theorems 1 and 2 plus the BGD rank conditions. equations: causal equations
    read from the BGI. modes: for each switch and mode, the causality of the ideal mode (see
    :func:`~bgmodelica.bondgraph.causality.ideal_modes`).
    """

    graph: Graph
    bgi: Causality
    bgd: Causality
    controllability: StructuralProperty
    observability: StructuralProperty
    equations: CausalEquations
    modes: list[IdealMode] = field(default_factory=list)

    # -- convenience -------------------------------------------------------------------------
    @property
    def conflicts(self) -> list:
        return self.bgi.conflicts

    @property
    def derivative(self) -> list[str]:
        return self.bgi.derivative

    @property
    def integral(self) -> list[str]:
        return self.bgi.integral

    def _t(self, name: str) -> str:
        node = self.graph.nodes[name]
        return f"{name} ({node.title})"

    @property
    def switches(self) -> list[str]:
        return [n.name for n in self.graph.nodes.values() if n.kind in SWITCHES]

    def switch_lines(self) -> list[str]:
        """How the switched bonds are handled (for the causality section of :meth:`to_text`)."""
        if not self.switches:
            return []
        c = self.bgi
        inc = self.graph.incidence()
        how = {"resistance": "resistance causality (flow in, effort out)",
               "conductance": "conductance causality (effort in, flow out)"}
        lines = ["  switched bonds (hybrid bond graph, Mosterman & Biswas 1998):"]
        for name in self.switches:
            node = self.graph.nodes[name]
            bonds = ", ".join(str(b.number) for b in inc[name]) or "-"
            caus = how.get(c.switches.get(name, ""), "no causality (unbonded)")
            lines.append(f"    {self._t(name)}: switched bond {bonds}, causality fixed "
                         f"(resistive form, Ron/Goff): {caus} in both modes; mode from "
                         f"{node.mode or '?'}")
            for m in self.modes:
                if m.switch != name:
                    continue
                ideal = "Se:0, e = 0" if m.mode == "on" else "Sf:0, f = 0"
                if m.consistent:
                    verdict = "same storage causality"
                else:
                    parts = []
                    if m.forced:
                        parts.append("would put " + ", ".join(self._t(x) for x in m.forced)
                                     + " in derivative causality (resistive form: a fast "
                                     "mode, time constant set by Ron/Goff)")
                    if m.conflicts:
                        parts.append("causal conflict: " + "; ".join(
                            x.message for x in m.conflicts))
                    verdict = "; ".join(parts)
                lines.append(f"      ideal {m.mode} ({ideal}): {verdict}")
        lines.append("  structural controllability/observability computed for the "
                     "mode-independent structure (switches in resistive form)")
        return lines

    def to_text(self) -> str:
        g, c = self.graph, self.bgi
        kinds: dict[str, int] = {}
        for n in g.nodes.values():
            kinds[n.kind] = kinds.get(n.kind, 0) + 1
        counts = ", ".join(f"{v} {k}" for k, v in sorted(kinds.items()))
        lines = [f"Bond graph {g.name}: {len(g.nodes)} elements ({counts}), {len(g.bonds)} bonds"]
        srcs = [self._t(n.name) for n in g.nodes.values() if n.kind in SOURCES and not n.zero]
        dets = [self._t(n.name) for n in g.nodes.values() if n.kind in DETECTORS]
        lines.append(f"  sources:   {', '.join(srcs) or 'none'}")
        lines.append(f"  detectors: {', '.join(dets) or 'none'}")
        lines.append("Causality (SCAP, BGI: preferred integral causality)")
        lines.append("  integral causality:   "
                     + (", ".join(self._t(x) for x in c.integral) or "none"))
        lines.append("  derivative causality: "
                     + (", ".join(self._t(x) for x in c.derivative) or "none"))
        if c.resistors:
            lines.append("  resistors: " + ", ".join(f"{self._t(k)} {v}"
                                                     for k, v in c.resistors.items()))
        lines += self.switch_lines()
        lines.append("  causal conflicts: " + ("; ".join(
            f"{x.element}: {x.message}" for x in c.conflicts) or "none"))
        if c.loops:
            lines.append("  zero-order causal paths (algebraic loops):")
            for lp in c.loops:
                lines.append(f"    bonds {', '.join(map(str, lp['bonds']))} through "
                             f"{', '.join(lp['elements'])}")
        else:
            lines.append("  zero-order causal paths (algebraic loops): none")
        if c.arbitrary:
            lines.append("  arbitrary choices: " + ", ".join(c.arbitrary))
        lines.append(f"  state variables: {len(c.integral)} (energy variables of the "
                     "integral-causality storage elements)")
        left = self.bgd.integral
        lines.append("BGD (storage preferably in derivative causality): "
                     + (f"left in integral causality: {', '.join(left)}" if left
                        else "every storage element in derivative causality"))
        for prop, who in ((self.controllability, "source"), (self.observability, "detector")):
            theorem = "Theorem 1" if prop.kind == "controllability" else "Theorem 2"
            verdict = "yes" if prop.ok else "NO"
            note = " (mode-independent structure, switches in resistive form)" \
                if self.switches else ""
            lines.append(f"Structural {prop.kind} ({theorem}): {verdict}{note}")
            for x in prop.states:
                if x in prop.connected_to:
                    near = prop.connected_to[x]
                    lines.append(f"  {x}: causal paths to {who}s {', '.join(near)} (nearest: "
                                 f"bonds {', '.join(map(str, prop.paths[x]))})")
                else:
                    lines.append(f"  {x}: NOT causally connected to any {who}")
            mat = "[A B]" if prop.kind == "controllability" else "[A; C]"
            dual = "sources" if prop.kind == "controllability" else "detectors"
            lines.append(f"  BGD rank {mat} = {prop.rank}/{prop.n} ({dual} dualized)"
                         + (f"; left integral: {', '.join(prop.bgd_integral)}"
                            if prop.bgd_integral else ""))
        lines.append("Causal equations")
        lines += ["  " + ln for ln in self.equations.to_text().splitlines()]
        return "\n".join(lines)

    def to_latex(self) -> str:
        return self.equations.to_latex()

    def to_dict(self) -> dict:
        g = self.graph
        return {
            "name": g.name,
            "elements": [{"name": n.name, "kind": n.kind, "label": n.label,
                          "modulus": n.modulus} for n in g.nodes.values()],
            "bonds": [{"number": b.number, "from": b.tail, "to": b.head}
                      for b in g.bonds],
            "bgi": self.bgi.to_dict(), "bgd": self.bgd.to_dict(),
            "controllability": self.controllability.to_dict(),
            "observability": self.observability.to_dict(),
            "equations": self.equations.to_dict(),
            "switches": [{"name": x, "mode": g.nodes[x].mode,
                          "causality": self.bgi.switches.get(x),
                          "fixed_across_modes": True, "form": "resistive (Ron/Goff)"}
                         for x in self.switches],
            "ideal_modes": [m.to_dict() for m in self.modes],
        }


def analyze(model: Any, inputs: list[str] | None = None,
            outputs: list[str] | None = None) -> BondGraphReport:
    """Analyze a bond graph (a :class:`Graph`, a ``BondGraph`` or a component holding bond
    graphs). ``inputs`` / ``outputs`` restrict the sources / detectors that count for
    controllability / observability (dotted element names; default: all). Raises
    :class:`~bgmodelica.bondgraph.errors.JunctionError` /
    :class:`~bgmodelica.bondgraph.errors.BondError` on malformed graphs; causal conflicts are
    reported, not raised."""
    graph = as_graph(model)
    bgi = assign_causality(graph, BGI)
    bgd = assign_causality(graph, BGD, check=False)
    return BondGraphReport(graph, bgi, bgd, controllability(graph, bgi, inputs),
                           observability(graph, bgi, outputs), causal_equations(bgi),
                           ideal_modes(graph, bgi))
