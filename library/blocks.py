"""Causal signal blocks (Modelica.Blocks conventions).

Signals are plain ``Input``/``Output`` variables: ``u``, ``u1``, ``u2`` in, ``y`` out, joined
with ``connect(a.y, b.u)``. Units are left empty (signals are dimensionless unless the
connected quantity says otherwise). Sources depending on ``time`` switch with ``if_else``:
there is no event handling, a step is a discontinuity met by the integrator's error control.

Initial values: a block with a state (``Integrator``, ``FirstOrder``, ``Derivative``,
``LimPID``) fixes it through its ``*_start`` constructor argument, a fixed start value that
``simulate(params={"block.y": value})`` can override.
"""

from __future__ import annotations

from bgmodelica import (
    Component,
    Input,
    Output,
    Parameter,
    Variable,
    der,
    sin,
    time,
)
from bgmodelica.core.expressions import fmax, fmin, if_else

__all__ = ["Constant", "Step", "Sine", "Ramp", "Gain", "Add", "Feedback", "Product",
           "Limiter", "Integrator", "FirstOrder", "Derivative", "LimPID"]

_PI = 3.141592653589793


class Constant(Component):
    """Constant source ``y = k``. Output: y. Parameter: k [1]."""

    k = Parameter(1.0, description="Constant output value")
    y = Output(description="Output signal")

    def equations(self):
        yield self.y == self.k


class Step(Component):
    """Step source ``y = offset + (time >= start_time ? height : 0)``.

    Output: y. Parameters: height [1], offset [1], start_time [s].
    """

    height = Parameter(1.0, description="Height of the step")
    offset = Parameter(0.0, description="Output before the step")
    start_time = Parameter(0.0, unit="s", description="Time of the step")
    y = Output(description="Output signal")

    def equations(self):
        yield self.y == self.offset + if_else(time >= self.start_time, self.height, 0)


class Sine(Component):
    """Sine source ``y = offset + amplitude*sin(2*pi*f*time + phase)``.

    Output: y. Parameters: amplitude [1], f [Hz], phase [rad], offset [1].
    """

    amplitude = Parameter(1.0, description="Amplitude")
    f = Parameter(1.0, unit="Hz", description="Frequency")
    phase = Parameter(0.0, unit="rad", description="Phase at time 0")
    offset = Parameter(0.0, description="Offset")
    y = Output(description="Output signal")

    def equations(self):
        yield self.y == self.offset + self.amplitude * sin(2 * _PI * self.f * time + self.phase)


class Ramp(Component):
    """Ramp source: ``y = offset`` before ``start_time``, then rising linearly by ``height``
    over ``duration``, then ``offset + height``.

    Output: y. Parameters: height [1], duration [s] (> 0), offset [1], start_time [s].
    """

    height = Parameter(1.0, description="Height of the ramp")
    duration = Parameter(1.0, unit="s", description="Duration of the ramp")
    offset = Parameter(0.0, description="Output before the ramp")
    start_time = Parameter(0.0, unit="s", description="Start time of the ramp")
    y = Output(description="Output signal")

    def equations(self):
        s = (time - self.start_time) / self.duration
        yield self.y == self.offset + self.height * fmin(1, fmax(0, s))


class Gain(Component):
    """Gain ``y = k*u``. Input: u. Output: y. Parameter: k [1]."""

    k = Parameter(1.0, description="Gain")
    u = Input(description="Input signal")
    y = Output(description="Output signal")

    def equations(self):
        yield self.y == self.k * self.u


class Add(Component):
    """Weighted sum ``y = k1*u1 + k2*u2``. Inputs: u1, u2. Output: y. Parameters: k1, k2 [1]."""

    k1 = Parameter(1.0, description="Gain of u1")
    k2 = Parameter(1.0, description="Gain of u2")
    u1 = Input(description="First input")
    u2 = Input(description="Second input")
    y = Output(description="Output signal")

    def equations(self):
        yield self.y == self.k1 * self.u1 + self.k2 * self.u2


class Feedback(Component):
    """Difference ``y = u1 - u2`` (setpoint minus feedback). Inputs: u1, u2. Output: y."""

    u1 = Input(description="Commanded input")
    u2 = Input(description="Feedback input")
    y = Output(description="Difference u1 - u2")

    def equations(self):
        yield self.y == self.u1 - self.u2


class Product(Component):
    """Product ``y = u1*u2``. Inputs: u1, u2. Output: y."""

    u1 = Input(description="First input")
    u2 = Input(description="Second input")
    y = Output(description="Product u1*u2")

    def equations(self):
        yield self.y == self.u1 * self.u2


class Limiter(Component):
    """Saturation ``y = max(u_min, min(u_max, u))`` (continuous, no events).

    Input: u. Output: y. Parameters: u_max, u_min [1].
    """

    u_max = Parameter(1.0, description="Upper limit")
    u_min = Parameter(-1.0, description="Lower limit")
    u = Input(description="Input signal")
    y = Output(description="Limited output")

    def equations(self):
        yield self.y == fmax(self.u_min, fmin(self.u_max, self.u))


class Integrator(Component):
    """Integrator ``der(y) = k*u``, ``y(0) = y_start``.

    Input: u. Output (state): y. Parameter: k [1]. Constructor argument: y_start (default 0).
    """

    k = Parameter(1.0, description="Integrator gain")
    u = Input(description="Input signal")
    y = Output(start=0.0, fixed=True, description="Integral of k*u")

    def __init__(self, y_start: float = 0.0, **modifiers):
        super().__init__(**{"y": y_start, **modifiers})

    def equations(self):
        yield der(self.y) == self.k * self.u


class FirstOrder(Component):
    """First-order lag ``T*der(y) = k*u - y``, ``y(0) = y_start``.

    Input: u. Output (state): y. Parameters: k [1], T [s] (> 0). Constructor: y_start (0).
    """

    k = Parameter(1.0, description="Gain")
    T = Parameter(1.0, unit="s", description="Time constant")
    u = Input(description="Input signal")
    y = Output(start=0.0, fixed=True, description="Output signal")

    def __init__(self, y_start: float = 0.0, **modifiers):
        super().__init__(**{"y": y_start, **modifiers})

    def equations(self):
        yield self.T * der(self.y) == self.k * self.u - self.y


class Derivative(Component):
    """Filtered derivative ``k*s/(T*s + 1)``: ``T*der(x) = u - x``, ``y = k*(u - x)/T``.

    Input: u. Output: y. State: x (low-passed u), ``x(0) = x_start``. Parameters: k [1],
    T [s] (> 0, filter time constant). Constructor: x_start (0; set it to u(0) to start at y=0).
    """

    k = Parameter(1.0, description="Gain")
    T = Parameter(0.01, unit="s", description="Filter time constant")
    u = Input(description="Input signal")
    y = Output(description="Approximate derivative k*der(u)")
    x = Variable(start=0.0, fixed=True, description="Filter state (low-passed input)")

    def __init__(self, x_start: float = 0.0, **modifiers):
        super().__init__(**{"x": x_start, **modifiers})

    def equations(self):
        yield self.T * der(self.x) == self.u - self.x
        yield self.y == self.k * (self.u - self.x) / self.T


class LimPID(Component):
    """PID controller with output limits and anti-windup (as Modelica.Blocks.Continuous.LimPID).

    Inputs: u_s (setpoint), u_m (measurement). Output: y.
    Parameters: k [1] proportional gain; Ti [s] integral time; Td [s] derivative time;
    Nd [1] derivative filter (filter time constant Td/Nd); wp, wd [1] setpoint weights of the
    P and D parts (wd = 0: derivative on the measurement only); Ni [1] anti-windup gain;
    y_max, y_min [1] output limits.
    States: x_i (integral part, ``x_i(0) = xi_start``), x_d (derivative filter state, chosen so
    the D part starts at ``D(0) = 0``, i.e. no derivative kick at t = 0).

    Equations (ideal/standard form; parallel gains Kp = k, Ki = k/Ti, Kd = k*Td)::

        P = wp*u_s - u_m
        der(x_i) = (u_s - u_m + (y - y_unlim)/(k*Ni)) / Ti        # back-calculation
        D = Nd*(wd*u_s - u_m - x_d),  der(x_d) = Nd/Td*(wd*u_s - u_m - x_d)
        y_unlim = k*(P + x_i + D)
        y = max(y_min, min(y_max, y_unlim))                     # continuous limiter

    The tracking time constant of the back-calculation is Tt = Ni*Ti; a very large Ni
    disables anti-windup. ``controller_type`` ("P", "PI", "PD", "PID") drops the unused
    parts (their variables are then identically 0). ``Kp``, ``Ki``, ``Kd`` may be given
    instead of k, Ti, Td (numbers, converted at construction).
    """

    k = Parameter(1.0, description="Proportional gain")
    Ti = Parameter(0.5, unit="s", description="Integral time constant")
    Td = Parameter(0.1, unit="s", description="Derivative time constant")
    Nd = Parameter(10.0, description="Derivative filter: filter time constant is Td/Nd")
    Ni = Parameter(0.9, description="Anti-windup gain (tracking time constant Ni*Ti)")
    wp = Parameter(1.0, description="Setpoint weight of the proportional part")
    wd = Parameter(0.0, description="Setpoint weight of the derivative part")
    y_max = Parameter(1.0, description="Upper output limit")
    y_min = Parameter(-1.0, description="Lower output limit")
    u_s = Input(description="Setpoint")
    u_m = Input(description="Measurement")
    y = Output(description="Limited controller output")
    y_unlim = Variable(description="Controller output before the limiter")
    P = Variable(description="Proportional part (before k)")
    D = Variable(start=0.0, fixed=True, description="Derivative part (before k)")
    x_i = Variable(start=0.0, fixed=True, description="Integral part (before k)")
    x_d = Variable(description="Derivative filter state")

    def __init__(self, controller_type: str = "PID", xi_start: float = 0.0,
                 Kp: float | None = None, Ki: float | None = None, Kd: float | None = None,
                 **modifiers):
        if controller_type not in ("P", "PI", "PD", "PID"):
            raise ValueError(f"controller_type must be P, PI, PD or PID, not {controller_type!r}")
        object.__setattr__(self, "controller_type", controller_type)
        k = modifiers.get("k", 1.0) if Kp is None else Kp
        if Kp is not None:
            modifiers["k"] = Kp
        if Ki is not None:
            modifiers["Ti"] = k / Ki
        if Kd is not None:
            modifiers["Td"] = Kd / k
        if "I" in controller_type:
            modifiers.setdefault("x_i", xi_start)
        else:
            modifiers.setdefault("x_i", dict(fixed=False))
        if "D" not in controller_type:
            modifiers.setdefault("D", dict(fixed=False))
        super().__init__(**modifiers)

    def equations(self):
        e = self.u_s - self.u_m
        yield self.P == self.wp * self.u_s - self.u_m
        if "I" in self.controller_type:
            tracking = (self.y - self.y_unlim) / (self.k * self.Ni)
            yield self.Ti * der(self.x_i) == e + tracking
        else:
            yield self.x_i == 0
        if "D" in self.controller_type:
            u_d = self.wd * self.u_s - self.u_m
            yield self.D == self.Nd * (u_d - self.x_d)
            yield self.Td * der(self.x_d) == self.Nd * (u_d - self.x_d)
        else:
            yield self.D == 0
            yield self.x_d == 0
        yield self.y_unlim == self.k * (self.P + self.x_i + self.D)
        yield self.y == fmax(self.y_min, fmin(self.y_max, self.y_unlim))
