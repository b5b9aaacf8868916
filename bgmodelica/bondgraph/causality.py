"""Causality assignment: the Sequential Causality Assignment Procedure (SCAP) of Karnopp,
Margolis and Rosenberg, on a pure :class:`~bgmodelica.bondgraph.graph.Graph`.

Causality of a bond is recorded as the end that *receives the effort* (where the causal stroke
is drawn). Constraints:

* Se gives effort (stroke away from it), Sf gives flow (stroke at it); De receives effort
  (an ideal effort detector draws no flow), Df receives flow (imposes no effort).
* C: integral causality = flow in, effort out (stroke away); derivative = stroke at C.
  I: integral causality = effort in, flow out (stroke at I); derivative = stroke away.
* R, X (adapters to other domains): free.
* Sw (switch of a hybrid bond graph): free, like an R, and *fixed across modes*. The element
  is written in the resistive form e = s*(Ron if on else 1), f = s*(1 if on else Goff)
  (Modelica's ideal switch), whose structure does not depend on the mode, so one causality
  serves both modes and no reassignment happens at a switching event. (The ideal modes, an
  Se of value 0 when on and an Sf of value 0 when off, are checked separately by
  :func:`ideal_modes`.)
* 0-junction: exactly one bond imposes the (common) effort on the junction.
  1-junction: exactly one bond imposes the (common) flow on the junction.
* TF/MTF: effort passes through (exactly one stroke at the element);
  GY/MGY: both strokes at the element or both away.

SCAP: (1) fixed-causality elements (sources, detectors), propagate; (2) storage elements one by
one (higher ``priority`` first, then declaration order) in preferred causality (integral for
the BGI, derivative for the BGD), propagate; an element whose bond was already fixed by an
earlier propagation is *forced* into that causality; (3) free elements (R, X, Sw) in
resistance causality, propagate; (4) any bond still open (a loop of the junction structure)
arbitrarily.
Each choice is tentative: if its propagation runs into a contradiction it is undone and the
alternative tried; if both fail, a :class:`Conflict` is recorded.

After assignment the causal graph is turned into a signal-flow graph (:mod:`.signal_flow`)
whose strongly connected algebraic parts are the zero-order causal paths (algebraic loops).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

from .graph import (
    DETECTORS,
    JUNCTIONS,
    SOURCES,
    STORAGE,
    SWITCHES,
    TWO_PORTS,
    Bond,
    Graph,
    Node,
)
from .signal_flow import zero_order_paths

BGI = "BGI"
BGD = "BGD"


@dataclass
class Conflict:
    """A causal contradiction: ``element`` could not get the causality it requires because of
    ``at`` (a junction or two-port whose constraint broke)."""

    element: str
    at: str
    message: str

    def to_dict(self) -> dict:
        return {"element": self.element, "at": self.at, "message": self.message}


@dataclass
class Causality:
    """Result of SCAP on a graph.

    effort_to: bond number -> the node that receives the effort (stroke end).
    storage: storage element -> "integral" / "derivative".
    forced: storage elements that could not get the view's preferred causality (in the BGI:
    those forced into derivative causality by sources or other storage elements).
    resistors: R / X element -> "resistance" (flow in) / "conductance" (effort in).
    switches: Sw element -> "resistance" / "conductance": the causality of its resistive form,
    the same in every mode (not listed in ``arbitrary``).
    arbitrary: elements or bonds ("bond 7") that needed an arbitrary choice.
    conflicts: unresolvable contradictions. loops: zero-order causal paths, each a dict with
    the bonds and elements on it.
    """

    graph: Graph
    view: str
    effort_to: dict[int, str]
    storage: dict[str, str] = field(default_factory=dict)
    forced: list[str] = field(default_factory=list)
    resistors: dict[str, str] = field(default_factory=dict)
    switches: dict[str, str] = field(default_factory=dict)
    arbitrary: list[str] = field(default_factory=list)
    conflicts: list[Conflict] = field(default_factory=list)
    loops: list[dict] = field(default_factory=list)

    @property
    def integral(self) -> list[str]:
        return [n for n, c in self.storage.items() if c == "integral"]

    @property
    def derivative(self) -> list[str]:
        return [n for n, c in self.storage.items() if c == "derivative"]

    def receives_effort(self, bond: Bond, node: str) -> bool:
        return self.effort_to.get(bond.number) == node

    def to_dict(self) -> dict:
        return {
            "view": self.view,
            "bonds": [{"bond": b.number, "from": b.tail, "to": b.head,
                       "stroke_at": self.effort_to.get(b.number)} for b in self.graph.bonds],
            "integral": self.integral, "derivative": self.derivative, "forced": self.forced,
            "resistors": dict(self.resistors), "switches": dict(self.switches),
            "arbitrary": list(self.arbitrary),
            "conflicts": [c.to_dict() for c in self.conflicts],
            "zero_order_causal_paths": self.loops,
        }


class _Contradiction(Exception):
    def __init__(self, at: str, message: str) -> None:
        super().__init__(message)
        self.at = at
        self.message = message


def _wanted(node: Node, choice: str) -> str:
    """Which end receives the effort for a one-port ``node`` in ``choice`` causality:
    "self" or "other"."""
    k = node.kind
    if k == "Se" or (k == "Df"):
        return "other"
    if k == "Sf" or k == "De":
        return "self"
    if k == "C":
        return "other" if choice == "integral" else "self"
    if k == "I":
        return "self" if choice == "integral" else "other"
    # R, X, Sw and dualized sources/detectors: "resistance" = flow in, effort out
    return "other" if choice in ("resistance", "effort-out") else "self"


class _Assigner:
    def __init__(self, graph: Graph) -> None:
        self.g = graph
        self.inc = graph.incidence()
        self.eto: dict[int, str] = {}

    def set(self, bond: Bond, to: str, queue: deque) -> None:
        cur = self.eto.get(bond.number)
        if cur is not None:
            if cur != to:
                raise _Contradiction(to, f"bond {bond.number} ({bond.tail} -> {bond.head}) "
                                     f"would need its effort imposed on both ends")
            return
        self.eto[bond.number] = to
        queue.append(bond.tail)
        queue.append(bond.head)

    def one_port(self, node: Node, where: str) -> None:
        """Assign ``node``'s single bond so that ``where`` ("self"/"other") gets the effort."""
        bond = self.inc[node.name][0]
        to = node.name if where == "self" else bond.other(node.name)
        queue: deque = deque()
        self.set(bond, to, queue)
        self.propagate(queue)

    def propagate(self, queue: deque) -> None:
        while queue:
            name = queue.popleft()
            for bond, to in self.forced(self.g.nodes[name]):
                self.set(bond, to, queue)

    def forced(self, node: Node) -> list[tuple[Bond, str]]:
        bonds = self.inc[node.name]
        name = node.name
        if node.kind in JUNCTIONS:
            # "strong" bond: imposes the junction's common variable on it.
            # 0: effort into the junction; 1: effort out of the junction (flow in).
            if node.kind == "0":
                def is_strong(b):
                    return self.eto.get(b.number) == name
            else:
                def is_strong(b):
                    return b.number in self.eto and self.eto[b.number] != name
            strong = [b for b in bonds if is_strong(b)]
            free = [b for b in bonds if b.number not in self.eto]
            what = "effort" if node.kind == "0" else "flow"
            if len(strong) > 1:
                raise _Contradiction(name, f"{node.kind}-junction {name}: bonds "
                                     f"{', '.join(str(b.number) for b in strong)} all impose "
                                     f"its common {what}")
            weak_to = (lambda b: b.other(name)) if node.kind == "0" else (lambda b: name)
            strong_to = (lambda b: name) if node.kind == "0" else (lambda b: b.other(name))
            if strong:
                return [(b, weak_to(b)) for b in free]
            if len(free) == 1:
                return [(free[0], strong_to(free[0]))]
            if not free:
                raise _Contradiction(name, f"{node.kind}-junction {name}: no bond imposes its "
                                     f"common {what}")
            return []
        if node.kind in TWO_PORTS and len(bonds) == 2:
            a, b = bonds
            out = []
            for x, y in ((a, b), (b, a)):
                if x.number in self.eto:
                    x_in = self.eto[x.number] == name
                    y_in = (not x_in) if node.kind in ("TF", "MTF") else x_in
                    want = name if y_in else y.other(name)
                    if y.number in self.eto:
                        if self.eto[y.number] != want:
                            rule = ("an effort in and an effort out" if node.kind in
                                    ("TF", "MTF") else "two efforts in or two flows in")
                            raise _Contradiction(name, f"{node.title} {name} needs {rule}")
                    else:
                        out.append((y, want))
            return out
        return []

    def attempt(self, action) -> _Contradiction | None:
        saved = dict(self.eto)
        try:
            action()
        except _Contradiction as err:
            self.eto = saved
            return err
        return None


def assign_causality(graph: Graph, view: str = BGI, dualize: frozenset[str] | set[str] = (),
                     check: bool = True, keep: list[str] | None = None) -> Causality:
    """Run SCAP on ``graph``.

    view: ``"BGI"`` (storage prefers integral causality) or ``"BGD"`` (derivative).
    dualize: element kinds ("Se", "Sf", "De", "Df") whose causality is left free, as for the
    rank conditions of structural controllability (sources) and observability (detectors).
    check: validate the graph first (junction bond counts, two-port directions).
    keep: names of elements whose causality stays fixed even if their kind is dualized.
    """
    if check:
        graph.validate()
    a = _Assigner(graph)
    res = Causality(graph, view, a.eto)
    order = list(graph.nodes.values())
    inc = a.inc
    kept = set(keep or ())

    def dual(n: Node) -> bool:
        return n.kind in dualize and n.name not in kept

    fixed = [n for n in order if (n.kind in SOURCES | DETECTORS) and not dual(n)]
    free = [n for n in order if n.kind in ("R", "X") or n.kind in SWITCHES or dual(n)]
    storage = sorted((n for n in order if n.kind in STORAGE),
                     key=lambda n: -n.priority)          # stable: declaration order kept
    preferred = "integral" if view == BGI else "derivative"
    other = "derivative" if preferred == "integral" else "integral"

    def assigned(n: Node) -> bool:
        return bool(inc[n.name]) and inc[n.name][0].number in a.eto

    # (1) fixed causality
    for n in fixed:
        if not inc[n.name]:
            continue
        bond = inc[n.name][0]
        if bond.number in a.eto:
            other = graph.nodes[bond.other(n.name)]
            want = n.name if _wanted(n, "") == "self" else other.name
            if a.eto[bond.number] != want:
                what = "effort" if n.kind in ("Se", "Df") else "flow"
                res.conflicts.append(Conflict(n.name, other.name, (
                    f"{n.title} {n.name} cannot impose its {what}: {other.title} "
                    f"{other.name} already has its {what} imposed through another bond")))
            continue
        err = a.attempt(lambda n=n: a.one_port(n, _wanted(n, "")))
        if err is not None:
            res.conflicts.append(Conflict(n.name, err.at, err.message))
    # (2) storage
    for n in storage:
        if not inc[n.name]:
            continue
        if assigned(n):
            continue
        err = a.attempt(lambda n=n: a.one_port(n, _wanted(n, preferred)))
        if err is not None:
            err2 = a.attempt(lambda n=n: a.one_port(n, _wanted(n, other)))
            if err2 is not None:
                res.conflicts.append(Conflict(n.name, err2.at, err2.message))
    # (3) free elements
    for n in free:
        if not inc[n.name] or assigned(n):
            continue
        if n.kind not in SWITCHES:
            res.arbitrary.append(n.name)
        err = a.attempt(lambda n=n: a.one_port(n, _wanted(n, "resistance")))
        if err is not None:
            err2 = a.attempt(lambda n=n: a.one_port(n, _wanted(n, "conductance")))
            if err2 is not None:
                res.conflicts.append(Conflict(n.name, err2.at, err2.message))
    # (4) open bonds of the junction structure
    for b in graph.bonds:
        if b.number in a.eto:
            continue
        res.arbitrary.append(f"bond {b.number}")
        for to in (b.head, b.tail):
            def act(b=b, to=to):
                q: deque = deque()
                a.set(b, to, q)
                a.propagate(q)
            if a.attempt(act) is None:
                break
        else:
            res.conflicts.append(Conflict(b.head, b.head, f"bond {b.number} cannot be given "
                                          "a consistent causality"))
    res.effort_to = a.eto
    # read back the causality of one-ports
    for n in order:
        bonds = inc[n.name]
        if not bonds or bonds[0].number not in a.eto:
            continue
        into = a.eto[bonds[0].number] == n.name
        if n.kind in STORAGE:
            integral = into if n.kind == "I" else not into
            res.storage[n.name] = "integral" if integral else "derivative"
        elif n.kind in SWITCHES:
            res.switches[n.name] = "conductance" if into else "resistance"
        elif n.kind in ("R", "X") or dual(n):
            res.resistors[n.name] = "conductance" if into else "resistance"
        elif n.kind in SOURCES | DETECTORS:
            want = _wanted(n, "")
            if (want == "self") != into and not any(c.element == n.name
                                                    for c in res.conflicts):
                res.conflicts.append(Conflict(n.name, bonds[0].other(n.name),
                                              f"{n.title} {n.name} cannot impose its "
                                              "causality"))
    # forced: storage elements that could not get the preferred causality
    res.forced = [n.name for n in storage if res.storage.get(n.name, preferred) != preferred]
    res.loops = zero_order_paths(res)
    return res


# -- switches: the ideal modes -------------------------------------------------------------
@dataclass
class IdealMode:
    """Causality of the graph with one switch in an *ideal* mode: ``on`` as a zero effort
    source (Se of value 0), ``off`` as a zero flow source (Sf of value 0), the other switches
    staying in their resistive form.

    forced: storage elements in integral causality with the resistive form that the ideal
    mode puts in derivative causality: with the resistive form they keep their state but get
    a fast time constant set by ``Ron`` / ``Goff`` (an inductance in series with an open
    switch, a capacitance shorted by a closed one). conflicts: causal conflicts of the ideal
    mode (e.g. a closed switch in parallel with an effort source): the resistive form makes
    them well-posed but stiff or with large currents.
    """

    switch: str
    mode: str
    states: int
    forced: list[str] = field(default_factory=list)
    conflicts: list[Conflict] = field(default_factory=list)

    @property
    def consistent(self) -> bool:
        return not self.forced and not self.conflicts

    def to_dict(self) -> dict:
        return {"switch": self.switch, "mode": self.mode, "states": self.states,
                "forced_derivative": list(self.forced),
                "conflicts": [c.to_dict() for c in self.conflicts]}


def ideal_modes(graph: Graph, bgi: Causality | None = None) -> list[IdealMode]:
    """For each switch (``Sw``) of ``graph`` and each of its modes, SCAP (BGI) with the switch
    replaced by its ideal element (on: Se of value 0, off: Sf of value 0). Compared with the
    resistive-form causality ``bgi``: which storage elements the ideal mode would force into
    derivative causality (a change of causality and of the number of states, which the
    resistive form avoids)."""
    from dataclasses import replace

    switches = [n for n in graph.nodes.values() if n.kind in SWITCHES]
    if not switches:
        return []
    bgi = bgi or assign_causality(graph, BGI, check=False)
    out = []
    for sw in switches:
        for mode, kind in (("on", "Se"), ("off", "Sf")):
            g = Graph(graph.name, {k: (replace(v, kind=kind, zero=True, label="0")
                                       if k == sw.name else v)
                                   for k, v in graph.nodes.items()}, list(graph.bonds))
            c = assign_causality(g, BGI, check=False)
            forced = [x for x in bgi.integral if c.storage.get(x) != "integral"]
            out.append(IdealMode(sw.name, mode, len(c.integral), forced, list(c.conflicts)))
    return out
