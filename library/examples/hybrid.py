"""Hybrid example models (events): a bouncing ball, stick-slip friction, a PWM-driven motor.

Each is an acceptance case with fixed parameter and variable names (SI units); see
``docs/guide/hybrid-models.md`` for the semantics of events, ``when`` and ``pre``.
"""

from __future__ import annotations

import math

from bgmodelica import (
    Boolean,
    Component,
    Discrete,
    Integer,
    Parameter,
    StateSelect,
    Variable,
    connect,
    der,
    eq,
    fabs,
    if_else,
    initial,
    pre,
    reinit,
    sample,
    sin,
    time,
    when,
)
from library.electrical import Capacitor, Ground, IdealDiode, Resistor, SineVoltage

__all__ = ["BouncingBall", "StickSlip", "PWMMotor", "PendulumWall", "HalfWaveRectifier"]


class BouncingBall(Component):
    """A ball dropped on a rigid floor.

    der(h) = v, der(v) = -g while flying. When h crosses 0 going down, v := -e*pre(v); if that
    new speed is below ``v_min`` the ball comes to rest (h = 0, v = 0, no more events).

    Parameters: h0 [m] (start height), v0 [m/s] (start speed, up positive), e [1]
    (restitution), g [m/s2], v_min [m/s]. Variables: h [m], v [m/s]; Boolean ``flying``.
    States: h, v.
    """

    h0 = Parameter(1.0, unit="m", description="Start height")
    v0 = Parameter(0.0, unit="m/s", description="Start speed (up positive)")
    e = Parameter(0.7, unit="1", description="Coefficient of restitution")
    g = Parameter(9.81, unit="m/s2", description="Gravity")
    v_min = Parameter(0.1, unit="m/s", description="Bounce speed below which the ball rests")
    h = Variable(unit="m", start=1.0, fixed=True, description="Height above the floor")
    v = Variable(unit="m/s", start=0.0, fixed=True, description="Vertical speed")
    flying = Boolean(start=True, description="False once the ball rests")

    def equations(self):
        yield der(self.h) == self.v
        yield der(self.v) == if_else(self.flying, -self.g, 0.0)
        bounce = -self.e * pre(self.v)
        yield when(initial(), reinit(self.h, self.h0), reinit(self.v, self.v0))
        yield when(self.h < 0,
                   self.flying == (bounce >= self.v_min),
                   reinit(self.v, if_else(bounce >= self.v_min, bounce, 0.0)),
                   reinit(self.h, 0.0))


class StickSlip(Component):
    """A mass on the ground pushed by F = F0 sin(2 pi f t), with Coulomb friction and stiction.

    Sliding: m der(v) = F - F_c sign(v). Stuck (v = 0) while |F| <= F_s; when stuck and
    |F| > F_s it breaks away in the direction of F; when sliding and v reaches 0 it sticks if
    |F| <= F_s, else it reverses. ``mode``: 1 forward, -1 backward, 0 stuck.

    Parameters: m [kg], F0 [N], f [Hz], F_c [N] (sliding friction), F_s [N] (stiction limit).
    Variables: x [m], v [m/s], F [N], a [m/s2]; Integer ``mode``. States: x, v.
    """

    m = Parameter(1.0, unit="kg", description="Mass")
    F0 = Parameter(6.0, unit="N", description="Force amplitude")
    f = Parameter(0.5, unit="Hz", description="Force frequency")
    F_c = Parameter(3.0, unit="N", description="Sliding (Coulomb) friction force")
    F_s = Parameter(4.0, unit="N", description="Stiction limit (breakaway force)")
    x = Variable(unit="m", start=0.0, fixed=True, description="Position")
    v = Variable(unit="m/s", start=0.0, fixed=True, description="Speed")
    F = Variable(unit="N", description="Applied force")
    a = Variable(unit="m/s2", description="Acceleration")
    mode = Integer(start=0, description="1 forward, 0 stuck, -1 backward")

    def equations(self):
        yield self.F == self.F0 * sin(2 * math.pi * self.f * time)
        yield der(self.x) == self.v
        yield der(self.v) == self.a
        yield self.m * self.a == if_else(eq(self.mode, 0), 0.0,
                                          self.F - self.F_c * self.mode)
        stuck, fwd, bwd = eq(self.mode, 0), eq(self.mode, 1), eq(self.mode, -1)
        holds = fabs(self.F) <= self.F_s
        yield (when(stuck & (self.F > self.F_s), self.mode == 1)
               .elsewhen(stuck & (self.F < -self.F_s), self.mode == -1)
               .elsewhen(fwd & (self.v < 0), self.mode == if_else(holds, 0, -1),
                         reinit(self.v, 0.0))
               .elsewhen(bwd & (self.v > 0), self.mode == if_else(holds, 0, 1),
                         reinit(self.v, 0.0)))


class PWMMotor(Component):
    """A DC motor without load fed by a PWM voltage.

    U = Vs while frac(t*f_pwm) < duty, else 0: the period starts at ``sample(0, 1/f_pwm)``
    and switches off at the time event period start + duty/f_pwm. Motor:
    L der(i) = U - R i - k w, J der(w) = k i - b w.

    Parameters: R [Ohm], L [H], k [N.m/A], J [kg.m2], b [N.m.s/rad], Vs [V], f_pwm [Hz],
    duty [1]. Variables: i [A], w [rad/s], U [V]; Discrete ``period_start`` [s].
    States: i, w.
    """

    R = Parameter(1.0, unit="Ohm", description="Armature resistance")
    L = Parameter(1e-3, unit="H", description="Armature inductance")
    k = Parameter(0.05, unit="N.m/A", description="Torque and back-EMF constant")
    J = Parameter(2e-5, unit="kg.m2", description="Rotor inertia")
    b = Parameter(1e-5, unit="N.m.s/rad", description="Viscous friction")
    Vs = Parameter(24.0, unit="V", description="Supply voltage")
    f_pwm = Parameter(20e3, unit="Hz", description="PWM frequency")
    duty = Parameter(0.6, unit="1", description="Duty cycle")
    i = Variable(unit="A", start=0.0, fixed=True, description="Armature current")
    w = Variable(unit="rad/s", start=0.0, fixed=True, description="Rotor speed")
    U = Variable(unit="V", description="Armature voltage")
    period_start = Discrete(unit="s", start=0.0, description="Start of the current PWM period")

    def equations(self):
        yield when(sample(0.0, 1.0 / self.f_pwm), self.period_start == time)
        yield self.U == if_else(time < self.period_start + self.duty / self.f_pwm,
                                self.Vs, 0.0)
        yield self.L * der(self.i) == self.U - self.R * self.i - self.k * self.w
        yield self.J * der(self.w) == self.k * self.i - self.b * self.w


class PendulumWall(Component):
    """The Cartesian pendulum (index 3) swinging against a vertical wall at ``x = x_wall``.

    When the mass reaches the wall moving towards it, both velocity components are reversed
    and scaled by ``e`` (the angular velocity jumps to -e times its value; the rod constraint
    still holds). Index reduction differentiates the constraint twice; the event loop locates
    the impacts and re-initializes the index-1 system.

    Parameters: L [m], m [kg], g [m/s2], x_wall [m] (< 0), e [1]. Variables: x, y [m],
    vx, vy [m/s], T [N/m]. Released from rest at x = x0, y = -sqrt(L^2 - x0^2) (x0 = 0.6 m).
    States: x, vx (preferred; the swing stays below the horizontal, where they are valid).
    """

    L = Parameter(1.0, unit="m", description="Rod length")
    m = Parameter(1.0, unit="kg", description="Mass")
    g = Parameter(9.81, unit="m/s2", description="Gravity along -y")
    x_wall = Parameter(-0.3, unit="m", description="Position of the wall")
    e = Parameter(0.8, unit="1", description="Coefficient of restitution")
    x = Variable(unit="m", start=0.6, fixed=True, state_select=StateSelect.PREFER,
                 description="Horizontal position")
    y = Variable(unit="m", start=-0.8, description="Vertical position")
    vx = Variable(unit="m/s", start=0.0, fixed=True, state_select=StateSelect.PREFER,
                  description="Horizontal velocity")
    vy = Variable(unit="m/s", start=0.0, description="Vertical velocity")
    T = Variable(unit="N/m", description="Rod force per unit length")

    def equations(self):
        yield der(self.x) == self.vx
        yield der(self.y) == self.vy
        yield self.m * der(self.vx) == -self.T * self.x
        yield self.m * der(self.vy) == -self.T * self.y - self.m * self.g
        yield self.x**2 + self.y**2 == self.L**2
        yield when(self.x < self.x_wall,
                   reinit(self.vx, -self.e * pre(self.vx)),
                   reinit(self.vy, -self.e * pre(self.vy)))


class HalfWaveRectifier(Component):
    """A half-wave rectifier: a sine source feeds an RC load through an ideal diode.

    source (v = V sin(2 pi f t)) -> diode (IdealDiode: Ron, Goff, Vknee = 0; anode at the
    source) -> load: resistor R in parallel with capacitor C -> ground. The diode conducts
    (``diode.off`` false) while it carries forward current and blocks once the current would
    turn negative; it turns on again when the source rises above the load voltage. Both are
    state events of the relation ``diode.s < 0``: two switchings per period (the first half
    period starts conducting from v_out = 0).

    Parameters: V [V] (amplitude), f [Hz], Ron [Ohm], Goff [S], R [Ohm], C [F].
    Variables: v_out [V] (load voltage, v_out(0) = 0), i_d [A] (diode current, anode ->
    cathode). Subcomponents: source, diode, resistor, capacitor, ground. State: capacitor.v.
    """

    V = Parameter(10.0, unit="V", description="Source amplitude")
    f = Parameter(50.0, unit="Hz", description="Source frequency")
    Ron = Parameter(1e-5, unit="Ohm", description="Diode on resistance")
    Goff = Parameter(1e-5, unit="S", description="Diode off conductance")
    R = Parameter(100.0, unit="Ohm", description="Load resistance")
    C = Parameter(100e-6, unit="F", description="Load (smoothing) capacitance")
    v_out = Variable(unit="V", start=0.0, fixed=True, description="Load voltage")
    i_d = Variable(unit="A", description="Diode current (anode -> cathode)")

    def __init__(self, **modifiers):
        super().__init__(**modifiers)
        self.source = SineVoltage(V=self.V, f=self.f)
        self.diode = IdealDiode(Ron=self.Ron, Goff=self.Goff)
        self.resistor = Resistor(R=self.R)
        self.capacitor = Capacitor(C=self.C)
        self.ground = Ground()

    def equations(self):
        yield connect(self.source.p, self.diode.p)
        yield connect(self.diode.n, self.resistor.p)
        yield connect(self.diode.n, self.capacitor.p)
        yield connect(self.resistor.n, self.ground.p)
        yield connect(self.capacitor.n, self.ground.p)
        yield connect(self.source.n, self.ground.p)
        yield self.v_out == self.capacitor.v
        yield self.i_d == self.diode.i
