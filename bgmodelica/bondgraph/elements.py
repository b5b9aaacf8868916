"""Bond-graph elements as acausal components.

Power ports and bonds
---------------------
A :class:`PowerPort` is a connector with effort ``e`` (a potential) and flow ``f`` (a flow,
counted positive *into* the element that owns the port, as every connector flow). A bond
``tail -> head`` is a connection of two ports: ``e`` equal, ``f_tail + f_head = 0``. The bond's
own flow (along its half-arrow) is therefore ``+head.f = -tail.f``: each port knows its
``orientation`` (+1 if the half-arrow points into its element, -1 if out) and the element laws
use the *bond flow* ``orientation * port.f``. Power into an element through a port is always
``e * port.f``.

Element laws (in bond variables, the half-arrow convention of the paper, Table III)
-----------------------------------------------------------------------------------
Se ``e = E``; Sf ``f = F``; R ``e = R f``; C ``dq/dt = f, C e = q``; I ``dp/dt = e,
I f = p``; TF/MTF ``e1 = m e2, f2 = m f1``; GY/MGY ``e1 = r f2, e2 = r f1``; 0-junction: common
effort, flows (signed by half-arrow) sum to 0; 1-junction: common flow, efforts sum to 0;
De ``y = e, f = 0``; Df ``y = f, e = 0``; Dq ``dy/dt = f, e = 0`` (displacement detector);
Sw (switch of hybrid bond graphs) ``e = 0`` when on, ``f = 0`` when off, in the resistive form
``e = s (Ron if on else 1), f = s (1 if on else Goff)`` (see :class:`~.switch.Sw`).

Values and moduli may be numbers, parameter expressions, SX expressions of model variables,
callables receiving the enclosing :class:`~bgmodelica.bondgraph.model.BondGraph`
(``lambda m: m.l1*cos(m.q1)``) or strings evaluated in its namespace (``"l1*cos(q1)"``).
Nonlinear laws: ``R(law=lambda e, f: e == 2*f**3)``, ``C(law=lambda e, q: ...)``,
``I(law=lambda f, p: ...)`` (a third argument, if declared, receives the bond graph).
"""

from __future__ import annotations

from typing import Any, ClassVar

from ..core import expressions as _expressions
from ..core.variables import (
    Input,
    Output,
    Parameter,
    Variable,
)
from .base import (
    BGElement,
    PowerPort,
    _law,
    bond_flow,
    declare,
    element_path,
    orientation,
    resolve,
)
from .errors import BondError, JunctionError, ModulusError

__all__ = ["PowerPort", "BGElement", "Se", "Sf", "R", "C", "I", "TF", "GY", "MTF", "MGY",
           "ZeroJunction", "OneJunction", "J0", "J1", "De", "Df", "Dq", "orientation",
           "bond_flow"]


class _Source(BGElement):
    _port_defaults = {"port": -1}
    _value_name = ""

    def __init__(self, name: str | None = None, *, value: Any = None, signal: bool = False,
                 **kw: Any) -> None:
        main = kw.pop(self._main, None)
        if main is not None and (value is not None or signal):
            raise ModulusError(f"{self.kind} {name or ''}: give either {self._main}=, value= "
                               "or signal=True", name)
        object.__setattr__(self, "_expr", value)
        object.__setattr__(self, "_signal", signal)
        super().__init__(name, **kw)
        if signal:
            declare(self, "u", Input(description=f"Imposed {self._value_name}"))
        elif value is None:
            declare(self, self._main, Parameter(0.0 if main is None else main,
                                                description=f"Imposed {self._value_name}"))

    def value(self) -> Any:
        if self._signal:
            return self.u
        if self._expr is not None:
            return resolve(self._expr, self, self._value_name)
        return getattr(self, self._main)

    def label(self) -> str:
        if self._label is None and (self._signal or self._expr is not None):
            if isinstance(self._expr, str):
                return self._expr
            return self.name or self.kind
        return super().label()

    def modulus_text(self) -> str:
        if self._expr is None or self._signal:
            return ""
        return self._expr if isinstance(self._expr, str) else str(self.value())


class Se(_Source):
    """Effort source ``e = E``. ``Se(E=12)`` (parameter ``E``); ``Se(value=expr)`` (a time
    expression, model expression, callable or string); ``Se(signal=True)`` adds an Input ``u``
    and ``e = u``."""

    kind = "Se"
    _main = "E"
    _value_name = "effort"
    port = PowerPort()

    def equations(self):
        yield self.port.e == self.value()


class Sf(_Source):
    """Flow source ``f = F`` (along the half-arrow, out of the source by default). Same
    options as :class:`Se` (``F=``, ``value=``, ``signal=True``)."""

    kind = "Sf"
    _main = "F"
    _value_name = "flow"
    port = PowerPort()

    def equations(self):
        yield bond_flow(self.port) == self.value()


# -- passive one-ports -------------------------------------------------------------------------
class _Passive(BGElement):
    def __init__(self, name: str | None = None, *, law: Any = None, **kw: Any) -> None:
        object.__setattr__(self, "_law", law)
        super().__init__(name, **kw)


class R(_Passive):
    """Dissipator. Linear ``e = R f``; nonlinear ``R(law=lambda e, f: e == ...)``."""

    kind = "R"
    _main = "R"
    R = Parameter(1.0, description="Resistance (effort per flow)")
    port = PowerPort()

    def equations(self):
        e, f = self.port.e, bond_flow(self.port)
        if self._law is not None:
            yield from _law(self._law, [e, f], self)
        else:
            yield e == self.R * f


class C(_Passive):
    """Capacitive storage: ``dq/dt = f``; linear ``C e = q``; nonlinear
    ``C(law=lambda e, q: e == q**3/k)``. State: displacement ``q`` (start via ``C(q=...)``)."""

    kind = "C"
    _main = "C"
    C = Parameter(1.0, description="Compliance (displacement per effort)")
    q = Variable(description="Generalized displacement (integral of the flow)")
    port = PowerPort()

    def equations(self):
        e, f = self.port.e, bond_flow(self.port)
        yield _der(self.q) == f
        if self._law is not None:
            yield from _law(self._law, [e, self.q], self)
        else:
            yield self.C * e == self.q


class I(_Passive):  # noqa: E742
    """Inertial storage: ``dp/dt = e``; linear ``I f = p``; nonlinear
    ``I(law=lambda f, p: ...)``. State: momentum ``p`` (start via ``I(p=...)``)."""

    kind = "I"
    _main = "I"
    I = Parameter(1.0, description="Inertance (momentum per flow)")  # noqa: E741
    p = Variable(description="Generalized momentum (integral of the effort)")
    port = PowerPort()

    def equations(self):
        e, f = self.port.e, bond_flow(self.port)
        yield _der(self.p) == e
        if self._law is not None:
            yield from _law(self._law, [f, self.p], self)
        else:
            yield self.I * f == self.p


def _der(x: Any) -> Any:
    return _expressions.der(x)


# -- two-ports ---------------------------------------------------------------------------------
class _TwoPort(BGElement):
    _port_defaults = {"p1": 1, "p2": -1}
    p1 = PowerPort()
    p2 = PowerPort()

    def _check_through(self) -> tuple[Any, Any, Any, Any]:
        s1, s2 = orientation(self.p1), orientation(self.p2)
        if s1 == s2:
            way = "into" if s1 > 0 else "out of"
            raise BondError(f"{self.kind} {element_path(self)}: both bonds point {way} it; a "
                            "transformer or gyrator passes power through, one bond in and "
                            "one out", element_path(self))
        return self.p1.e, bond_flow(self.p1), self.p2.e, bond_flow(self.p2)


class TF(_TwoPort):
    """Transformer ``e1 = m e2``, ``f2 = m f1`` (ports ``p1``, ``p2``). Parameter: m."""

    kind = "TF"
    _main = "m"
    m = Parameter(1.0, description="Transformer modulus")

    def modulus(self) -> Any:
        return self.m

    def equations(self):
        e1, f1, e2, f2 = self._check_through()
        m = self.modulus()
        yield e1 == m * e2
        yield f2 == m * f1


class GY(_TwoPort):
    """Gyrator ``e1 = r f2``, ``e2 = r f1`` (ports ``p1``, ``p2``). Parameter: r."""

    kind = "GY"
    _main = "r"
    r = Parameter(1.0, description="Gyrator modulus")

    def modulus(self) -> Any:
        return self.r

    def equations(self):
        e1, f1, e2, f2 = self._check_through()
        r = self.modulus()
        yield e1 == r * f2
        yield e2 == r * f1


class _Modulated(_TwoPort):
    def __init__(self, name: str | None = None, *, m: Any = None, **kw: Any) -> None:
        if m is None:
            raise ModulusError(f"{self.kind} {name or ''}: a modulus m= is required "
                               "(number, expression, callable or string)", name)
        object.__setattr__(self, "_modulus", m)
        super().__init__(name, **kw)

    def modulus(self) -> Any:
        return resolve(self._modulus, self, "modulus")

    def modulus_text(self) -> str:
        if isinstance(self._modulus, str):
            return self._modulus
        return str(self.modulus())


class MTF(_Modulated):
    """Modulated transformer: like :class:`TF` with ``m`` an expression of model variables:
    ``MTF(m=lambda bg: -bg.lc1*sin(bg.q1))`` or ``MTF(m="-lc1*sin(q1)")``."""

    kind = "MTF"
    equations = TF.equations


class MGY(_Modulated):
    """Modulated gyrator: like :class:`GY` with its modulus given as ``m=`` (an
    expression)."""

    kind = "MGY"
    equations = GY.equations


# -- junctions ---------------------------------------------------------------------------------
class _Junction(BGElement):
    _port_defaults: ClassVar[dict[str, int]] = {}

    def new_port(self) -> PowerPort:
        k = 1 + sum(isinstance(c, PowerPort) for c in self._children.values())
        while f"p{k}" in self._children:
            k += 1
        port = PowerPort()
        object.__setattr__(port, "_owner", self)
        self.add(f"p{k}", port)
        return port

    def _ports(self) -> list[PowerPort]:
        ports = self.power_ports()
        if len(ports) < 2:
            raise JunctionError(f"{self.kind}-junction {element_path(self)} has {len(ports)} "
                                f"bond{'s' if len(ports) != 1 else ''}; a junction needs at "
                                "least two", element_path(self))
        return ports

    def label(self) -> str:
        return self._label if self._label is not None else (self.name or "")


class ZeroJunction(_Junction):
    """0-junction: common effort ``e``; the bond flows, signed by their half-arrows (in +,
    out -), sum to zero. Ports ``p1, p2, ...`` are created by :meth:`BondGraph.bond`."""

    kind = "0"
    e = Variable(description="Common effort")

    def equations(self):
        ports = self._ports()
        for p in ports:
            yield p.e == self.e
        yield sum((p.f for p in ports[1:]), ports[0].f) == 0


class OneJunction(_Junction):
    """1-junction: common flow ``f`` (along each half-arrow); the efforts, signed by their
    half-arrows (in +, out -), sum to zero."""

    kind = "1"
    f = Variable(description="Common flow")

    def equations(self):
        ports = self._ports()
        total: Any = 0.0
        for k, p in enumerate(ports):
            s = orientation(p)
            yield s * p.f == self.f
            term = p.e if s > 0 else -p.e
            total = term if k == 0 else total + term
        yield total == 0


J0 = ZeroJunction
J1 = OneJunction


# -- detectors ---------------------------------------------------------------------------------
class De(BGElement):
    """Effort detector: output ``y = e``; draws no flow."""

    kind = "De"
    port = PowerPort()
    y = Output(description="Measured effort")

    def equations(self):
        yield bond_flow(self.port) == 0
        yield self.y == self.port.e


class Df(BGElement):
    """Flow detector: output ``y = f``; imposes no effort."""

    kind = "Df"
    port = PowerPort()
    y = Output(description="Measured flow")

    def equations(self):
        yield self.port.e == 0
        yield self.y == bond_flow(self.port)


class Dq(BGElement):
    """Displacement detector (a Df followed by an integrator): ``dy/dt = f``, imposes no
    effort. Measures e.g. a joint angle from the joint speed; ``Dq(y=0.3)`` sets y(0)."""

    kind = "Df"
    port = PowerPort()
    y = Output(description="Integral of the measured flow")

    def equations(self):
        yield self.port.e == 0
        yield _der(self.y) == bond_flow(self.port)
