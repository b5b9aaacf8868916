"""High-index test models: the compiler must reduce them to index 1 before simulating.

- :class:`Pendulum`: Cartesian pendulum (index 3), states chosen automatically.
- :class:`PendulumPreferXY`: the same with ``x``, ``y`` preferred as states.
- :class:`RigidInertias`: two inertias rigidly coupled (index 2).
- :class:`GearedLoad`: inertias coupled through an IdealGear, torque-driven (index 2).
- :class:`MotorGearLoad`: DC motor, gearbox and load inertia as separate components (index 2).
- :class:`DoublePendulum`: two point masses on rigid rods in Cartesian coordinates (index 3).
"""

from __future__ import annotations

from bgmodelica import Component, Parameter, StateSelect, Variable, connect, der

from ..electrical import EMF, ConstantVoltage, Ground, Inductor, Resistor
from ..rotational import ConstantTorque, Damper, Fixed, IdealGear, Inertia

__all__ = ["Pendulum", "PendulumPreferXY", "RigidInertias", "GearedLoad", "MotorGearLoad",
           "DoublePendulum"]


class Pendulum(Component):
    """Point mass on a massless rod, in Cartesian coordinates (index 3).

    Parameters: L = 1 m rod length, m = 1 kg mass, g = 9.81 m/s2 gravity along -y.
    Variables: x, y [m] position; vx, vy [m/s] velocity; T [N] rod tension per length.
    Released from rest at x = L, y = 0 (y and vy fixed; x is a guess that picks the root).
    """

    L = Parameter(1.0, unit="m", description="Rod length")
    m = Parameter(1.0, unit="kg", description="Mass")
    g = Parameter(9.81, unit="m/s2", description="Gravity along -y")
    x = Variable(unit="m", start=1.0, description="Horizontal position")
    y = Variable(unit="m", start=0.0, fixed=True, description="Vertical position")
    vx = Variable(unit="m/s", start=0.0, description="Horizontal velocity")
    vy = Variable(unit="m/s", start=0.0, fixed=True, description="Vertical velocity")
    T = Variable(unit="N/m", description="Rod force per unit length (tension / L)")

    def equations(self):
        yield der(self.x) == self.vx
        yield der(self.y) == self.vy
        yield self.m * der(self.vx) == -self.T * self.x
        yield self.m * der(self.vy) == -self.T * self.y - self.m * self.g
        yield self.x**2 + self.y**2 == self.L**2


class PendulumPreferXY(Pendulum):
    """:class:`Pendulum` with ``stateSelect = prefer`` on x and y (dynamic choice of x or y)."""

    x = Variable(unit="m", start=1.0, state_select=StateSelect.PREFER,
                 description="Horizontal position")
    y = Variable(unit="m", start=0.0, fixed=True, state_select=StateSelect.PREFER,
                 description="Vertical position")


class RigidInertias(Component):
    """Two inertias J1 = 1, J2 = 2 kg.m2 rigidly joined, driven by a 3 N.m constant torque.

    Both inertias declare angle and speed states: only one pair survives index reduction.
    Analytic: w = 3/(J1 + J2) * t.
    """

    j1 = Inertia(J=1.0, phi=0.0, w=0.0)
    j2 = Inertia(J=2.0)
    torque = ConstantTorque(tau_constant=3.0)

    def equations(self):
        yield connect(self.torque.flange, self.j1.flange_a)
        yield connect(self.j1.flange_b, self.j2.flange_a)


class GearedLoad(Component):
    """Motor inertia J1 = 0.01 kg.m2 through an IdealGear (ratio 10) to a load J2 = 1 kg.m2,
    driven by 1 N.m. Analytic: load acceleration = ratio*tau/(J2 + ratio^2*J1)."""

    motor = Inertia(J=0.01, phi=0.0, w=0.0)
    gear = IdealGear(ratio=10.0)
    load = Inertia(J=1.0)
    torque = ConstantTorque(tau_constant=1.0)

    def equations(self):
        yield connect(self.torque.flange, self.motor.flange_a)
        yield connect(self.motor.flange_b, self.gear.flange_a)
        yield connect(self.gear.flange_b, self.load.flange_a)


class MotorGearLoad(Component):
    """DC motor (R = 1 Ohm, L = 1 mH, k = 0.1 N.m/A, rotor Jm = 1e-4 kg.m2) at 12 V, gearbox
    ratio 50, load inertia 0.05 kg.m2 with viscous damping 0.01 N.m.s/rad to ground.

    Rotor and load both declare states; the rigid gear makes it index 2.
    """

    source = ConstantVoltage(V=12.0)
    ground = Ground()
    R = Resistor(R=1.0)
    L = Inductor(L=1e-3, i=0.0)
    emf = EMF(k=0.1)
    rotor = Inertia(J=1e-4, phi=0.0, w=0.0)
    gear = IdealGear(ratio=50.0)
    load = Inertia(J=0.05)
    damper = Damper(d=0.01)
    housing = Fixed()

    def equations(self):
        yield connect(self.source.p, self.R.p)
        yield connect(self.R.n, self.L.p)
        yield connect(self.L.n, self.emf.p)
        yield connect(self.emf.n, self.source.n)
        yield connect(self.source.n, self.ground.p)
        yield connect(self.emf.flange, self.rotor.flange_a)
        yield connect(self.rotor.flange_b, self.gear.flange_a)
        yield connect(self.gear.flange_b, self.load.flange_a)
        yield connect(self.load.flange_b, self.damper.flange_a)
        yield connect(self.damper.flange_b, self.housing.flange)


class DoublePendulum(Component):
    """Two point masses on rigid rods, Cartesian coordinates, chain of two constraints.

    Parameters: L1 = 1 m, L2 = 0.8 m, m1 = 1 kg, m2 = 0.5 kg, g = 9.81 m/s2 (along -y).
    Starts at rest with both rods horizontal (x1 = L1, x2 = L1 + L2, y1 = y2 = 0).
    """

    L1 = Parameter(1.0, unit="m")
    L2 = Parameter(0.8, unit="m")
    m1 = Parameter(1.0, unit="kg")
    m2 = Parameter(0.5, unit="kg")
    g = Parameter(9.81, unit="m/s2")
    x1 = Variable(unit="m", start=1.0)
    y1 = Variable(unit="m", start=0.0, fixed=True)
    x2 = Variable(unit="m", start=1.8)
    y2 = Variable(unit="m", start=0.0, fixed=True)
    vx1 = Variable(unit="m/s", start=0.0)
    vy1 = Variable(unit="m/s", start=0.0, fixed=True)
    vx2 = Variable(unit="m/s", start=0.0)
    vy2 = Variable(unit="m/s", start=0.0, fixed=True)
    T1 = Variable(unit="N/m", description="Force per length in rod 1")
    T2 = Variable(unit="N/m", description="Force per length in rod 2")

    def equations(self):
        dx2, dy2 = self.x2 - self.x1, self.y2 - self.y1
        yield der(self.x1) == self.vx1
        yield der(self.y1) == self.vy1
        yield der(self.x2) == self.vx2
        yield der(self.y2) == self.vy2
        yield self.m1 * der(self.vx1) == -self.T1 * self.x1 + self.T2 * dx2
        yield self.m1 * der(self.vy1) == -self.T1 * self.y1 + self.T2 * dy2 - self.m1 * self.g
        yield self.m2 * der(self.vx2) == -self.T2 * dx2
        yield self.m2 * der(self.vy2) == -self.T2 * dy2 - self.m2 * self.g
        yield self.x1**2 + self.y1**2 == self.L1**2
        yield dx2**2 + dy2**2 == self.L2**2
