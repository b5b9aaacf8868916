"""Example circuits: RC charging, underdamped series RLC, the SciML RC ladder."""

from __future__ import annotations

from bgmodelica import Component, connect
from library.electrical import (
    Capacitor,
    ConstantVoltage,
    Ground,
    Inductor,
    Resistor,
    SineVoltage,
)

__all__ = ["RC", "SeriesRLC", "RCLadder"]


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
