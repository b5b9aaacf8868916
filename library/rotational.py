"""1-D rotational mechanics (Modelica.Mechanics.Rotational conventions).

Connector :class:`Flange`: potential ``phi`` [rad], flow ``tau`` [N.m] (positive into the
component). Speeds ``w`` [rad/s], accelerations ``a`` [rad/s2].

:class:`BearingFriction` is Coulomb friction with stiction in the MSL formulation
(``Interfaces.PartialFriction``): a stick/slip state machine of discrete variables (``mode``,
``locked``, ``startForward``, ``startBackward``) updated at state events.
"""

from __future__ import annotations

from bgmodelica import (
    Boolean,
    Component,
    Connector,
    Flow,
    Input,
    Integer,
    Output,
    Parameter,
    Potential,
    StateSelect,
    Variable,
    der,
    eq,
    if_else,
    pre,
)

from .friction import FORWARD, UNKNOWN, stick_slip_equations

__all__ = ["Flange", "PartialTwoFlanges", "Fixed", "Inertia", "Damper", "Spring",
           "SpringDamper", "IdealGear", "Torque", "ConstantTorque", "AngleSensor",
           "SpeedSensor", "TorqueSensor", "PartialFriction", "BearingFriction"]


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


# -- Coulomb friction (hybrid: events and pre()) ---------------------------------------------

# Friction modes UNKNOWN, FORWARD, STUCK, BACKWARD and the state machine: library.friction


class PartialFriction(Component):
    """Coulomb friction state machine of MSL ``Rotational.Interfaces.PartialFriction``.

    A subclass defines ``w_relfric`` [rad/s], ``a_relfric`` [rad/s2] (relative speed and
    acceleration of the frictional surfaces), ``tau0`` [N.m] (sliding friction torque at
    ``w_relfric = 0``) and ``tau0_max`` [N.m] (maximum static friction torque, ``>= tau0``),
    and the friction torque ``tau = sa*unitTorque`` [N.m] while ``locked``. This class gives
    the dimensionless path parameter ``sa`` of the characteristic, the Booleans
    ``startForward``, ``startBackward``, ``locked`` and the Integer ``mode`` (Forward = 1,
    Stuck = 0, Backward = -1; start value Unknown = 3). With T = tau/unitTorque,
    A = a_relfric/unitAngularAcceleration:

    - stuck: ``A = 0``; breakaway forward when ``sa > T0_max`` (and keeps starting while
      ``sa > T0``), backward when ``sa < -T0_max``;
    - sliding forward / backward: ``A = sa -+ T0_max``; sliding ends (mode Stuck) when
      ``w_relfric`` reaches 0; a speed jump of more than ``w_small`` [rad/s] against the
      sliding direction (only possible through ``reinit``) restarts sliding the other way.

    Parameters: w_small [rad/s]; unitTorque [N.m] = 1 and unitAngularAcceleration
    [rad/s2] = 1 only scale ``sa`` (MSL's protected constants; leave them at 1).
    """

    w_small = Parameter(1.0e10, unit="rad/s", description="Relative angular velocity near to "
                                                          "zero (if reinit() can make it jump)")
    unitTorque = Parameter(1.0, unit="N.m", description="Torque per unit of sa (keep 1)")
    unitAngularAcceleration = Parameter(1.0, unit="rad/s2", description="Angular acceleration "
                                                                        "per unit of sa "
                                                                        "(keep 1)")
    w_relfric = Variable(unit="rad/s", description="Relative angular velocity between the "
                                                   "frictional surfaces")
    a_relfric = Variable(unit="rad/s2", description="Relative angular acceleration between "
                                                    "the frictional surfaces")
    tau0 = Variable(unit="N.m", description="Friction torque for w_relfric = 0 and sliding")
    tau0_max = Variable(unit="N.m", description="Maximum friction torque for w_relfric = 0 "
                                                "and locked")
    sa = Variable(unit="1", description="Path parameter of the friction characteristic "
                                        "tau = tau(a_relfric)")
    startForward = Boolean(start=False, description="w_relfric = 0 and start of forward "
                                                    "sliding")
    startBackward = Boolean(start=False, description="w_relfric = 0 and start of backward "
                                                     "sliding")
    locked = Boolean(start=False, description="w_relfric = 0 and not sliding")
    mode = Integer(start=UNKNOWN, description="Mode of friction (-1: backward sliding, "
                                              "0: stuck, 1: forward sliding, 3: unknown)")

    def equations(self):
        # MSL: sa is dimensionless, scaled by unitTorque and unitAngularAcceleration
        yield from stick_slip_equations(
            self, self.w_relfric, self.a_relfric / self.unitAngularAcceleration,
            self.tau0 / self.unitTorque, self.tau0_max / self.unitTorque, self.w_small)


class BearingFriction(PartialTwoFlanges, PartialFriction):
    """Coulomb friction with stiction in a bearing (between the rigidly joined flanges and
    the housing).

    Friction torque ``tau`` [N.m] (against the speed ``w``): ``tau_c + tau_prop*w`` turning
    forward, ``-tau_c + tau_prop*w`` backward; while stuck (``w = 0``) ``tau`` balances the
    applied torque until it exceeds the breakaway torque ``tau_s`` (>= tau_c). Torque balance
    ``0 = flange_a.tau + flange_b.tau - tau``.

    Parameters: tau_c [N.m] Coulomb (sliding) friction torque, tau_s [N.m] static
    (breakaway) friction torque, tau_prop [N.m.s/rad] speed-proportional friction,
    w_small [rad/s]. Variables: phi [rad], w [rad/s], a [rad/s2], tau [N.m], mode (see
    :class:`PartialFriction`). Connectors: flange_a, flange_b. Connect it to an inertia (or
    through a spring), never directly to another friction element.
    """

    tau_c = Parameter(1.0, unit="N.m", description="Coulomb (sliding) friction torque",
                      min=0.0)
    tau_s = Parameter(1.0, unit="N.m", description="Static (breakaway) friction torque, "
                                                   ">= tau_c", min=0.0)
    tau_prop = Parameter(0.0, unit="N.m.s/rad", description="Speed-proportional friction",
                         min=0.0)
    phi = Variable(unit="rad", description="Absolute rotation angle of the flanges")
    w = Variable(unit="rad/s", description="Absolute angular speed of the flanges")
    a = Variable(unit="rad/s2", description="Absolute angular acceleration of the flanges")
    tau = Variable(unit="N.m", description="Friction torque (positive against w)")

    def equations(self):
        yield self.phi == self.flange_a.phi
        yield self.flange_a.phi == self.flange_b.phi
        yield self.w == der(self.phi)
        yield self.a == der(self.w)
        yield self.w_relfric == self.w
        yield self.a_relfric == self.a
        yield self.tau0 == self.tau_c
        yield self.tau0_max == self.tau_s
        yield 0 == self.flange_a.tau + self.flange_b.tau - self.tau
        forward = self.startForward | (~self.startBackward & eq(pre(self.mode), FORWARD))
        yield self.tau == if_else(self.locked, self.sa * self.unitTorque,
                                  self.tau_prop * self.w
                                  + if_else(forward, self.tau_c, -self.tau_c))
