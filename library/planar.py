"""Planar (2-D) multibody mechanics, in the spirit of Modelica's PlanarMechanics library.

Connector :class:`Frame`: position ``x``, ``y`` [m] and orientation ``phi`` [rad] of a frame
in world coordinates (potentials); cut force ``fx``, ``fy`` [N] resolved in the *world* frame
and cut torque ``tau`` [N.m] about the frame origin (flows, positive *into* the component).
Gravity acts along ``-y`` with acceleration ``g`` [m/s2].

Rigid components write the kinematics at position level (``x_b = x_a + R(phi_a) r``); a chain
of bodies and joints is therefore a high-index DAE (Cartesian coordinates of every frame tied
by the joints), which the compiler reduces with Pantelides' algorithm and dummy derivatives.
Joint coordinates carry ``state_select=PREFER`` so they are chosen as states over the
Cartesian positions of the bodies (:class:`Body` positions have the default priority).

Components: :class:`World`, :class:`Fixed`, :class:`Body`, :class:`FixedTranslation`,
:class:`Revolute`, :class:`RelativeAngleSensor`, :class:`RelativeSpeedSensor`,
:class:`AbsoluteAngleSensor`, :class:`AbsolutePositionSensor`.

Gravity: there is no ``inner``/``outer`` in bgmodelica, so :class:`Body` has its own parameter
``g``; bind it to the world's (``Body(g=self.world.g)`` or to a top-level parameter) so one
value rules the whole model.
"""

from __future__ import annotations

from bgmodelica import (
    Component,
    Connector,
    Flow,
    Output,
    Parameter,
    Potential,
    StateSelect,
    Variable,
    cos,
    der,
    sin,
)

from .rotational import Flange

__all__ = ["Frame", "World", "Fixed", "Body", "FixedTranslation", "Revolute",
           "RelativeAngleSensor", "RelativeSpeedSensor", "AbsoluteAngleSensor",
           "AbsolutePositionSensor"]


class Frame(Connector):
    """Planar frame. Potentials ``x``, ``y`` [m], ``phi`` [rad] (world coordinates); flows
    ``fx``, ``fy`` [N] (world-resolved cut force) and ``tau`` [N.m], positive into the
    component."""

    x = Potential(unit="m", description="x position of the frame origin (world)")
    y = Potential(unit="m", description="y position of the frame origin (world)")
    phi = Potential(unit="rad", description="Orientation of the frame (world)")
    fx = Flow(unit="N", description="Cut force into the component, world x component")
    fy = Flow(unit="N", description="Cut force into the component, world y component")
    tau = Flow(unit="N.m", description="Cut torque into the component")


class Fixed(Component):
    """Frame fixed in the world at (``x0``, ``y0``) [m] with orientation ``phi0`` [rad].

    Connector: ``frame_b``. Parameters: x0 [m], y0 [m], phi0 [rad]. No states.
    """

    x0 = Parameter(0.0, unit="m", description="x position of the fixed frame")
    y0 = Parameter(0.0, unit="m", description="y position of the fixed frame")
    phi0 = Parameter(0.0, unit="rad", description="Orientation of the fixed frame")
    frame_b = Frame()

    def equations(self):
        yield self.frame_b.x == self.x0
        yield self.frame_b.y == self.y0
        yield self.frame_b.phi == self.phi0


class World(Fixed):
    """The inertial frame (origin, orientation 0) and the gravity field along ``-y``.

    Connector: ``frame_b``. Parameters: g [m/s2] gravity acceleration (bind the bodies' ``g``
    to it), x0, y0 [m], phi0 [rad] (default 0). No states.
    """

    g = Parameter(9.81, unit="m/s2", description="Gravity acceleration (along -y)")


class Body(Component):
    """Rigid body with mass ``m``, inertia ``I`` about its centre of mass, the centre of mass
    at (``rcx``, ``rcy``) [m] from ``frame_a``, in ``frame_a`` coordinates. Newton-Euler:

        m * der(vx) = frame_a.fx,   m * der(vy) = frame_a.fy - m*g,
        I * der(w)  = frame_a.tau + (r_a - r_cm) x f_a.

    Connector: ``frame_a``. Parameters: m [kg], I [kg.m2], rcx, rcy [m], g [m/s2].
    Variables: centre-of-mass position x, y [m], velocity vx, vy [m/s], acceleration ax, ay
    [m/s2], orientation phi [rad], angular speed w [rad/s] and acceleration z [rad/s2].
    Potential states (default priority): x, y, vx, vy, phi, w; in a jointed mechanism the
    joint coordinates are preferred and these become dummy derivatives.
    """

    m = Parameter(1.0, unit="kg", description="Mass")
    I = Parameter(0.1, unit="kg.m2", description="Moment of inertia about the centre of mass")
    rcx = Parameter(0.0, unit="m", description="Centre of mass from frame_a, x (body axes)")
    rcy = Parameter(0.0, unit="m", description="Centre of mass from frame_a, y (body axes)")
    g = Parameter(9.81, unit="m/s2", description="Gravity acceleration (along -y)")
    frame_a = Frame()
    x = Variable(unit="m", description="Centre of mass x position (world)")
    y = Variable(unit="m", description="Centre of mass y position (world)")
    vx = Variable(unit="m/s", description="Centre of mass velocity, x")
    vy = Variable(unit="m/s", description="Centre of mass velocity, y")
    ax = Variable(unit="m/s2", description="Centre of mass acceleration, x")
    ay = Variable(unit="m/s2", description="Centre of mass acceleration, y")
    phi = Variable(unit="rad", description="Orientation (world)")
    w = Variable(unit="rad/s", description="Angular speed")
    z = Variable(unit="rad/s2", description="Angular acceleration")

    def equations(self):
        fa = self.frame_a
        c, s = cos(fa.phi), sin(fa.phi)
        yield self.x == fa.x + c * self.rcx - s * self.rcy
        yield self.y == fa.y + s * self.rcx + c * self.rcy
        yield self.phi == fa.phi
        yield self.vx == der(self.x)
        yield self.vy == der(self.y)
        yield self.w == der(self.phi)
        yield self.ax == der(self.vx)
        yield self.ay == der(self.vy)
        yield self.z == der(self.w)
        yield self.m * self.ax == fa.fx
        yield self.m * self.ay == fa.fy - self.m * self.g
        yield self.I * self.z == fa.tau + (fa.x - self.x) * fa.fy - (fa.y - self.y) * fa.fx


class FixedTranslation(Component):
    """Massless rigid rod from ``frame_a`` to ``frame_b``: ``r_b = r_a + R(phi_a) (rx, ry)``,
    same orientation; force and moment balance.

    Connectors: ``frame_a``, ``frame_b``. Parameters: rx, ry [m] (vector a -> b in frame_a
    coordinates). No states.
    """

    rx = Parameter(1.0, unit="m", description="Vector frame_a -> frame_b, x (frame_a axes)")
    ry = Parameter(0.0, unit="m", description="Vector frame_a -> frame_b, y (frame_a axes)")
    frame_a = Frame()
    frame_b = Frame()

    def equations(self):
        fa, fb = self.frame_a, self.frame_b
        c, s = cos(fa.phi), sin(fa.phi)
        yield fb.x == fa.x + c * self.rx - s * self.ry
        yield fb.y == fa.y + s * self.rx + c * self.ry
        yield fb.phi == fa.phi
        yield 0 == fa.fx + fb.fx
        yield 0 == fa.fy + fb.fy
        yield 0 == fa.tau + fb.tau + (fb.x - fa.x) * fb.fy - (fb.y - fa.y) * fb.fx


class Revolute(Component):
    """Revolute joint: ``frame_b`` turns by ``q`` relative to ``frame_a`` about their common
    origin. The rotational ``flange`` drives the joint (``flange.phi = q``; a torque ``tau``
    pushed into ``flange`` acts on ``frame_b``'s side, its reaction on ``frame_a``'s side);
    an unconnected flange leaves the joint free.

    Connectors: ``frame_a``, ``frame_b`` (:class:`Frame`), ``flange``
    (:class:`library.rotational.Flange`). Variables: q [rad] joint angle, w [rad/s] joint
    speed, a [rad/s2] joint acceleration, tau [N.m] driving torque. States (PREFER): q, w.
    Start values: ``Revolute(q=0.3, w=0)`` fixes the initial joint angle / speed.
    """

    frame_a = Frame()
    frame_b = Frame()
    flange = Flange()
    q = Variable(unit="rad", description="Joint angle frame_b.phi - frame_a.phi",
                 state_select=StateSelect.PREFER)
    w = Variable(unit="rad/s", description="Joint speed", state_select=StateSelect.PREFER)
    a = Variable(unit="rad/s2", description="Joint acceleration")
    tau = Variable(unit="N.m", description="Driving torque applied through the flange")

    def equations(self):
        fa, fb = self.frame_a, self.frame_b
        yield self.q == fb.phi - fa.phi
        yield self.w == der(self.q)
        yield self.a == der(self.w)
        yield fb.x == fa.x
        yield fb.y == fa.y
        yield 0 == fa.fx + fb.fx
        yield 0 == fa.fy + fb.fy
        yield self.flange.phi == self.q
        yield self.tau == self.flange.tau
        yield fb.tau == -self.tau
        yield fa.tau == self.tau


class RelativeAngleSensor(Component):
    """Output ``phi_rel = frame_b.phi - frame_a.phi`` [rad]; no forces.
    Connectors: ``frame_a``, ``frame_b``."""

    frame_a = Frame()
    frame_b = Frame()
    phi_rel = Output(unit="rad", description="Relative angle frame_b - frame_a")

    def equations(self):
        for f in (self.frame_a, self.frame_b):
            yield f.fx == 0
            yield f.fy == 0
            yield f.tau == 0
        yield self.phi_rel == self.frame_b.phi - self.frame_a.phi


class RelativeSpeedSensor(Component):
    """Output ``w_rel = der(frame_b.phi - frame_a.phi)`` [rad/s]; no forces.
    Connectors: ``frame_a``, ``frame_b``."""

    frame_a = Frame()
    frame_b = Frame()
    w_rel = Output(unit="rad/s", description="Relative angular speed frame_b - frame_a")

    def equations(self):
        for f in (self.frame_a, self.frame_b):
            yield f.fx == 0
            yield f.fy == 0
            yield f.tau == 0
        yield self.w_rel == der(self.frame_b.phi) - der(self.frame_a.phi)


class AbsoluteAngleSensor(Component):
    """Output ``phi`` [rad] and ``w`` [rad/s]: orientation and angular speed of ``frame_a``
    in the world; no forces. Connector: ``frame_a``."""

    frame_a = Frame()
    phi = Output(unit="rad", description="Absolute orientation")
    w = Output(unit="rad/s", description="Absolute angular speed")

    def equations(self):
        yield self.frame_a.fx == 0
        yield self.frame_a.fy == 0
        yield self.frame_a.tau == 0
        yield self.phi == self.frame_a.phi
        yield self.w == der(self.frame_a.phi)


class AbsolutePositionSensor(Component):
    """Outputs ``x``, ``y`` [m]: position of ``frame_a`` in the world; no forces.
    Connector: ``frame_a``."""

    frame_a = Frame()
    x = Output(unit="m", description="Absolute x position")
    y = Output(unit="m", description="Absolute y position")

    def equations(self):
        yield self.frame_a.fx == 0
        yield self.frame_a.fy == 0
        yield self.frame_a.tau == 0
        yield self.x == self.frame_a.x
        yield self.y == self.frame_a.y
