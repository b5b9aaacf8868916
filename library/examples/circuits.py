"""Example circuits: RC charging, underdamped series RLC, the SciML RC ladder (a component
per section, an array of components, and array equations)."""

from __future__ import annotations

import math

import numpy as np

from bgmodelica import Component, Parameter, Variable, array_of, connect, der, sin, time
from library.electrical import (
    Capacitor,
    ConstantVoltage,
    Ground,
    Inductor,
    Pin,
    Resistor,
    SineVoltage,
)

__all__ = ["RC", "SeriesRLC", "RCLadder", "RCLadderArrays", "RCLadderSections", "RCLadderVector",
           "Section"]


class RC(Component):
    """A 10 V source charges a 1 mF capacitor through a 1 kOhm resistor.

    source (V = 10 V) -> resistor (R = 1 kOhm) -> capacitor (C = 1 mF, v(0) = 0) -> ground.
    Time constant tau = R*C = 1 s: ``capacitor.v = V*(1 - exp(-t/tau))``.
    """

    source = ConstantVoltage(V=10.0)
    resistor = Resistor(R=1e3)
    capacitor = Capacitor(C=1e-3, v=0.0)
    ground = Ground()

    def equations(self):
        yield connect(self.source.p, self.resistor.p)
        yield connect(self.resistor.n, self.capacitor.p)
        yield connect(self.capacitor.n, self.source.n)
        yield connect(self.source.n, self.ground.p)


class SeriesRLC(Component):
    """Underdamped series RLC circuit switched onto a 1 V source at t = 0.

    source (V = 1 V) -> resistor (R = 10 Ohm) -> inductor (L = 0.1 H, i(0) = 0)
    -> capacitor (C = 1 mF, v(0) = 0) -> ground.
    Natural frequency w0 = 1/sqrt(L*C) = 100 rad/s, decay rate alpha = R/(2*L) = 50 1/s,
    damped frequency wd = sqrt(w0^2 - alpha^2) = 86.6 rad/s (damping ratio 0.5):
    ``capacitor.v = V*(1 - exp(-alpha*t)*(cos(wd*t) + alpha/wd*sin(wd*t)))``,
    ``inductor.i = V/(L*wd)*exp(-alpha*t)*sin(wd*t)``.
    """

    source = ConstantVoltage(V=1.0)
    resistor = Resistor(R=10.0)
    inductor = Inductor(L=0.1, i=0.0)
    capacitor = Capacitor(C=1e-3, v=0.0)
    ground = Ground()

    def equations(self):
        yield connect(self.source.p, self.resistor.p)
        yield connect(self.resistor.n, self.inductor.p)
        yield connect(self.inductor.n, self.capacitor.p)
        yield connect(self.capacitor.n, self.source.n)
        yield connect(self.source.n, self.ground.p)


class RCLadder(Component):
    """The SciML "RC circuit" benchmark: a chain of ``n`` RC sections.

    A sine source (amplitude 1 V, 10 Hz) drives resistors R1..Rn in series; node k (after
    resistor Rk) is tied to ground by capacitor Ck. Rk = 1/k Ohm, Ck = 1/k^2 F, and capacitor
    k starts at Ck.v = k V. Subcomponents: ``source``, ``ground``, ``R1..Rn``, ``C1..Cn``.
    """

    def __init__(self, n: int = 10, **modifiers):
        super().__init__(**modifiers)
        if n < 1:
            raise ValueError("RCLadder needs n >= 1 sections")
        self.n_sections = n
        self.source = SineVoltage(V=1.0, f=10.0)
        self.ground = Ground()
        self.connect(self.source.n, self.ground.p)
        node = self.source.p
        for k in range(1, n + 1):
            resistor = self.add(f"R{k}", Resistor(R=1.0 / k))
            capacitor = self.add(f"C{k}", Capacitor(C=1.0 / k**2, v=float(k)))
            self.connect(node, resistor.p)
            self.connect(resistor.n, capacitor.p)
            self.connect(capacitor.n, self.ground.p)
            node = resistor.n


class Section(Component):
    """One section of an RC ladder: a resistor from ``p`` to ``n`` and a capacitor from ``n``
    to ``ground``.

    Connectors: ``p``, ``n``, ``ground`` (Pin). Subcomponents: ``R`` (Resistor, R = 1 Ohm),
    ``C`` (Capacitor, C = 1 F; its voltage ``C.v`` is the state). Set them by modifiers:
    ``Section(**{"R.R": 0.5, "C.C": 0.25, "C.v": 2.0})``.
    """

    p = Pin()
    n = Pin()
    ground = Pin()
    R = Resistor(R=1.0)
    C = Capacitor(C=1.0)

    def equations(self):
        yield connect(self.p, self.R.p)
        yield connect(self.R.n, self.C.p)
        yield connect(self.R.n, self.n)
        yield connect(self.C.n, self.ground)


class RCLadderSections(Component):
    """:class:`RCLadder` built from a :class:`Section` per rung: ``section1..section{n}``,
    section ``k`` with ``R.R = 1/k`` Ohm, ``C.C = 1/k^2`` F and ``C.v(0) = k`` V, chained
    ``p`` to ``n`` from the sine source, every ``ground`` pin to the ground. Same equations
    and results as :class:`RCLadder` (its ``Ck.v`` is ``section{k}.C.v`` here)."""

    def __init__(self, n: int = 10, **modifiers):
        super().__init__(**modifiers)
        if n < 1:
            raise ValueError("RCLadderSections needs n >= 1 sections")
        self.n_sections = n
        self.source = SineVoltage(V=1.0, f=10.0)
        self.ground = Ground()
        self.connect(self.source.n, self.ground.p)
        node = self.source.p
        for k in range(1, n + 1):
            section = self.add(f"section{k}", Section(**{"R.R": 1.0 / k, "C.C": 1.0 / k**2,
                                                         "C.v": float(k)}))
            self.connect(node, section.p)
            self.connect(section.ground, self.ground.p)
            node = section.n


def _ladder_values(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """R_k = 1/k Ohm, C_k = 1/k^2 F, v_k(0) = k V for k = 1..n."""
    k = np.arange(1, n + 1, dtype=float)
    return 1.0 / k, 1.0 / k**2, k


class RCLadderArrays(Component):
    """:class:`RCLadder` built from arrays of components: ``R[1..n]`` and ``C[1..n]``
    (``R[k].R = 1/k``, ``C[k].C = 1/k^2``, ``C[k].v(0) = k``), connected array-wise.
    Same equations, same results as :class:`RCLadder` (its ``Ck.v`` is ``C[k].v`` here)."""

    def __init__(self, n: int = 10, **modifiers):
        super().__init__(**modifiers)
        if n < 1:
            raise ValueError("RCLadderArrays needs n >= 1 sections")
        r, c, v0 = _ladder_values(n)
        self.source = SineVoltage(V=1.0, f=10.0)
        self.ground = Ground()
        self.R = array_of(Resistor, n, R=r)
        self.C = array_of(Capacitor, n, C=c, v=v0)
        self.connect(self.source.n, self.ground.p)
        self.connect(self.source.p, self.R[0].p)
        self.connect(self.R.n[:-1], self.R.p[1:])      # the series chain
        self.connect(self.R.n, self.C.p)
        self.connect(self.C.n, self.ground.p)           # one connector, broadcast


class RCLadderVector(Component):
    """:class:`RCLadder` as array equations on node voltages ``v[1..n]`` [V] and resistor
    currents ``i[1..n]`` [A] (``R[k] = 1/k`` Ohm, ``C[k] = 1/k^2`` F, ``v[k](0) = k`` V;
    source ``V*sin(2*pi*f*time)``, V = 1 V, f = 10 Hz)::

        i[1]      = (V*sin(2*pi*f*t) - v[1]) / R[1]
        i[2:n]    = (v[1:n-1] - v[2:n]) / R[2:n]
        C*der(v)  = i - [i[2:n], 0]

    Its ``v[k]`` is ``Ck.v`` of :class:`RCLadder`; ``i[k]`` is ``Rk.i``.
    """

    v = Variable(shape="n", unit="V", description="node voltage (capacitor voltage)")
    i = Variable(shape="n", unit="A", description="resistor current")
    R = Parameter(shape="n", value=1.0, unit="Ohm", description="section resistance")
    C = Parameter(shape="n", value=1.0, unit="F", description="section capacitance")
    V = Parameter(1.0, unit="V", description="source amplitude")
    f = Parameter(10.0, unit="Hz", description="source frequency")

    def __init__(self, n: int = 10, **modifiers):
        if n < 1:
            raise ValueError("RCLadderVector needs n >= 1 sections")
        self.n = n
        r, c, v0 = _ladder_values(n)
        super().__init__(**{"R": r, "C": c, "v": v0, **modifiers})

    def equations(self):
        v, i = self.v, self.i
        yield i[0] == (self.V * sin(2 * math.pi * self.f * time) - v[0]) / self.R[0]
        if self.n > 1:
            yield i[1:] == (v[:-1] - v[1:]) / self.R[1:]
            yield self.C[:-1] * der(v[:-1]) == i[:-1] - i[1:]
        yield self.C[-1] * der(v[-1]) == i[-1]
