"""Consistency checks of a co-simulation set-up against its FMUs, and the direct-feedthrough
graph that orders the evaluation of outputs at a communication point.

:func:`check_system` raises (all :class:`~bgmodelica.errors.ModelError`):

* :class:`~.errors.DuplicateElementError` -- two elements with one name (or no element);
* :class:`~.errors.InvalidParameterError` -- a parameter binding that is not finite, lies
  outside the ``[min, max]`` the FMU declares, or sets something that cannot be set (a
  constant, a calculated parameter, an output, a local, a non-real variable);
* :class:`~.errors.UnknownConnectorError` -- a connection or parameter binding names an
  element, connector or parameter that does not exist;
* :class:`~.errors.ConnectorMismatchError` -- a connection from something that is not an
  output, to something that is not an input, between different types or incompatible units,
  an input driven twice, or a connector declared in the SSD that contradicts the FMU;
* :class:`~.errors.UnconnectedInputError` -- inputs no connection drives (all listed);
* :class:`~.errors.AlgebraicLoopError` -- a cycle through direct feedthrough: the outputs of
  the FMUs' ``<ModelStructure>`` declare on which inputs they depend *directly*; following
  connections and these dependencies around a loop means the coupled outputs at one instant
  depend on themselves. The message names the connectors along the cycle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..fmi.units import parse_unit
from .errors import (
    AlgebraicLoopError,
    ConnectorMismatchError,
    DuplicateElementError,
    InvalidParameterError,
    SetupError,
    UnconnectedInputError,
    UnknownConnectorError,
)
from .fmu import FmuInfo, FmuVariable
from .ssp import SystemStructure
from .values import to_fmi

#: variable kinds that are not signals (set by name only)
NOT_SIGNALS = ("String", "Binary")


@dataclass
class Plan:
    """What the master needs from a checked system.

    ``inputs[el]``/``outputs[el]``: connector names per element (FMU inputs; FMU outputs used
    by a connection, then the other outputs); ``sources[(el, input)] = (el, output)``;
    ``order``: every connector node ``(el, name, is_output)`` in an order where each output
    comes after the inputs it depends on directly and each input after its source output.
    String and Binary connectors are apart (they are no numeric signals, :mod:`.text`):
    ``text_inputs[el]``, ``text_outputs[el]``, ``text_sources[(el, input)] = (el, output)``.
    """

    inputs: dict[str, list[str]]
    outputs: dict[str, list[str]]
    sources: dict[tuple[str, str], tuple[str, str]]
    order: list[tuple[str, str, bool]]
    feedthrough: dict[str, dict[str, list[str]]]

    def gauss_seidel_sources(self, seq: list[str], src_index: dict[str, list]
                             ) -> tuple[dict[str, list], dict[str, np.ndarray]]:
        """Which inputs of each element read a value already at ``t_{k+1}`` when it steps in
        Gauss-Seidel order ``seq``: the output of an element stepped before it that does not
        depend directly on an input still at ``t_k``. The same at every macro step, so the
        master finds it once. ``src_index[el][j]``: (source element, output position) of
        input ``j`` or None. Returns element -> [(source, its output positions, our input
        positions)] for those inputs, and element -> positions of the other connected
        inputs."""
        fresh = {m: np.zeros(len(self.outputs[m]), dtype=bool) for m in seq}
        groups: dict[str, list] = {}
        stale: dict[str, np.ndarray] = {}
        for n in seq:
            by_src: dict[str, tuple[list[int], list[int]]] = {}
            rest = []
            for j, s in enumerate(src_index[n]):
                if s is None:
                    continue
                if fresh[s[0]][s[1]]:
                    pair = by_src.setdefault(s[0], ([], []))
                    pair[0].append(s[1])
                    pair[1].append(j)
                else:
                    rest.append(j)
            groups[n] = [(src, np.array(a), np.array(b)) for src, (a, b) in by_src.items()]
            stale[n] = np.array(rest, dtype=int)
            # an output is at t_k+1 if every input it depends on directly is
            fresh_in = {self.inputs[n][j]: s is None or bool(fresh[s[0]][s[1]])
                        for j, s in enumerate(src_index[n])}
            fresh[n] = np.array([all(fresh_in.get(u, True)
                                     for u in self.feedthrough[n].get(yn, []))
                                 for yn in self.outputs[n]], dtype=bool)
        return groups, stale
    unconnected: list[str]
    text_inputs: dict[str, list[str]] = field(default_factory=dict)
    text_outputs: dict[str, list[str]] = field(default_factory=dict)
    text_sources: dict[tuple[str, str], tuple[str, str]] = field(default_factory=dict)


def units_compatible(a: str, b: str) -> bool:
    """Equal unit strings, or strings with the same base-unit exponents, factor and offset
    (an empty unit is compatible with anything)."""
    if not a or not b or a == b:
        return True
    da, db = parse_unit(a), parse_unit(b)
    if da.exponents is None or db.exponents is None:
        return False
    return (da.exponents == db.exponents and abs(da.factor - db.factor) <= 1e-12 * abs(da.factor)
            and da.offset == db.offset)


def check_parameter_value(element: str, info: FmuInfo, name: str, value: object,
                          what: str = "parameter binding", unit: str = "") -> Any:
    """Check that ``element.name = value`` can be set before initialization of the FMU
    ``info`` (exists, settable parameter or input, a value of its type, finite, in
    ``[min, max]``, ``unit`` compatible); return the value as a float (numeric and Boolean
    variables), a str (String) or bytes (Binary)."""
    var: FmuVariable | None = info.variables.get(name)
    where = f"{what} {element}.{name}"
    if var is None:
        raise UnknownConnectorError(f"{where}: {info.path.name} has no variable {name!r}")
    if not var.settable:
        raise InvalidParameterError(
            f"{where}: it is a {var.variability} {var.causality} {var.type} of "
            f"{info.path.name}, not a parameter that can be set (only tunable or fixed "
            "parameters and the start values of inputs can)")
    if var.type in ("String", "Binary"):
        try:
            return to_fmi(var.fmi_type or var.type, value, where)
        except (TypeError, ValueError) as err:
            raise InvalidParameterError(str(err)) from None
    try:
        x = float(to_fmi(var.fmi_type or var.type, value, where))
    except (TypeError, ValueError) as err:
        msg = str(err) if var.type != "Real" else f"{where}: {value!r} is not a number"
        raise InvalidParameterError(msg) from None
    if not math.isfinite(x):
        raise InvalidParameterError(f"{where}: the value {x} is not finite")
    if var.out_of_range(x):
        raise InvalidParameterError(f"{where} = {x:g} is outside the range "
                                    f"{var.range_text()} declared in {info.path.name}")
    if unit and not units_compatible(unit, var.unit):
        raise ConnectorMismatchError(f"{where} is given in {unit!r} but {name} is in "
                                     f"{var.unit!r} in {info.path.name}")
    return x


def check_system(system: SystemStructure, infos: dict[str, FmuInfo],
                 allow_unconnected: bool = False) -> Plan:
    """Check ``system`` against the FMUs (``infos``: element -> :class:`FmuInfo`); return the
    :class:`Plan` or raise (see the module docstring)."""
    names = system.element_names
    if not names:
        raise SetupError(f"system {system.name!r} has no elements")
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise DuplicateElementError(f"system {system.name!r}: element name(s) used twice: "
                                    f"{', '.join(sorted(dup))}")
    for comp in system.elements:
        info = infos[comp.name]
        cnames = [c.name for c in comp.connectors]
        cdup = sorted({n for n in cnames if cnames.count(n) > 1})
        if cdup:
            raise DuplicateElementError(f"element {comp.name!r} declares the connector(s) "
                                        f"{', '.join(cdup)} twice")
        for c in comp.connectors:
            var = info.variables.get(c.name)
            if var is None:
                raise UnknownConnectorError(
                    f"connector {comp.name}.{c.name} of the SSD does not exist in "
                    f"{info.path.name}")
            if c.kind in ("input", "output", "parameter") and var.causality != c.kind:
                raise ConnectorMismatchError(
                    f"connector {comp.name}.{c.name} is declared as {c.kind} in the SSD but "
                    f"is a {var.causality} of {info.path.name}")
            if c.type != var.type:
                raise ConnectorMismatchError(
                    f"connector {comp.name}.{c.name} is declared {c.type} in the SSD but is "
                    f"{var.type} in {info.path.name}")
            if not units_compatible(c.unit, var.unit):
                raise ConnectorMismatchError(
                    f"connector {comp.name}.{c.name} has unit {c.unit!r} in the SSD but "
                    f"{var.unit!r} in {info.path.name}")
        for pname, value in comp.parameters.items():
            check_parameter_value(comp.name, info, pname, value,
                                  unit=comp.parameter_units.get(pname, ""))

    sources: dict[tuple[str, str], tuple[str, str]] = {}
    text_sources: dict[tuple[str, str], tuple[str, str]] = {}
    used_outputs: dict[str, list[str]] = {n: [] for n in names}
    for con in system.connections:
        for el in (con.start_element, con.end_element):
            if el not in infos:
                raise UnknownConnectorError(
                    f"connection {con}: there is no element {el!r} (elements: "
                    f"{', '.join(names)})")
        a = infos[con.start_element].variables.get(con.start_connector)
        b = infos[con.end_element].variables.get(con.end_connector)
        for var, full, el in ((a, con.start, con.start_element),
                              (b, con.end, con.end_element)):
            if var is None:
                info = infos[el]
                choices = [v.name for v in info.inputs + info.outputs]
                raise UnknownConnectorError(
                    f"connection {con}: {full} does not exist ({info.path.name} has inputs/"
                    f"outputs {', '.join(choices) or 'none'})")
        assert a is not None and b is not None
        if a.causality != "output":
            raise ConnectorMismatchError(
                f"connection {con}: {con.start} is a {a.causality}, not an output")
        if b.causality != "input":
            hint = (" (a connection cannot drive a parameter: set it with a parameter "
                    "binding)" if "arameter" in b.causality else "")
            raise ConnectorMismatchError(
                f"connection {con}: {con.end} is a {b.causality}, not an input{hint}")
        if a.type != b.type:
            raise ConnectorMismatchError(
                f"connection {con}: type mismatch, {con.start} is {a.type} and {con.end} is "
                f"{b.type}")
        if not units_compatible(a.unit, b.unit):
            raise ConnectorMismatchError(
                f"connection {con}: unit mismatch, {con.start} is in {a.unit!r} and "
                f"{con.end} in {b.unit!r}")
        key = (con.end_element, con.end_connector)
        if key in sources or key in text_sources:
            other = "{}.{}".format(*(sources.get(key) or text_sources[key]))
            raise ConnectorMismatchError(
                f"input {con.end} is driven twice: by {other} and by {con.start}")
        if a.type in NOT_SIGNALS:
            text_sources[key] = (con.start_element, con.start_connector)
            continue
        sources[key] = (con.start_element, con.start_connector)
        if con.start_connector not in used_outputs[con.start_element]:
            used_outputs[con.start_element].append(con.start_connector)

    inputs = {n: [v.name for v in infos[n].inputs if v.type not in NOT_SIGNALS]
              for n in names}
    unconnected = [f"{n}.{u}" for n in names for u in inputs[n] if (n, u) not in sources]
    if unconnected and not allow_unconnected:
        raise UnconnectedInputError(
            f"input(s) not connected to any output: {', '.join(unconnected)} (connect them, "
            "or allow_unconnected=True to keep their start values)", unconnected)
    outputs = {n: used_outputs[n] + [v.name for v in infos[n].outputs
                                     if v.name not in used_outputs[n]
                                     and v.type not in NOT_SIGNALS] for n in names}
    feed = {n: infos[n].feedthrough for n in names}
    order = _evaluation_order(names, inputs, outputs, sources, feed)
    text_in = {n: [v.name for v in infos[n].inputs if v.type in NOT_SIGNALS] for n in names}
    text_out = {n: [v.name for v in infos[n].outputs if v.type in NOT_SIGNALS] for n in names}
    return Plan(inputs, outputs, sources, order, feed, unconnected, text_in, text_out,
                text_sources)


def _evaluation_order(names, inputs, outputs, sources, feed) -> list[tuple[str, str, bool]]:
    """Topological order of the connector graph; raises AlgebraicLoopError on a cycle."""
    nodes: list[tuple[str, str, bool]] = []
    succ: dict[tuple[str, str, bool], list[tuple[str, str, bool]]] = {}
    for n in names:
        for u in inputs[n]:
            nodes.append((n, u, False))
        for y in outputs[n]:
            nodes.append((n, y, True))
    for node in nodes:
        succ[node] = []
    for (el, u), (src, y) in sources.items():
        succ[(src, y, True)].append((el, u, False))
    for n in names:
        for y in outputs[n]:
            for u in feed[n].get(y, []):
                if (n, u, False) in succ:
                    succ[(n, u, False)].append((n, y, True))
    cycle = _find_cycle(nodes, succ)
    if cycle:
        path = [f"{el}.{name}" for el, name, _ in cycle + cycle[:1]]
        raise AlgebraicLoopError(
            "algebraic loop between subsystems (direct feedthrough around a cycle): "
            + " -> ".join(path) + "; break it with a state (e.g. a filter or an inertia) "
            "in one subsystem, or move the loop into one FMU", [f"{e}.{c}" for e, c, _ in cycle])
    # Kahn's algorithm, stable in the declaration order
    indeg = {v: 0 for v in nodes}
    for v in nodes:
        for w in succ[v]:
            indeg[w] += 1
    ready = [v for v in nodes if indeg[v] == 0]
    order = []
    while ready:
        v = ready.pop(0)
        order.append(v)
        for w in succ[v]:
            indeg[w] -= 1
            if indeg[w] == 0:
                ready.append(w)
    return order


def _find_cycle(nodes, succ):
    """One cycle of the directed graph (list of nodes) or [] (iterative DFS)."""
    color = {v: 0 for v in nodes}           # 0 new, 1 on stack, 2 done
    parent: dict = {}
    for root in nodes:
        if color[root]:
            continue
        stack = [(root, iter(succ[root]))]
        color[root] = 1
        while stack:
            v, it = stack[-1]
            for w in it:
                if color[w] == 0:
                    color[w] = 1
                    parent[w] = v
                    stack.append((w, iter(succ[w])))
                    break
                if color[w] == 1:               # back edge v -> w: cycle w ... v
                    cycle = [v]
                    while cycle[-1] != w:
                        cycle.append(parent[cycle[-1]])
                    return cycle[::-1]
            else:
                color[v] = 2
                stack.pop()
    return []
