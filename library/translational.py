"""1-D translational mechanics (Modelica.Mechanics.Translational conventions).

Connector :class:`Flange`: potential ``s`` [m] (absolute position), flow ``f`` [N] (cut force,
positive into the component). Speeds ``v`` [m/s], accelerations ``a`` [m/s2]. A positive
force on ``flange_b`` of a :class:`PartialCompliant` element pulls b in the positive direction
and the element pulls back with ``f``: ``f > 0`` means the element is in tension.

Hybrid elements (state events, ``pre()``, ``when``/``reinit``): Coulomb friction with stiction
in the MSL formulation (:class:`PartialFriction` stick/slip state machine; :class:`SupportFriction`,
:class:`MassWithFriction`) and hard stops (:class:`MassWithStopAndFriction`,
:class:`MassWithStop`: fully inelastic impact by ``reinit`` of position and velocity).
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
    reinit,
    when,
)

from .friction import FORWARD, UNKNOWN, stick_slip_equations

__all__ = ["Flange", "PartialTwoFlanges", "PartialCompliant", "PartialRigid", "Fixed", "Mass",
           "Rod", "Spring", "Damper", "SpringDamper", "Force", "ConstantForce",
           "PositionSensor", "SpeedSensor", "AccSensor", "ForceSensor", "PartialFriction",
           "SupportFriction", "MassWithFriction", "MassWithStopAndFriction", "MassWithStop"]


class Flange(Connector):
    """Translational flange. Potential ``s`` [m]; flow ``f`` [N] into the component."""

    s = Potential(unit="m", description="Absolute position of the flange")
    f = Flow(unit="N", description="Cut force into the component")


class PartialTwoFlanges(Component):
    """Two flanges ``flange_a`` (left) and ``flange_b`` (right)."""

    flange_a = Flange()
    flange_b = Flange()


class PartialCompliant(PartialTwoFlanges):
    """Massless compliant element between ``flange_a`` and ``flange_b``.

    Relative position ``s_rel = flange_b.s - flange_a.s`` [m] and force ``f`` [N] from a to b:
    ``flange_b.f = f``, ``flange_a.f = -f`` (``f > 0``: tension).
    """

    s_rel = Variable(unit="m", description="Relative distance flange_b.s - flange_a.s")
    f = Variable(unit="N", description="Force between the flanges (positive in tension)")

    def equations(self):
        yield self.s_rel == self.flange_b.s - self.flange_a.s
        yield self.flange_b.f == self.f
        yield self.flange_a.f == -self.f


class PartialRigid(PartialTwoFlanges):
    """Rigid body of length ``L`` [m] with centre position ``s`` [m]:
    ``flange_a.s = s - L/2``, ``flange_b.s = s + L/2``."""

    L = Parameter(0.0, unit="m", description="Length of the component, from flange_a to "
                                             "flange_b")
    s = Variable(unit="m", description="Absolute position of the centre of the component",
                 state_select=StateSelect.PREFER)

    def equations(self):
        yield self.flange_a.s == self.s - self.L / 2
        yield self.flange_b.s == self.s + self.L / 2


class Fixed(Component):
    """Flange fixed to the housing at position ``s0`` [m]. Connector: ``flange``."""

    s0 = Parameter(0.0, unit="m", description="Fixed offset position of the housing")
    flange = Flange()

    def equations(self):
        yield self.flange.s == self.s0


class Mass(PartialRigid):
    """Sliding mass ``m*a = flange_a.f + flange_b.f``.

    Parameters: m [kg], L [m] length (flanges at ``s -+ L/2``). States: s [m], v [m/s].
    Connectors: flange_a, flange_b.
    """

    m = Parameter(1.0, unit="kg", description="Mass of the sliding mass")
    v = Variable(unit="m/s", description="Absolute velocity of the component",
                 state_select=StateSelect.PREFER)
    a = Variable(unit="m/s2", description="Absolute acceleration of the component")

    def equations(self):
        yield self.v == der(self.s)
        yield self.a == der(self.v)
        yield self.m * self.a == self.flange_a.f + self.flange_b.f


class Rod(PartialRigid):
    """Massless rigid rod of length ``L`` [m]: ``0 = flange_a.f + flange_b.f``.
    Connectors: flange_a, flange_b."""

    def equations(self):
        yield 0 == self.flange_a.f + self.flange_b.f


class Spring(PartialCompliant):
    """Linear spring ``f = c*(s_rel - s_rel0)``.

    Parameters: c [N/m], s_rel0 [m] unstretched length. Connectors: flange_a, flange_b.
    """

    c = Parameter(1.0, unit="N/m", description="Spring constant", min=0.0)
    s_rel0 = Parameter(0.0, unit="m", description="Unstretched spring length")

    def equations(self):
        yield self.f == self.c * (self.s_rel - self.s_rel0)


class Damper(PartialCompliant):
    """Linear damper ``f = d*v_rel``, ``v_rel = der(s_rel)``.

    Parameter: d [N.s/m]. Connectors: flange_a, flange_b.
    """

    d = Parameter(0.0, unit="N.s/m", description="Damping constant", min=0.0)
    v_rel = Variable(unit="m/s", description="Relative velocity der(s_rel)")

    def equations(self):
        yield self.v_rel == der(self.s_rel)
        yield self.f == self.d * self.v_rel


class SpringDamper(PartialCompliant):
    """Linear spring and damper in parallel: ``f = c*(s_rel - s_rel0) + d*v_rel``.

    Parameters: c [N/m], d [N.s/m], s_rel0 [m] unstretched length. Connectors: flange_a,
    flange_b.
    """

    c = Parameter(1.0, unit="N/m", description="Spring constant", min=0.0)
    d = Parameter(0.0, unit="N.s/m", description="Damping constant", min=0.0)
    s_rel0 = Parameter(0.0, unit="m", description="Unstretched spring length")
    v_rel = Variable(unit="m/s", description="Relative velocity der(s_rel)")

    def equations(self):
        yield self.v_rel == der(self.s_rel)
        yield self.f == self.c * (self.s_rel - self.s_rel0) + self.d * self.v_rel


class Force(Component):
    """Force source driven by the signal ``f`` [N], acting on ``flange``
    (``flange.f = -f``: a positive signal pushes the connected mass in +s)."""

    f = Input(unit="N", description="Driving force")
    flange = Flange()

    def equations(self):
        yield self.flange.f == -self.f


class ConstantForce(Component):
    """Constant force ``f_constant`` [N] acting on ``flange`` (positive: pushes in +s).
    Connector: flange."""

    f_constant = Parameter(1.0, unit="N", description="Driving force")
    flange = Flange()

    def equations(self):
        yield self.flange.f == -self.f_constant


class PositionSensor(Component):
    """Ideal position sensor: output ``s`` [m] of ``flange``."""

    flange = Flange()
    s = Output(unit="m", description="Measured absolute position")

    def equations(self):
        yield self.flange.f == 0
        yield self.s == self.flange.s


class SpeedSensor(Component):
    """Ideal speed sensor: output ``v`` [m/s] of ``flange``."""

    flange = Flange()
    v = Output(unit="m/s", description="Measured absolute velocity")

    def equations(self):
        yield self.flange.f == 0
        yield self.v == der(self.flange.s)


class AccSensor(Component):
    """Ideal acceleration sensor: output ``a`` [m/s2] of ``flange``."""

    flange = Flange()
    v = Variable(unit="m/s", description="Absolute velocity of the flange")
    a = Output(unit="m/s2", description="Measured absolute acceleration")

    def equations(self):
        yield self.flange.f == 0
        yield self.v == der(self.flange.s)
        yield self.a == der(self.v)


class ForceSensor(PartialTwoFlanges):
    """Ideal force sensor between its flanges: output ``f`` [N], the force that flange_a
    exerts on whatever is connected to flange_b (``flange_a.f = f``, ``flange_b.f = -f``)."""

    f = Output(unit="N", description="Measured force a -> b")

    def equations(self):
        yield self.flange_a.s == self.flange_b.s
        yield self.flange_a.f == self.f
        yield self.flange_b.f == -self.f


# -- Coulomb friction and hard stops (hybrid: events, pre(), when/reinit) --------------------

# Friction modes UNKNOWN, FORWARD, STUCK, BACKWARD and the state machine: library.friction


class PartialFriction(Component):
    """Coulomb friction state machine of MSL ``Translational.Interfaces.PartialFriction``.

    A subclass defines ``v_relfric`` [m/s], ``a_relfric`` [m/s2] (relative velocity and
    acceleration of the frictional surfaces), ``f0`` [N] (sliding friction force at
    ``v_relfric = 0``) and ``f0_max`` [N] (maximum static friction force, ``>= f0``), and the
    friction force ``f = sa*unitForce`` [N] while ``locked``. This class gives the
    dimensionless path parameter ``sa`` of the characteristic, the Booleans ``startForward``,
    ``startBackward``, ``locked`` and the Integer ``mode`` (Forward = 1, Stuck = 0,
    Backward = -1; start value Unknown = 3). With F = f/unitForce, A = a_relfric/unitAcceleration:

    - stuck: ``A = 0``; the element breaks away forward when ``sa > F0_max`` (and keeps
      starting while ``sa > F0``), backward when ``sa < -F0_max``;
    - sliding forward / backward: ``A = sa -+ F0_max``; sliding ends (mode Stuck) when
      ``v_relfric`` reaches 0; a velocity jump of more than ``v_small`` [m/s] against the
      sliding direction restarts sliding the other way.

    Parameters: v_small [m/s]; unitForce [N] = 1 and unitAcceleration [m/s2] = 1 only scale
    ``sa`` (MSL's protected constants; leave them at 1).

    Override ``_forward_allowed()`` / ``_backward_allowed()`` (Boolean expressions) to block
    sliding in one direction (hard stops).
    """

    v_small = Parameter(1e-3, unit="m/s", description="Relative velocity near to zero")
    unitForce = Parameter(1.0, unit="N", description="Force per unit of sa (keep 1)")
    unitAcceleration = Parameter(1.0, unit="m/s2", description="Acceleration per unit of sa "
                                                               "(keep 1)")
    v_relfric = Variable(unit="m/s", description="Relative velocity between the frictional "
                                                 "surfaces")
    a_relfric = Variable(unit="m/s2", description="Relative acceleration between the "
                                                  "frictional surfaces")
    f0 = Variable(unit="N", description="Friction force for v_relfric = 0 and sliding")
    f0_max = Variable(unit="N", description="Maximum friction force for v_relfric = 0 and "
                                            "locked")
    sa = Variable(unit="1", description="Path parameter of the friction characteristic "
                                        "f = f(a_relfric)")
    startForward = Boolean(start=False, description="v_relfric = 0 and start of forward "
                                                    "sliding")
    startBackward = Boolean(start=False, description="v_relfric = 0 and start of backward "
                                                     "sliding")
    locked = Boolean(start=False, description="v_relfric = 0 and not sliding")
    mode = Integer(start=UNKNOWN, description="Mode of friction (-1: backward sliding, "
                                              "0: stuck, 1: forward sliding, 3: unknown)")

    def _forward_allowed(self):
        return None

    def _backward_allowed(self):
        return None

    def equations(self):
        # MSL: sa is dimensionless, scaled by unitForce and unitAcceleration
        yield from stick_slip_equations(
            self, self.v_relfric, self.a_relfric / self.unitAcceleration,
            self.f0 / self.unitForce, self.f0_max / self.unitForce, self.v_small,
            self._forward_allowed(), self._backward_allowed())

    def _friction_force(self, v):
        """Friction force [N] (opposing v_relfric): ``sa*unitForce`` while locked, else
        ``+-F_c + F_prop*v`` in the sliding (or starting) direction (subclasses declare F_c
        and F_prop)."""
        forward = self.startForward | (~self.startBackward & eq(pre(self.mode), FORWARD))
        return if_else(self.locked, self.sa * self.unitForce,
                       self.F_prop * v + if_else(forward, self.F_c, -self.F_c))


class SupportFriction(PartialTwoFlanges, PartialFriction):
    """Coulomb friction with stiction between the rigidly joined flanges and the housing.

    Friction force ``f`` [N] (opposing the velocity ``v``): ``F_c + F_prop*v`` sliding
    forward, ``-F_c + F_prop*v`` backward; while stuck (``v = 0``) ``f`` balances the applied
    force until it exceeds the breakaway force ``F_s`` (>= F_c). Force balance
    ``0 = flange_a.f + flange_b.f - f``.

    Parameters: F_c [N] Coulomb (sliding) friction force, F_s [N] static (breakaway) friction
    force, F_prop [N.s/m] velocity-proportional friction, v_small [m/s]. Variables: s [m],
    v [m/s], a [m/s2], f [N], mode (see :class:`PartialFriction`). Connectors: flange_a,
    flange_b. Connect it to a mass (or through a spring), never directly to another friction
    element.
    """

    F_c = Parameter(1.0, unit="N", description="Coulomb (sliding) friction force", min=0.0)
    F_s = Parameter(1.0, unit="N", description="Static (breakaway) friction force, >= F_c",
                    min=0.0)
    F_prop = Parameter(0.0, unit="N.s/m", description="Velocity-proportional friction",
                       min=0.0)
    s = Variable(unit="m", description="Absolute position of the flanges")
    v = Variable(unit="m/s", description="Absolute velocity of the flanges")
    a = Variable(unit="m/s2", description="Absolute acceleration of the flanges")
    f = Variable(unit="N", description="Friction force (positive against v)")

    def equations(self):
        yield self.s == self.flange_a.s
        yield self.flange_a.s == self.flange_b.s
        yield self.v == der(self.s)
        yield self.a == der(self.v)
        yield self.v_relfric == self.v
        yield self.a_relfric == self.a
        yield self.f0 == self.F_c
        yield self.f0_max == self.F_s
        yield 0 == self.flange_a.f + self.flange_b.f - self.f
        yield self.f == self._friction_force(self.v)


class MassWithFriction(PartialRigid, PartialFriction):
    """Sliding mass on a surface with Coulomb friction and stiction.

    ``m*a = flange_a.f + flange_b.f - f``; friction force ``f`` [N] (against ``v``) as in
    :class:`SupportFriction`: ``+-F_c + F_prop*v`` sliding, the balancing force while stuck,
    breakaway when it exceeds ``F_s``.

    Parameters: m [kg], L [m], F_c [N] Coulomb friction force, F_s [N] static (breakaway)
    friction force (>= F_c), F_prop [N.s/m] velocity-proportional friction, v_small [m/s].
    States: s [m], v [m/s]. Discrete: mode (Forward 1, Stuck 0, Backward -1), locked,
    startForward, startBackward. Connectors: flange_a, flange_b.
    """

    m = Parameter(1.0, unit="kg", description="Mass of the sliding mass")
    F_c = Parameter(1.0, unit="N", description="Coulomb (sliding) friction force", min=0.0)
    F_s = Parameter(1.0, unit="N", description="Static (breakaway) friction force, >= F_c",
                    min=0.0)
    F_prop = Parameter(0.0, unit="N.s/m", description="Velocity-proportional friction",
                       min=0.0)
    v = Variable(unit="m/s", description="Absolute velocity of the component",
                 state_select=StateSelect.ALWAYS)
    a = Variable(unit="m/s2", description="Absolute acceleration of the component")
    f = Variable(unit="N", description="Friction force (positive against v)")

    def equations(self):
        yield self.v == der(self.s)
        yield self.a == der(self.v)
        yield self.v_relfric == self.v
        yield self.a_relfric == self.a
        yield self.f0 == self.F_c
        yield self.f0_max == self.F_s
        yield self.m * self.a == self.flange_a.f + self.flange_b.f - self.f
        yield self.f == self._friction_force(self.v)


class MassWithStopAndFriction(MassWithFriction):
    """:class:`MassWithFriction` between hard stops: ``smin <= flange_a.s`` and
    ``flange_b.s <= smax`` (centre ``s`` in ``[smin + L/2, smax - L/2]``).

    Reaching a stop is a fully inelastic impact: ``reinit(s, stop)``, ``reinit(v, 0)``; the
    mass then stays stuck at the stop until the applied force pulls it away (beyond the
    breakaway force ``F_s``). Integer ``stopped``: -1 at smin, +1 at smax, 0 between.

    Parameters: m [kg], L [m], smin [m], smax [m], F_c [N], F_s [N], F_prop [N.s/m],
    v_small [m/s]. States: s [m], v [m/s]. Connectors: flange_a, flange_b.
    """

    smin = Parameter(-25.0, unit="m", description="Left stop for flange_a")
    smax = Parameter(25.0, unit="m", description="Right stop for flange_b")
    s = Variable(unit="m", description="Absolute position of the centre of the component",
                 state_select=StateSelect.ALWAYS)
    stopped = Integer(start=0, description="Hard stop: -1 at smin, 0 none, +1 at smax")

    def _forward_allowed(self):
        return self.s < self.smax - self.L / 2

    def _backward_allowed(self):
        return self.s > self.smin + self.L / 2

    def equations(self):
        lo, hi = self.smin + self.L / 2, self.smax - self.L / 2
        yield self.stopped == if_else(self.s <= lo, -1, if_else(self.s >= hi, 1, 0))
        yield when(~eq(self.stopped, 0),
                   reinit(self.s, if_else(eq(self.stopped, -1), lo, hi)),
                   reinit(self.v, 0.0))


class MassWithStop(MassWithStopAndFriction):
    """Sliding mass between hard stops ``smin <= flange_a.s``, ``flange_b.s <= smax``,
    without friction (inelastic impact: ``reinit(s, stop)``, ``reinit(v, 0)``; the mass stays
    at a stop while the applied force pushes into it and leaves it when the force reverses).

    Parameters: m [kg], L [m], smin [m], smax [m]. States: s [m], v [m/s].
    Connectors: flange_a, flange_b.
    """

    F_c = Parameter(0.0, unit="N", description="Coulomb (sliding) friction force", min=0.0)
    F_s = Parameter(0.0, unit="N", description="Static (breakaway) friction force, >= F_c",
                    min=0.0)
