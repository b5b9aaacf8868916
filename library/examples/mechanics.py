"""Rotational mechanics examples: a gear pair, a torsional oscillator."""

from __future__ import annotations

from bgmodelica import Component, connect
from library.rotational import ConstantTorque, Fixed, IdealGear, Inertia, Spring

__all__ = ["GearedInertias", "TorsionOscillator"]


class GearedInertias(Component):
    """A constant torque accelerates two inertias coupled by an ideal gear.

    motor_torque (tau = 2 N.m) -> input_shaft (J = 0.1 kg.m2, phi(0) = 0, w(0) = 0)
    -> gear (ratio = 4: input speed / output speed) -> output_shaft (J = 0.8 kg.m2).
    Reflected inertia J_eff = 0.1 + 0.8/4^2 = 0.15 kg.m2 at the input:
    ``input_shaft.w = tau*t/J_eff``, ``output_shaft.w = input_shaft.w/4``.
    """

    motor_torque = ConstantTorque(tau_constant=2.0)
    input_shaft = Inertia(J=0.1, phi=0.0, w=0.0)
    gear = IdealGear(ratio=4.0)
    output_shaft = Inertia(J=0.8)

    def equations(self):
        yield connect(self.motor_torque.flange, self.input_shaft.flange_a)
        yield connect(self.input_shaft.flange_b, self.gear.flange_a)
        yield connect(self.gear.flange_b, self.output_shaft.flange_a)


class TorsionOscillator(Component):
    """An inertia on a torsion spring to the housing, released from a twisted position.

    fixed -> spring (c = 4 N.m/rad) -> body (J = 0.01 kg.m2, phi(0) = 0.5 rad, w(0) = 0).
    Undamped: ``body.phi = 0.5*cos(w0*t)``, w0 = sqrt(c/J) = 20 rad/s, period 2*pi/w0 = 0.314 s.
    """

    fixed = Fixed()
    spring = Spring(c=4.0)
    body = Inertia(J=0.01, phi=0.5, w=0.0)

    def equations(self):
        yield connect(self.fixed.flange, self.spring.flange_a)
        yield connect(self.spring.flange_b, self.body.flange_a)
