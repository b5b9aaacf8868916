"""Examples for the control-engineering analyses (:mod:`bgmodelica.analysis`): models with
top-level ``Input``s and ``Output``s, linearized by ``bgmodelica linearize``."""

from __future__ import annotations

from bgmodelica import Component, Input, Output, Parameter, Variable, connect, der
from library.electrical import EMF, Ground, Inductor, Resistor, SignalVoltage
from library.rotational import Damper, Fixed, Inertia, SpeedSensor

__all__ = ["DCMotorIO", "DoubleIntegrator"]


class DCMotorIO(Component):
    """Armature-controlled DC motor, voltage in, speed out.

    Input ``V`` [V] (armature voltage), output ``w`` [rad/s] (rotor speed). Parameters: R
    [Ohm], L [H], k [N.m/A] (torque constant = back-EMF constant [V.s/rad]), J [kg.m2]
    (rotor + load), b [N.m.s/rad] (viscous friction). Equations ``L di/dt = V - R i - k w``,
    ``J dw/dt = k i - b w``: the transfer function from V to w is
    ``k / ((L s + R)(J s + b) + k^2)``. States: inductor.i, rotor.phi, rotor.w (the angle is
    unobservable from the speed). Starts at rest with zero current.
    """

    R = Parameter(1.0, unit="Ohm", description="Armature resistance")
    L = Parameter(0.01, unit="H", description="Armature inductance")
    k = Parameter(0.1, unit="N.m/A", description="Torque / back-EMF constant")
    J = Parameter(0.01, unit="kg.m2", description="Rotor and load inertia")
    b = Parameter(0.001, unit="N.m.s/rad", description="Viscous friction")
    V = Input(unit="V", description="Armature voltage")
    w = Output(unit="rad/s", description="Rotor speed")

    def __init__(self, name: str | None = None, **modifiers):
        super().__init__(name, **modifiers)
        self.source = SignalVoltage()
        self.resistor = Resistor(R=self.R)
        self.inductor = Inductor(L=self.L, i=0.0)
        self.emf = EMF(k=self.k)
        self.ground = Ground()
        self.rotor = Inertia(J=self.J, phi=0.0, w=0.0)
        self.damper = Damper(d=self.b)
        self.fixed = Fixed()
        self.sensor = SpeedSensor()

    def equations(self):
        yield connect(self.V, self.source.u)
        yield connect(self.source.p, self.resistor.p)
        yield connect(self.resistor.n, self.inductor.p)
        yield connect(self.inductor.n, self.emf.p)
        yield connect(self.emf.n, self.source.n)
        yield connect(self.source.n, self.ground.p)
        yield connect(self.emf.flange, self.rotor.flange_a)
        yield connect(self.rotor.flange_b, self.damper.flange_a)
        yield connect(self.damper.flange_b, self.fixed.flange)
        yield connect(self.rotor.flange_b, self.sensor.flange)
        yield self.w == self.sensor.w


class DoubleIntegrator(Component):
    """A unit mass pushed by a force: the textbook optimal-control plant.

    Input ``u`` [m/s2] (acceleration); states ``x`` [m] (position) and ``v`` [m/s] (speed),
    ``der(x) = v``, ``der(v) = u``; starts at rest at 0. Moving it from rest at 0 to rest at
    1 m in minimum time with ``|u| <= 1`` takes 2 s (bang-bang, switching at 1 s).
    """

    u = Input(unit="m/s2", description="Acceleration")
    x = Variable(0.0, unit="m", description="Position", fixed=True)
    v = Variable(0.0, unit="m/s", description="Speed", fixed=True)

    def equations(self):
        yield der(self.x) == self.v
        yield der(self.v) == self.u
