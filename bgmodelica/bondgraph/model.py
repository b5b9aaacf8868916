"""The :class:`BondGraph` component: elements, directed bonds, exposed ports (word bond
graphs), and its pure-graph view for analysis and drawing.

    class RC(BondGraph):
        def __init__(self, **kw):
            super().__init__(**kw)
            self.U = Se(E=1.0)
            self.j = J0()
            self.res = R(R=10.0)
            self.cap = C(C=1e-3)
            self.bond(self.U, self.j)          # half-arrow U -> j: power from U into j
            self.bond(self.j, self.res)
            self.bond(self.j, self.cap)

``bond(a, b)`` takes elements (a one-port's single port, a junction's new port, a two-port's
first free port), ports, or dotted names ("j1", "gear.p2", "motor.shaft"). A bond is an
acausal connection of two :class:`PowerPort` s (efforts equal, port flows sum to zero), the
half-arrow pointing at ``b``: ``b``'s port sees the bond flow as flow in (+1), ``a``'s as flow
out (-1), and the elements' laws use these orientations.

A bond graph nests inside another as a word-bond-graph subsystem: ``expose("shaft", target)``
gives it an outer port standing for a port of one of its elements (a new junction port for a
junction); bonds to the outer port then reach that element, with their direction. A port left
unbonded has zero flow (in the analysis: a zero flow source).

Before flattening, the outermost bond graph assigns causality (SCAP): storage elements in
integral causality get ``StateSelect.PREFER`` on their energy variable, those in derivative
causality ``AVOID`` (unless set by the user); a causal conflict raises
:class:`~bgmodelica.bondgraph.errors.CausalConflictError`.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from ..core.component import Component, Element
from ..core.variables import StateSelect
from .causality import assign_causality
from .elements import BGElement, Dq, PowerPort, _Junction, element_path
from .errors import BondError, CausalConflictError
from .graph import Graph

__all__ = ["BondGraph", "graph_of"]


class BondGraph(Component):
    """A component made of bond-graph elements and bonds; nests as a subsystem.

    ``causal_states`` (class attribute) sets how the causality of the outermost bond graph
    guides state selection: ``"auto"`` (default) gives the energy variables of storage
    elements in integral causality (and the outputs of displacement detectors)
    ``StateSelect.ALWAYS`` when the graph is closed (no adapter, no open port) and ``PREFER``
    otherwise; ``"always"``, ``"prefer"`` force one of these; ``"off"`` leaves them alone.
    Storage elements in derivative causality get ``AVOID``. A ``state_select`` given by the
    user is never overridden.
    """

    causal_states: str = "auto"

    def __init__(self, name: str | None = None, *, pos: tuple[float, float] | None = None,
                 **modifiers: Any) -> None:
        object.__setattr__(self, "_bonds", [])
        object.__setattr__(self, "_exposed", {})
        object.__setattr__(self, "_bg_owner", None)
        object.__setattr__(self, "_pos", pos)
        super().__init__(name, **modifiers)

    # -- building --------------------------------------------------------------------------
    def add(self, name: str, element: Element, at: tuple[float, float] | None = None
            ) -> Element:
        """Add an element (or a nested bond graph) under ``name``; ``at`` is a drawing
        position hint (x right, y up, in bond lengths)."""
        out = super().add(name, element)
        if isinstance(element, (BGElement, BondGraph)):
            object.__setattr__(element, "_bg_owner", self)
            if at is not None:
                object.__setattr__(element, "_pos", tuple(at))
        return out

    def _find(self, ref: str) -> Any:
        obj: Any = self
        parts = ref.split(".")
        for k, part in enumerate(parts):
            children = getattr(obj, "_children", {})
            if part not in children:
                where = ".".join(parts[:k]) or (self.name or type(self).__name__)
                known = ", ".join(children) or "none"
                kind = "port or element" if k else "element"
                raise BondError(f"bond in {self.name or type(self).__name__}: {where} has no "
                                f"{kind} {part!r} (it has: {known})",
                                ".".join(parts[:k + 1]))
            obj = children[part]
        return obj

    def _port(self, x: Any, role: str) -> PowerPort:
        if isinstance(x, str):
            x = self._find(x)
        if isinstance(x, PowerPort):
            return x
        if isinstance(x, _Junction):
            self._check_member(x)
            return x.new_port()
        if isinstance(x, BGElement):
            self._check_member(x)
            port = x.free_port()
            if port is None:
                used = ", ".join(p.name or "?" for p in x.power_ports())
                raise BondError(f"{x.kind} {element_path(x)}: every port ({used}) is already "
                                "bonded", element_path(x))
            return port
        if isinstance(x, BondGraph):
            free = [p for p in x._exposed.values() if not p.bonded]
            if len(free) != 1:
                raise BondError(f"subsystem {element_path(x)}: name the port to bond "
                                f"(exposed ports: {', '.join(x._exposed) or 'none'})",
                                element_path(x))
            return free[0]
        raise BondError(f"bond {role}: {x!r} is not an element, a port or a name")

    def _check_member(self, elem: Any) -> None:
        o = elem
        while o is not None:
            if o is self:
                return
            o = getattr(o, "_bg_owner", None)
        raise BondError(f"{getattr(elem, 'kind', type(elem).__name__)} "
                        f"{elem.name or type(elem).__name__} is not part of bond graph "
                        f"{self.name or type(self).__name__}: add it first",
                        elem.name)

    def bond(self, a: Any, b: Any) -> tuple[PowerPort, PowerPort]:
        """Bond ``a -> b`` (power positive from ``a`` to ``b``); returns the two ports."""
        pa, pb = self._port(a, "tail"), self._port(b, "head")
        if pa is pb:
            raise BondError(f"bond from port {pa.name} to itself", pa.name)
        for p in (pa, pb):
            if p._peer is not None:
                owner = p._owner if p._owner is not None else p
                raise BondError(f"port {p.name} of {element_path(owner)} is already bonded "
                                f"to {p._peer.name} of {element_path(p._peer._owner)}",
                                element_path(owner))
            if p._inner is None and p._outer is not None and p._owner is not None:
                raise BondError(f"port {p.name} of {element_path(p._owner)} is exposed by "
                                "its subsystem; bond to the subsystem's port instead",
                                element_path(p._owner))
        object.__setattr__(pa, "_sign", -1)
        object.__setattr__(pb, "_sign", 1)
        object.__setattr__(pa, "_peer", pb)
        object.__setattr__(pb, "_peer", pa)
        self._bonds.append((pa, pb))
        self.connect(pa, pb)
        return pa, pb

    def expose(self, name: str, target: Any, direction: str = "in") -> PowerPort:
        """Give this subsystem a port ``name`` standing for ``target``'s port (a junction
        gets a new port). ``direction`` ("in"/"out") is the default half-arrow when the port
        is left unbonded; a bond to the port sets it."""
        inner = self._port(target, "exposed")
        if inner._peer is not None or inner._outer is not None:
            raise BondError(f"{name}: port {inner.name} is already bonded or exposed",
                            inner.name)
        outer = PowerPort()
        self.add(name, outer)
        object.__setattr__(outer, "_inner", inner)
        object.__setattr__(outer, "_owner", self)
        object.__setattr__(outer, "_default", 1 if direction == "in" else -1)
        object.__setattr__(inner, "_outer", outer)
        self._exposed[name] = outer
        self.connect(outer, inner)
        return outer

    # -- causality drives state selection ------------------------------------------------
    def equations(self):
        if self._bg_owner is None:
            self._apply_causality()
        return ()

    def _apply_causality(self) -> None:
        graph = graph_of(self)
        causal = assign_causality(graph)
        if causal.conflicts:
            c = causal.conflicts[0]
            raise CausalConflictError(
                "causal conflict in " + (self.name or type(self).__name__) + ": "
                + "; ".join(f"{x.element}: {x.message}" for x in causal.conflicts),
                c.element, causal.conflicts)
        mode = self.causal_states
        if mode == "off":
            return
        closed = not any(n.kind == "X" or n.zero for n in graph.nodes.values())
        strong = StateSelect.ALWAYS if (mode == "always" or (mode == "auto" and closed)) \
            else StateSelect.PREFER
        elements = _elements_by_path(self)

        def hint(sym, pick):
            if getattr(sym.decl, "state_select", StateSelect.DEFAULT) == StateSelect.DEFAULT:
                sym.decl = replace(sym.decl, state_select=pick)

        for name, how in causal.storage.items():
            elem = elements.get(name)
            if elem is not None:
                hint(elem._symbols["p" if elem.kind == "I" else "q"],
                     strong if how == "integral" else StateSelect.AVOID)
        for elem in elements.values():
            if isinstance(elem, Dq):
                hint(elem._symbols["y"], strong)


def _elements_by_path(root: Component) -> dict[str, BGElement]:
    out: dict[str, BGElement] = {}
    stack: list[tuple[Element, str]] = [(root, "")]
    while stack:
        elem, path = stack.pop()
        if isinstance(elem, BGElement):
            out[path] = elem
        for name, child in elem._children.items():
            if isinstance(child, Component):
                stack.append((child, f"{path}.{name}" if path else name))
    return out


def graph_of(model: Component, name: str | None = None) -> Graph:
    """The pure :class:`Graph` of every bond-graph element and bond in ``model`` (any
    component; nested bond graphs are flattened, element names are dotted paths)."""
    graph = Graph(name or model.name or type(model).__name__)
    where: dict[int, tuple[str, str]] = {}          # id(port) -> (element path, port name)
    bond_lists: list[list[tuple[PowerPort, PowerPort]]] = []
    open_ports: list[tuple[PowerPort, str]] = []

    def walk(elem: Element, path: str, offset: tuple[float, float]) -> None:
        pos = getattr(elem, "_pos", None)
        here = offset
        if isinstance(elem, BondGraph) and pos is not None and elem is not model:
            here = (offset[0] + pos[0], offset[1] + pos[1])
        if isinstance(elem, BGElement):
            ports = elem.power_ports()
            graph.add(path, elem.kind, label=elem.label(), modulus=elem.modulus_text(),
                      priority=elem._priority, ports=[p.name for p in ports],
                      mode=elem.mode_text(),
                      pos=(offset[0] + pos[0], offset[1] + pos[1]) if pos is not None
                      else None)
            for p in ports:
                where[id(p)] = (path, p.name)
            return
        if isinstance(elem, BondGraph):
            bond_lists.append(elem._bonds)
            for pname, port in elem._exposed.items():
                if port._peer is None and port._outer is None:
                    open_ports.append((port, f"{path}.{pname}" if path else pname))
        for cname, child in elem._children.items():
            if isinstance(child, Component):
                walk(child, f"{path}.{cname}" if path else cname, here)

    walk(model, "", (0.0, 0.0))

    def end(port: PowerPort) -> tuple[str, str]:
        p = port
        while p._inner is not None:
            p = p._inner
        if id(p) not in where:
            raise BondError(f"port {port.name} is not part of {graph.name}", port.name)
        return where[id(p)]

    for bonds in bond_lists:
        for pa, pb in bonds:
            (ta, tpa), (hb, hpb) = end(pa), end(pb)
            graph.bond(ta, hb, tpa, hpb)
    for port, path in open_ports:
        node, pname = end(port)
        virtual = graph.add(path, "Sf", label="0", zero=True)
        if port._default > 0:
            graph.bond(virtual.name, node, "", pname)
        else:
            graph.bond(node, virtual.name, pname, "")
    return graph
