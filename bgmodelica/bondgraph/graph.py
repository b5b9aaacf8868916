"""Pure bond-graph description: nodes (elements, junctions) and directed bonds.

This layer knows nothing of CasADi or of equations: it is what causality assignment,
structural analysis, causal-equation generation and drawing work on. A
:class:`~bgmodelica.bondgraph.model.BondGraph` component produces one with ``graph_of``; a
graph can also be written by hand::

    g = Graph("rc")
    g.add("U", "Se"); g.add("j", "0"); g.add("R", "R"); g.add("C", "C")
    g.bond("U", "j"); g.bond("j", "R"); g.bond("j", "C")

A bond ``tail -> head`` carries power from ``tail`` to ``head`` (the half-arrow points at the
head). Its effort ``e`` is the same at both ends, its flow ``f`` is counted along the
half-arrow.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .errors import BondError, JunctionError

#: Element kinds and their family.
SOURCES = {"Se", "Sf"}
DETECTORS = {"De", "Df"}
STORAGE = {"C", "I"}
RESISTORS = {"R"}
#: switched one-ports of hybrid bond graphs (Mosterman & Biswas): free causality, kept fixed
#: across modes (resistive form e = s*(Ron if on else 1), f = s*(1 if on else Goff))
SWITCHES = {"Sw"}
TWO_PORTS = {"TF", "GY", "MTF", "MGY"}
JUNCTIONS = {"0", "1"}
EXTERNAL = {"X"}          # adapter to another physical domain's connector: free causality
KINDS = SOURCES | DETECTORS | STORAGE | RESISTORS | TWO_PORTS | JUNCTIONS | EXTERNAL | SWITCHES
ONE_PORTS = SOURCES | DETECTORS | STORAGE | RESISTORS | EXTERNAL | SWITCHES


@dataclass
class Node:
    """One element or junction.

    name: unique dotted path. kind: one of :data:`KINDS`. label: text after the colon in a
    drawing ("L" -> ``I:L``) and the symbol of its modulus/parameter in equations.
    modulus: text of a (modulated) modulus, e.g. ``-lc1*sin(q1)``. priority: storage elements
    of higher priority get integral causality first. zero: a source of value 0 (an open port
    of a subsystem), not counted as an input. pos: drawing position hint. mode: for a switch
    (``Sw``), the text of its Boolean mode (``time >= t_s``, ``drive``, ``sw.u > 0.5``).
    """

    name: str
    kind: str
    label: str = ""
    modulus: str = ""
    priority: int = 0
    zero: bool = False
    pos: tuple[float, float] | None = None
    ports: list[str] = field(default_factory=list)
    mode: str = ""

    @property
    def title(self) -> str:
        """``Se:U``, ``1:w1``, ``TF:k2`` as drawn."""
        if self.kind in JUNCTIONS:
            return self.kind if not self.label else f"{self.kind}:{self.label}"
        return f"{self.kind}:{self.label}" if self.label else self.kind

    @property
    def symbol(self) -> str:
        return self.label or self.name.rpartition(".")[2]


@dataclass
class Bond:
    """A power bond ``tail -> head`` (numbered from 1)."""

    number: int
    tail: str
    head: str
    tail_port: str = ""
    head_port: str = ""

    def other(self, node: str) -> str:
        return self.head if node == self.tail else self.tail

    def port_at(self, node: str) -> str:
        return self.head_port if node == self.head else self.tail_port

    def points_into(self, node: str) -> bool:
        return node == self.head


@dataclass
class Graph:
    """Nodes by name and bonds in creation order."""

    name: str = "bondgraph"
    nodes: dict[str, Node] = field(default_factory=dict)
    bonds: list[Bond] = field(default_factory=list)

    def add(self, name: str, kind: str, **kw) -> Node:
        if kind not in KINDS:
            raise BondError(f"{name}: unknown bond-graph element kind {kind!r}; "
                            f"use one of {', '.join(sorted(KINDS))}", name)
        if name in self.nodes:
            raise BondError(f"element {name!r} is defined twice", name)
        node = Node(name, kind, **kw)
        self.nodes[name] = node
        return node

    def bond(self, tail: str, head: str, tail_port: str = "", head_port: str = "") -> Bond:
        for end in (tail, head):
            if end not in self.nodes:
                raise BondError(f"bond {tail} -> {head}: no element named {end!r} "
                                f"(elements: {', '.join(self.nodes) or 'none'})", end)
        b = Bond(len(self.bonds) + 1, tail, head, tail_port, head_port)
        self.bonds.append(b)
        return b

    # -- queries ---------------------------------------------------------------------------
    def bonds_of(self, name: str) -> list[Bond]:
        return [b for b in self.bonds if name in (b.tail, b.head)]

    def incidence(self) -> dict[str, list[Bond]]:
        inc: dict[str, list[Bond]] = {n: [] for n in self.nodes}
        for b in self.bonds:
            inc[b.tail].append(b)
            if b.head != b.tail:
                inc[b.head].append(b)
        return inc

    def of_kind(self, *kinds: str) -> list[Node]:
        return [n for n in self.nodes.values() if n.kind in kinds]

    def validate(self) -> None:
        """Raise :class:`JunctionError` / :class:`BondError` naming the element when a
        junction has fewer than two bonds, a one-port has not exactly one, a two-port has not
        exactly two (one in, one out), or a bond loops on one element."""
        inc = self.incidence()
        for b in self.bonds:
            if b.tail == b.head:
                raise BondError(f"bond {b.number} connects {b.tail} to itself", b.tail)
        for name, node in self.nodes.items():
            n = len(inc[name])
            if node.kind in JUNCTIONS and n < 2:
                raise JunctionError(
                    f"{node.kind}-junction {name} has {n} bond{'s' if n != 1 else ''}; a "
                    "junction needs at least two", name)
            if node.kind in ONE_PORTS and n != 1:
                raise BondError(f"{node.title} element {name} has {n} bonds; a one-port "
                                "element takes exactly one", name)
            if node.kind in TWO_PORTS:
                if n != 2:
                    raise BondError(f"{node.title} element {name} has {n} bonds; it needs "
                                    "exactly two", name)
                ins = sum(b.points_into(name) for b in inc[name])
                if ins != 1:
                    way = "into" if ins == 2 else "out of"
                    raise BondError(
                        f"{node.title} element {name}: both bonds point {way} it; a "
                        "transformer or gyrator passes power through, one bond in and one "
                        "out", name)


def strong_bond(node: Node, bonds: list[Bond], effort_to: dict[int, str]) -> Bond | None:
    """The one bond that sets a causal junction's common variable: the bond bringing the
    effort into a 0-junction, or the flow into a 1-junction (``effort_to``: bond number ->
    the node its effort goes to); None unless exactly one does."""
    if node.kind == "0":
        strong = [b for b in bonds if effort_to[b.number] == node.name]
    else:
        strong = [b for b in bonds if effort_to[b.number] != node.name]
    return strong[0] if len(strong) == 1 else None
