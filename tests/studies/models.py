"""Small models for the study tests (units declared for the compile-time unit check)."""

from __future__ import annotations

from bgmodelica import Component, Parameter, Variable, connect
from library.electrical import Capacitor, ConstantVoltage, Ground, OnePort, Resistor


class CubicConductor(OnePort):
    """Nonlinear conductor ``i = a v^3 + b v``: with a series resistor it leaves a nonlinear
    algebraic loop, an algebraic variable of IDAS."""

    a = Parameter(0.02, unit="A/V3", description="cubic coefficient")
    b = Parameter(0.01, unit="S", description="linear conductance")

    def equations(self):
        yield self.i == self.a * self.v**3 + self.b * self.v


class LoopCircuit(Component):
    """V -> R1 -> node; node -> cubic conductor -> ground; node -> R2 -> C -> ground. The
    current through R2 is fixed at t = 0 (a condition on the capacitor voltage through the
    loop, so the initial state depends on the parameters)."""

    src = ConstantVoltage(V=5.0)
    R1 = Resistor(R=100.0)
    g = CubicConductor()
    R2 = Resistor(R=200.0)
    C = Capacitor(C=1e-3, v=dict(start=0.0, fixed=False))
    gnd = Ground()
    i2 = Variable(unit="A", start=0.01, fixed=True, description="current through R2")

    def equations(self):
        yield connect(self.src.p, self.R1.p)
        yield connect(self.R1.n, self.g.p)
        yield connect(self.R1.n, self.R2.p)
        yield connect(self.R2.n, self.C.p)
        yield connect(self.g.n, self.src.n)
        yield connect(self.C.n, self.src.n)
        yield connect(self.src.n, self.gnd.p)
        yield self.i2 == self.R2.i
