"""Turn an acausal component into a causal subsystem (top-level inputs and outputs) for export.

A co-simulation unit (an FMU) has causal signals only: inputs it is given, outputs it computes.
An acausal component talks through connectors (a rotational ``Flange``: potential ``phi``,
flow ``tau``). :func:`expose` decides, per connector, which side of the power bond the
subsystem *receives* and which it *returns*:

* :class:`FlowInput` -- the environment pushes a flow into the connector (a torque source:
  ``tau`` in, the component computes its motion). Pair it with :class:`PotentialOutput`
  (``phi``, or ``der(phi)`` with ``order=1``) to return the motion.
* :class:`PotentialInput` -- the environment imposes the potential (``order=0``) or its time
  derivative (``order=1``, a speed source; the potential is integrated from ``start``). Pair it
  with :class:`FlowOutput` to return the flow the component exerts on its environment.
* a plain string -- an existing variable: for inputs an ``Input`` of a subcomponent (joined to
  the new top-level input), for outputs any variable (``name == path``). A top-level
  variable mapped to its own name is turned into an ``Output`` in place. (If the compiler then
  picks that very variable as a *state*, the FMU exporter keeps it a state, not an output:
  expose a state under a new name, e.g. ``outputs={"x": "y"}`` for an integrator's ``y``.)

Causality must make sense physically: a component holding an inertia rigidly at a connector
can only be driven by a *flow* there (a prescribed speed would need its derivative: the
compiler then reports that an input would have to be differentiated). Lump such inertias on
the other side of the cut (see :mod:`library.robots.subsystems`) or put a compliance at the cut.

Example -- a geared motor without rotor inertia, driven by the joint speed::

    motor = expose(GearedMotor(), inputs={"w": PotentialInput("flange", order=1)},
                   outputs={"tau": FlowOutput("flange")})

``expose`` modifies and returns the component it is given (pass a fresh instance); the new
signals are top-level ``Input``/``Output`` variables, so :func:`bgmodelica.fmi.from_model.
export_model` makes them FMU inputs and outputs, and all original names are kept.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any

from ..core.component import Component, Connector, Element
from ..core.expressions import der
from ..core.variables import (
    KIND_FLOW,
    KIND_INPUT,
    KIND_OUTPUT,
    KIND_POTENTIAL,
    KIND_VARIABLE,
    Input,
    Output,
    Symbol,
)
from ..errors import DeclarationError

__all__ = ["FlowInput", "FlowOutput", "PotentialInput", "PotentialOutput", "add_signal",
           "expose"]


@dataclass(frozen=True)
class FlowInput:
    """The input is the flow pushed *into* the component at ``connector`` (a force/torque
    source). ``flow`` names the flow variable when the connector has several."""

    connector: str
    flow: str | None = None


@dataclass(frozen=True)
class PotentialInput:
    """The input imposes the potential (``order=0``) or its time derivative (``order=1``,
    integrated from ``start``; ``fixed=False`` leaves the initial potential to the component)
    at ``connector``. The adapter exerts no other flow."""

    connector: str
    order: int = 1
    start: float = 0.0
    fixed: bool = True
    potential: str | None = None


@dataclass(frozen=True)
class PotentialOutput:
    """The output is the potential of ``connector`` (``order=0``) or its derivative (1)."""

    connector: str
    order: int = 0
    potential: str | None = None


@dataclass(frozen=True)
class FlowOutput:
    """The output is the flow the component exerts on its environment at ``connector``
    (minus the flow into the component). Needs a :class:`PotentialInput` on that connector."""

    connector: str


class _Adapter(Component):
    """Drives one connector from a top-level signal (built by :func:`expose`)."""

    def __init__(self, port: Connector, mode: str, pot: str, flow: str, order: int = 0,
                 name: str | None = None):
        super().__init__(name)
        self.add("port", port)
        object.__setattr__(self, "_mode", (mode, pot, flow, order))

    def drive(self, signal: Any) -> list[Any]:
        """Equations of the adapter: the other flows vanish, the chosen one is the input (flow
        mode) or free (potential mode, where the potential or its rate is the input)."""
        mode, pot, flow, order = self._mode
        port = self.port
        eqs = [getattr(port, n) == 0 for n, s in port._symbols.items()
               if s.decl.kind == KIND_FLOW and n != flow]
        if mode == "flow":
            eqs.append(getattr(port, flow) == -signal)     # into the adapter: -signal
        elif order == 0:
            eqs.append(getattr(port, pot) == signal)
        else:
            eqs.append(der(getattr(port, pot)) == signal)
        return eqs


def _resolve(component: Component, path: str) -> Element | Symbol:
    node: Element = component
    parts = path.split(".")
    for k, part in enumerate(parts):
        if part in node._children:
            node = node._children[part]
        elif part in node._symbols and k == len(parts) - 1:
            return node._symbols[part]
        else:
            raise DeclarationError(
                f"{type(component).__name__}: {path!r} names nothing ({part!r} is not a "
                f"subcomponent, connector or variable of {type(node).__name__})")
    return node


def _connector(component: Component, path: str) -> Connector:
    node = _resolve(component, path)
    if not isinstance(node, Connector):
        raise DeclarationError(f"{type(component).__name__}: {path!r} is not a connector")
    return node


def _pick(conn: Connector, kind: str, wanted: str | None, path: str) -> str:
    names = [n for n, s in conn._symbols.items() if s.decl.kind == kind]
    if wanted is not None:
        if wanted not in names:
            raise DeclarationError(f"connector {path!r} has no {kind} variable {wanted!r} "
                                   f"(it has {', '.join(names) or 'none'})")
        return wanted
    if len(names) != 1:
        raise DeclarationError(f"connector {path!r} has {len(names)} {kind} variables "
                               f"({', '.join(names)}): say which one")
    return names[0]


def add_signal(component: Component, name: str, decl: Any) -> Any:
    """Declare a new top-level signal ``name`` (an :class:`~bgmodelica.Input` or
    :class:`~bgmodelica.Output` declaration) on the component instance; returns its leaf for
    equations (``component.equation(leaf == ...)``)."""
    if not name.isidentifier():
        raise DeclarationError(f"{name!r} is not a valid signal name")
    if name in component._symbols or name in component._children:
        raise DeclarationError(
            f"{type(component).__name__} already has a variable or subcomponent {name!r}")
    sym = Symbol(name, decl, component)
    component._symbols[name] = sym
    object.__setattr__(component, name, sym.leaf)
    return sym.leaf


def expose(component: Component, inputs: Mapping[str, Any] | None = None,
           outputs: Mapping[str, Any] | None = None) -> Component:
    """Add top-level inputs and outputs to ``component`` (in place) and return it.

    ``inputs``/``outputs`` map new signal names to a port spec (:class:`FlowInput`,
    :class:`PotentialInput`, :class:`PotentialOutput`, :class:`FlowOutput`) or to the dotted
    path of an existing variable. A name that already is a top-level ``Input`` (for inputs) or
    ``Output`` (for outputs) of the component and maps to itself is kept as it is.
    Raises :class:`~bgmodelica.errors.DeclarationError` for unknown paths, two inputs on one
    connector, a :class:`FlowOutput` without a :class:`PotentialInput`, or name clashes.
    """
    inputs = dict(inputs or {})
    outputs = dict(outputs or {})
    adapters: dict[int, _Adapter] = {}
    for name, spec in inputs.items():
        if isinstance(spec, str):
            existing = component._symbols.get(name)
            if spec == name and existing is not None and existing.decl.kind == KIND_INPUT:
                continue
            target = _resolve(component, spec)
            if not isinstance(target, Symbol) or target.decl.kind != KIND_INPUT:
                raise DeclarationError(f"input {name!r}: {spec!r} is not an Input variable")
            leaf = add_signal(component, name, Input(unit=target.decl.unit,
                                                      description=target.decl.description))
            component.connect(leaf, target.leaf)
            continue
        if not isinstance(spec, (FlowInput, PotentialInput)):
            raise DeclarationError(f"input {name!r}: expected FlowInput, PotentialInput or a "
                                   f"variable path, got {spec!r}")
        conn = _connector(component, spec.connector)
        if id(conn) in adapters:
            raise DeclarationError(f"connector {spec.connector!r} is driven by two inputs")
        if isinstance(spec, FlowInput):
            flow = _pick(conn, KIND_FLOW, spec.flow, spec.connector)
            pot = ""
            decl = conn._symbols[flow].decl
            mode, order = "flow", 0
        else:
            if spec.order not in (0, 1):
                raise DeclarationError(f"input {name!r}: order must be 0 or 1")
            pot = _pick(conn, KIND_POTENTIAL, spec.potential, spec.connector)
            flow = _pick(conn, KIND_FLOW, None, spec.connector)
            decl = conn._symbols[pot].decl
            mode, order = "potential", spec.order
        unit = decl.unit if order == 0 else _der_unit(decl.unit)
        port = conn.clone()
        if mode == "potential" and order == 1:
            port.modify(**{pot: dict(start=float(spec.start), fixed=bool(spec.fixed))})
        adapter = _Adapter(port, mode, pot, flow, order)
        component.add(f"{name}_source", adapter)
        what = (f"Flow into {spec.connector}.{flow}" if mode == "flow" else
                f"Imposed {'rate of ' if order else ''}{spec.connector}.{pot}")
        leaf = add_signal(component, name, Input(unit=unit, description=what))
        component.connect(adapter.port, conn)
        component.equation(*adapter.drive(leaf))
        adapters[id(conn)] = adapter
    for name, spec in outputs.items():
        if isinstance(spec, str):
            existing = component._symbols.get(name)
            if spec == name and existing is not None and existing.decl.kind == KIND_OUTPUT:
                continue
            if spec == name and existing is not None and existing.decl.kind == KIND_VARIABLE:
                # promote a top-level variable to an output, keeping its metadata
                existing.decl = Output(**{f.name: getattr(existing.decl, f.name)
                                          for f in fields(existing.decl)})
                continue
            target = _resolve(component, spec)
            if not isinstance(target, Symbol):
                raise DeclarationError(f"output {name!r}: {spec!r} is not a variable")
            leaf = add_signal(component, name, Output(unit=target.decl.unit,
                                                       description=target.decl.description))
            component.equation(leaf == target.leaf)
        elif isinstance(spec, PotentialOutput):
            conn = _connector(component, spec.connector)
            pot = _pick(conn, KIND_POTENTIAL, spec.potential, spec.connector)
            unit = conn._symbols[pot].decl.unit
            value = getattr(conn, pot)
            if spec.order == 1:
                value, unit = der(value), _der_unit(unit)
            elif spec.order != 0:
                raise DeclarationError(f"output {name!r}: order must be 0 or 1")
            leaf = add_signal(component, name, Output(unit=unit, description=(
                f"{'Rate of ' if spec.order else ''}{spec.connector}.{pot}")))
            component.equation(leaf == value)
        elif isinstance(spec, FlowOutput):
            conn = _connector(component, spec.connector)
            adapter = adapters.get(id(conn))
            if adapter is None or adapter._mode[0] != "potential":
                raise DeclarationError(
                    f"output {name!r}: FlowOutput({spec.connector!r}) needs a PotentialInput "
                    "on the same connector (the flow is what it takes to impose the motion)")
            flow = adapter._mode[2]
            leaf = add_signal(component, name, Output(
                unit=conn._symbols[flow].decl.unit,
                description=f"{flow} exerted by the component at {spec.connector}"))
            component.equation(leaf == getattr(adapter.port, flow))
        else:
            raise DeclarationError(f"output {name!r}: expected PotentialOutput, FlowOutput or "
                                   f"a variable path, got {spec!r}")
    return component


def _der_unit(unit: str) -> str:
    if not unit or unit == "1":
        return "1/s"
    return {"rad": "rad/s", "m": "m/s", "rad/s": "rad/s2", "m/s": "m/s2"}.get(unit, f"{unit}/s")
