"""1-D rotational mechanics (Modelica.Mechanics.Rotational conventions).

Connector :class:`Flange`: potential ``phi`` [rad], flow ``tau`` [N.m] (positive into the
component). Speeds ``w`` [rad/s], accelerations ``a`` [rad/s2].
"""

from __future__ import annotations

from bgmodelica import (
    Component,
    Connector,
    Flow,
    Input,
    Output,
    Parameter,
    Potential,
    StateSelect,
    Variable,
    der,
)

__all__ = ["Flange", "PartialTwoFlanges", "Fixed", "Inertia", "Damper", "Spring",
           "SpringDamper", "IdealGear", "Torque", "ConstantTorque", "AngleSensor",
           "SpeedSensor", "TorqueSensor"]


class Flange(Connector):
    """Rotational flange. Potential ``phi`` [rad]; flow ``tau`` [N.m] into the component."""

    phi = Potential(unit="rad", description="Absolute rotation angle")
    tau = Flow(unit="N.m", description="Cut torque into the component")


class PartialTwoFlanges(Component):
    """Two flanges ``flange_a`` and ``flange_b``."""

    flange_a = Flange()
    flange_b = Flange()


class PartialCompliant(PartialTwoFlanges):
    """Relative angle ``phi_rel = flange_b.phi - flange_a.phi`` [rad] and torque ``tau`` [N.m]
    from a to b: ``flange_b.tau = tau``, ``flange_a.tau = -tau``."""

    phi_rel = Variable(unit="rad", description="Relative rotation angle b - a")
    tau = Variable(unit="N.m", description="Torque transmitted a -> b")

    def equations(self):
        yield self.phi_rel == self.flange_b.phi - self.flange_a.phi
        yield self.flange_b.tau == self.tau
        yield self.flange_a.tau == -self.tau


class Fixed(Component):
    """Flange fixed to the housing at angle ``phi0`` [rad]. Connector: ``flange``."""

    phi0 = Parameter(0.0, unit="rad", description="Fixed angle")
    flange = Flange()

    def equations(self):
        yield self.flange.phi == self.phi0


class Inertia(PartialTwoFlanges):
    """Rigid rotating body ``J*a = flange_a.tau + flange_b.tau``.

    Parameter: J [kg.m2]. States: phi [rad], w [rad/s]. Connectors: flange_a, flange_b.
    """

    J = Parameter(1.0, unit="kg.m2", description="Moment of inertia")
    phi = Variable(unit="rad", description="Absolute rotation angle",
                   state_select=StateSelect.PREFER)
    w = Variable(unit="rad/s", description="Absolute angular speed",
                 state_select=StateSelect.PREFER)
    a = Variable(unit="rad/s2", description="Absolute angular acceleration")

    def equations(self):
        yield self.phi == self.flange_a.phi
        yield self.phi == self.flange_b.phi
        yield self.w == der(self.phi)
        yield self.a == der(self.w)
        yield self.J * self.a == self.flange_a.tau + self.flange_b.tau


class Damper(PartialCompliant):
    """Linear rotational damper ``tau = d * der(phi_rel)``. Parameter: d [N.m.s/rad]."""

    d = Parameter(0.0, unit="N.m.s/rad", description="Damping constant")

    def equations(self):
        yield self.tau == self.d * der(self.phi_rel)


class Spring(PartialCompliant):
    """Linear rotational spring ``tau = c*(phi_rel - phi_rel0)``.

    Parameters: c [N.m/rad], phi_rel0 [rad] unstretched angle.
    """

    c = Parameter(1.0, unit="N.m/rad", description="Spring constant")
    phi_rel0 = Parameter(0.0, unit="rad", description="Unstretched relative angle")

    def equations(self):
        yield self.tau == self.c * (self.phi_rel - self.phi_rel0)


class SpringDamper(PartialCompliant):
    """Spring and damper in parallel. Parameters: c [N.m/rad], d [N.m.s/rad], phi_rel0 [rad]."""

    c = Parameter(1.0, unit="N.m/rad", description="Spring constant")
    d = Parameter(0.0, unit="N.m.s/rad", description="Damping constant")
    phi_rel0 = Parameter(0.0, unit="rad", description="Unstretched relative angle")

    def equations(self):
        yield self.tau == self.c * (self.phi_rel - self.phi_rel0) + self.d * der(self.phi_rel)


class IdealGear(PartialTwoFlanges):
    """Ideal gear ``flange_a.phi = ratio * flange_b.phi``, ``0 = ratio*flange_a.tau +
    flange_b.tau``. Parameter: ratio [1] (input speed / output speed)."""

    ratio = Parameter(1.0, unit="1", description="Transmission ratio w_a / w_b")

    def equations(self):
        yield self.flange_a.phi == self.ratio * self.flange_b.phi
        yield 0 == self.ratio * self.flange_a.tau + self.flange_b.tau


class Torque(Component):
    """Torque source driven by the signal ``tau`` [N.m], acting on ``flange``
    (``flange.tau = -tau``: a positive signal accelerates the connected inertia)."""

    tau = Input(unit="N.m", description="Driving torque")
    flange = Flange()

    def equations(self):
        yield self.flange.tau == -self.tau


class ConstantTorque(Component):
    """Constant torque ``tau_constant`` [N.m] acting on ``flange``."""

    tau_constant = Parameter(1.0, unit="N.m", description="Driving torque")
    flange = Flange()

    def equations(self):
        yield self.flange.tau == -self.tau_constant


class AngleSensor(Component):
    """Ideal angle sensor: output ``phi`` [rad] of ``flange``."""

    flange = Flange()
    phi = Output(unit="rad", description="Measured absolute angle")

    def equations(self):
        yield self.flange.tau == 0
        yield self.phi == self.flange.phi


class SpeedSensor(Component):
    """Ideal speed sensor: output ``w`` [rad/s] of ``flange``."""

    flange = Flange()
    w = Output(unit="rad/s", description="Measured absolute speed")

    def equations(self):
        yield self.flange.tau == 0
        yield self.w == der(self.flange.phi)


class TorqueSensor(PartialTwoFlanges):
    """Ideal torque sensor between its flanges: output ``tau`` [N.m] (a -> b)."""

    tau = Output(unit="N.m", description="Measured torque")

    def equations(self):
        yield self.flange_a.phi == self.flange_b.phi
        yield self.flange_a.tau == self.tau
        yield self.flange_b.tau == -self.tau
