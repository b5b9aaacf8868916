"""The paper's armature-controlled DC motor with gear (Sec. 3, Eq. 5-7; bond graph Fig. 6-7)
in component form:

    U = R i + L di/dt + E,  E = k1 w_m,  tau_m = k1 i,
    Jm dw_m/dt = tau_m - b w_m - tau_a / k2,  w_m = k2 w_a,  tau_a = k2 (motor-side torque).

SignalVoltage (``u``) -> Resistor R -> Inductor L -> EMF k1 -> ground; EMF flange (with the
rotor Inertia Jm and a Damper b to the housing) -> IdealGear k2 -> ``flange`` (joint side).
"""

from __future__ import annotations

from typing import Any

from bgmodelica import Component, Input, Output, Parameter, StateSelect, connect
from library.electrical import EMF, Ground, Inductor, Resistor, SignalVoltage
from library.rotational import Damper, Fixed, Flange, IdealGear, Inertia

from .params import MOTOR

__all__ = ["GearedMotor", "DCMotor"]

_DEFAULT = dict(state_select=StateSelect.DEFAULT)


class GearedMotor(Component):
    """Geared DC motor driven by a voltage signal, *without* rotor inertia (for a split where
    the rotor inertia k2^2 Jm is lumped into the joint it drives rigidly).

    Connectors: ``u`` (Input, armature voltage [V]), ``flange`` (rotational, joint side of the
    gear). Outputs: ``i`` armature current [A], ``w_m`` rotor speed [rad/s].
    Parameters: R [Ohm], L [H], k1 [N.m/A] torque / back-EMF constant, b [N.m.s/rad] rotor
    viscous friction, k2 [1] gear ratio (w_m = k2 * joint speed, joint torque = k2 *
    motor-side torque). Defaults: :data:`library.robots.params.MOTOR`. State: inductor.i [A]
    (fixed start 0).
    """

    R = Parameter(MOTOR["R"], unit="Ohm", description="Armature resistance")
    L = Parameter(MOTOR["L"], unit="H", description="Armature inductance")
    k1 = Parameter(MOTOR["k1"], unit="N.m/A", description="Torque / back-EMF constant")
    b = Parameter(MOTOR["b"], unit="N.m.s/rad", description="Rotor viscous friction")
    k2 = Parameter(MOTOR["k2"], unit="1", description="Gear ratio w_motor / w_joint")
    u = Input(unit="V", description="Armature voltage command")
    i = Output(unit="A", description="Armature current")
    w_m = Output(unit="rad/s", description="Rotor speed")
    flange = Flange()

    def __init__(self, name: str | None = None, **modifiers: Any):
        super().__init__(name, **modifiers)
        self.source = SignalVoltage()
        self.resistor = Resistor(R=self.R)
        self.inductor = Inductor(L=self.L, i=0.0)
        self.emf = EMF(k=self.k1)
        self.ground = Ground()
        self.friction = Damper(d=self.b)
        self.housing = Fixed()
        self.gear = IdealGear(ratio=self.k2)

    def equations(self):
        yield connect(self.u, self.source.u)
        yield connect(self.source.p, self.resistor.p)
        yield connect(self.resistor.n, self.inductor.p)
        yield connect(self.inductor.n, self.emf.p)
        yield connect(self.emf.n, self.source.n)
        yield connect(self.source.n, self.ground.p)
        yield connect(self.emf.flange, self.gear.flange_a)
        yield connect(self.friction.flange_a, self.housing.flange)
        yield connect(self.friction.flange_b, self.emf.flange)
        yield connect(self.gear.flange_b, self.flange)
        yield self.i == self.inductor.i
        yield self.w_m == self.emf.w


class DCMotor(GearedMotor):
    """Geared DC motor driven by a voltage signal: :class:`GearedMotor` plus the rotor
    inertia Jm [kg.m2] on the motor shaft.

    States: inductor.i [A] (fixed start 0); the rotor angle/speed are tied to the joint by the
    gear, so the joint's coordinates are preferred as states (rotor state_select DEFAULT).
    """

    Jm = Parameter(MOTOR["Jm"], unit="kg.m2", description="Rotor inertia")

    def __init__(self, name: str | None = None, **modifiers: Any):
        super().__init__(name, **modifiers)
        self.rotor = Inertia(J=self.Jm, phi=dict(_DEFAULT), w=dict(_DEFAULT))

    def equations(self):
        yield connect(self.rotor.flange_a, self.emf.flange)
