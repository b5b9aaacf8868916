"""Causal signal blocks (Modelica.Blocks conventions).

Signals are plain ``Input``/``Output`` variables: ``u``, ``u1``, ``u2`` in, ``y`` out, joined
with ``connect(a.y, b.u)``. Units are left empty (signals are dimensionless unless the
connected quantity says otherwise). Sources depending on ``time`` switch with ``if_else`` on a
relation of ``time``, which is a time event (hit exactly).

Event blocks (Modelica semantics, see :mod:`bgmodelica.core.hybrid`): ``Relay`` (hysteresis)
and ``LimiterEvents`` switch at state events (zero crossings of their relations);
``Sampler``, ``ZeroOrderHold``, ``UnitDelay`` and ``DiscretePID`` act at the time events
``sample(start_time, Ts)``; ``PWM`` and ``TimeTable`` switch at exact time events. At an
event instant a result has two rows with the same time: the left limit, then the right limit.
State events need a model with at least one continuous state (an event-loop limitation).

Initial values: a block with a state (``Integrator``, ``FirstOrder``, ``Derivative``,
``LimPID``) fixes it through its ``*_start`` constructor argument, a fixed start value that
``simulate(params={"block.y": value})`` can override.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from bgmodelica import (
    Boolean,
    Component,
    Discrete,
    Input,
    Output,
    Parameter,
    Variable,
    der,
    initial,
    pre,
    sample,
    sin,
    time,
    time_table,
    when,
)
from bgmodelica.core.expressions import fmax, fmin, if_else

__all__ = ["Constant", "Step", "Sine", "Ramp", "Gain", "Add", "Feedback", "Product",
           "Limiter", "Integrator", "FirstOrder", "Derivative", "LimPID",
           "Relay", "LimiterEvents", "Sampler", "ZeroOrderHold", "UnitDelay", "DiscretePID",
           "PWM", "TimeTable"]

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


# -- event blocks -------------------------------------------------------------------------------


class Relay(Component):
    """Relay with hysteresis (Modelica.Blocks.Logical.Hysteresis with a Real output).

    The Boolean state ``on`` switches on when u > uHigh and off when u < uLow::

        on = (not pre(on) and u > uHigh) or (pre(on) and u >= uLow)
        y = if on then y_on else y_off

    Both relations are state events, located to the event tolerance.
    Input: u. Output: y. Parameters: uLow [1], uHigh [1] (uLow < uHigh), y_on [1], y_off [1].
    Discrete: on (Boolean). Constructor: pre_y_start (False; the value of pre(on) at the start).
    """

    uLow = Parameter(0.0, description="Lower switching threshold (off when u < uLow)")
    uHigh = Parameter(1.0, description="Upper switching threshold (on when u > uHigh)")
    y_on = Parameter(1.0, description="Output while on")
    y_off = Parameter(0.0, description="Output while off")
    u = Input(description="Input signal")
    y = Output(description="y_on while on, else y_off")
    on = Boolean(start=False, description="Relay state")

    def __init__(self, pre_y_start: bool = False, **modifiers):
        super().__init__(**{"on": dict(start=float(bool(pre_y_start)), fixed=False),
                            **modifiers})

    def equations(self):
        was_on = pre(self.on)
        yield self.on == ((~was_on & (self.u > self.uHigh)) | (was_on & (self.u >= self.uLow)))
        yield self.y == if_else(self.on, self.y_on, self.y_off)


class LimiterEvents(Component):
    """Saturation with events at its corners:
    ``y = if u > u_max then u_max elseif u < u_min then u_min else u``.

    Unlike :class:`Limiter` (continuous, no events) the relations u > u_max and u < u_min are
    state events, so the integrator restarts exactly at the corners.
    Input: u. Output: y. Parameters: u_max, u_min [1].
    """

    u_max = Parameter(1.0, description="Upper limit")
    u_min = Parameter(-1.0, description="Lower limit")
    u = Input(description="Input signal")
    y = Output(description="Limited output")

    def equations(self):
        yield self.y == if_else(self.u > self.u_max, self.u_max,
                                if_else(self.u < self.u_min, self.u_min, self.u))


class Sampler(Component):
    """Ideal sampler (Modelica.Blocks.Discrete.Sampler): at the start and at every instant
    ``start_time + k*Ts`` (k = 0, 1, ...) the output takes the input's value and holds it.

    Input: u. Output: y (piecewise constant). Parameters: Ts [s] (> 0), start_time [s].
    Discrete: y_sample (the last sampled value).
    """

    Ts = Parameter(0.1, unit="s", description="Sample period")
    start_time = Parameter(0.0, unit="s", description="First sample instant")
    u = Input(description="Continuous input signal")
    y = Output(description="Sampled and held input")
    y_sample = Discrete(start=0.0, description="Last sampled value of u")

    def equations(self):
        yield when([sample(self.start_time, self.Ts), initial()], self.y_sample == self.u)
        yield self.y == self.y_sample


class ZeroOrderHold(Component):
    """Zero-order hold (Modelica.Blocks.Discrete.ZeroOrderHold): samples u at the start and at
    ``start_time + k*Ts`` and outputs ``y = pre(y_sample)``, the sampled value with an
    infinitesimal delay (so a loop through the hold and a direct-feedthrough plant is not an
    algebraic loop). After each sample instant y equals the new sample.

    Input: u. Output: y. Parameters: Ts [s] (> 0), start_time [s].
    Discrete: y_sample (the last sampled value).
    """

    Ts = Parameter(0.1, unit="s", description="Sample period")
    start_time = Parameter(0.0, unit="s", description="First sample instant")
    u = Input(description="Continuous input signal")
    y = Output(description="Held input")
    y_sample = Discrete(start=0.0, description="Last sampled value of u")

    def equations(self):
        yield when([sample(self.start_time, self.Ts), initial()], self.y_sample == self.u)
        yield self.y == pre(self.y_sample)


class UnitDelay(Component):
    """Unit delay ``y = u/z``: at the sample instants t_k = start_time + k*Ts the output takes
    the input sampled at the previous instant, ``y_k = u_(k-1)``, with ``y_0 = y_start``
    (and y = y_start before the first sample); y is held between samples.

    Input: u. Output: y. Parameters: Ts [s] (> 0), start_time [s]. Constructor: y_start (0).
    Discrete: u_last (u at the last sample), y_hold (the output).
    """

    Ts = Parameter(0.1, unit="s", description="Sample period")
    start_time = Parameter(0.0, unit="s", description="First sample instant")
    u = Input(description="Continuous input signal")
    y = Output(description="Input delayed by one sample")
    u_last = Discrete(start=0.0, description="Input at the last sample instant")
    y_hold = Discrete(start=0.0, description="Held output")

    def __init__(self, y_start: float = 0.0, **modifiers):
        super().__init__(**{"u_last": y_start, "y_hold": y_start, **modifiers})

    def equations(self):
        yield when(sample(self.start_time, self.Ts),
                   self.y_hold == pre(self.u_last),
                   self.u_last == self.u)
        yield self.y == self.y_hold


class DiscretePID(Component):
    """Sampled PID with output limits, period Ts. At every sample instant t_k = k*Ts
    (k = 0, 1, ...)::

        e_k = u_s(t_k) - u_m(t_k)
        I_k = I_(k-1) + Ts*e_k                       (I_(-1) = 0)
        D_k = (e_k - e_(k-1))/Ts                     (e_(-1) = e_0, so D_0 = 0)
        y_k = clamp(Kp*e_k + Ki*I_k + Kd*D_k, y_min, y_max)

    and y = y_k on [t_k, t_(k+1)) (held; no anti-windup beyond the clamp of the output).
    Inputs: u_s (setpoint), u_m (measurement). Output: y. Parameters: Kp [1], Ki [1/s],
    Kd [s], Ts [s] (> 0), y_max, y_min [1]. Discrete: e (last sampled error), I (sum of
    Ts*e), y_hold (the output), first (Boolean, true before the first sample).
    """

    Kp = Parameter(1.0, description="Proportional gain")
    Ki = Parameter(0.0, unit="1/s", description="Integral gain")
    Kd = Parameter(0.0, unit="s", description="Derivative gain")
    Ts = Parameter(0.01, unit="s", description="Sample period")
    y_max = Parameter(1.0, description="Upper output limit")
    y_min = Parameter(-1.0, description="Lower output limit")
    u_s = Input(description="Setpoint")
    u_m = Input(description="Measurement")
    y = Output(description="Held, limited controller output")
    e = Discrete(start=0.0, description="Error at the last sample")
    I = Discrete(start=0.0, unit="s", description="Sum of Ts*e over the samples")  # noqa: E741
    y_hold = Discrete(start=0.0, description="Output computed at the last sample")
    first = Boolean(start=True, description="No sample taken yet")

    def equations(self):
        e_k = self.u_s - self.u_m
        i_k = pre(self.I) + self.Ts * e_k
        d_k = if_else(pre(self.first), 0.0, (e_k - pre(self.e)) / self.Ts)
        raw = self.Kp * e_k + self.Ki * i_k + self.Kd * d_k
        yield when(sample(0.0, self.Ts),
                   self.e == e_k,
                   self.I == i_k,
                   self.y_hold == fmax(self.y_min, fmin(self.y_max, raw)),
                   self.first == False)  # noqa: E712 -- assigns the Boolean
        yield self.y == self.y_hold


class PWM(Component):
    """Pulse-width-modulated source: y = V while frac((time - start_time)*f) < duty, else 0
    (and 0 before start_time).

    Each period starts at ``sample(start_time, 1/f)`` (the output goes high) and the output
    goes low at the time event period start + duty/f (a relation on time), so both edges are
    exact time events.
    Output: y. Parameters: V [1] (high value), f [Hz] (> 0), duty [1] (0..1), start_time [s].
    Discrete: period_start [s] (start of the current period), on (Boolean, the output is high).
    """

    V = Parameter(1.0, description="Output while high")
    f = Parameter(1.0, unit="Hz", description="PWM frequency")
    duty = Parameter(0.5, unit="1", description="Duty cycle (high fraction of each period)")
    start_time = Parameter(0.0, unit="s", description="Start of the first period")
    y = Output(description="V while high, else 0")
    period_start = Discrete(unit="s", start=0.0, description="Start of the current period")
    on = Boolean(start=False, description="True while the output is high")

    def equations(self):
        yield when(sample(self.start_time, 1.0 / self.f), self.period_start == time)
        yield self.on == ((time >= self.start_time)
                          & (time < self.period_start + self.duty / self.f))
        yield self.y == if_else(self.on, self.V, 0.0)


class TimeTable(Component):
    """Table look-up in time, one output column (like Modelica.Blocks.Sources.CombiTimeTable).

    ``y = offset + table(time)``, built on :func:`bgmodelica.time_table`: breakpoints are time
    events, so kinks and jumps are hit exactly.

    Output: y. Parameter: offset [1].
    Constructor arguments (fixed at construction):

    - ``table``: an N x M array (column 1 is time [s], non-decreasing) or the path of a CSV
      file with a header row (first column time). A CSV whose first column is named ``time``
      (and ``timeScale`` 1) is read through ``time_table(file=...)``: an exported FMU carries
      the file in its resources and reads it when instantiated.
    - ``column``: the output column, 1-based as in Modelica (column 1 is time, so the default
      2 is the first value column) or a header name of the CSV file.
    - ``smoothness``: "linear" (linear interpolation) or "hold" (constant from each breakpoint
      to the next). A repeated time is a jump: the later row holds from that instant.
    - ``extrapolation``: "hold" (first/last value), "periodic" (the table repeats with period
      t_last - t_first) or "linear" (first/last segment continued; with "linear" smoothness).
    - ``timeScale`` [s] (> 0): the table's time column is in units of timeScale seconds
      (a table time t_tab is the model time t_tab*timeScale).
    """

    offset = Parameter(0.0, description="Offset added to the table value")
    y = Output(description="Table value at time (plus offset)")

    def __init__(self, table, column: int | str = 2, smoothness: str = "linear",
                 extrapolation: str = "hold", timeScale: float = 1.0, **modifiers):  # noqa: N803
        data, names = _read_table(table)
        if isinstance(column, str):
            if names is None or column not in names:
                raise ValueError(f"TimeTable: no column named {column!r}"
                                 + (f" (columns: {names})" if names else
                                    " (the table has no header; give a 1-based index)"))
            index = names.index(column) + 1
        else:
            index = int(column)
        if not 2 <= index <= data.shape[1]:
            raise ValueError(f"TimeTable: column must be 2..{data.shape[1]} (1-based; column 1 "
                             f"is time), got {column!r}")
        if smoothness not in ("linear", "hold"):
            raise ValueError(f"TimeTable: smoothness must be 'linear' or 'hold', got "
                             f"{smoothness!r}")
        if extrapolation not in ("hold", "periodic", "linear"):
            raise ValueError(f"TimeTable: extrapolation must be 'hold', 'periodic' or 'linear', "
                             f"got {extrapolation!r}")
        if not (np.isfinite(timeScale) and timeScale > 0):
            raise ValueError(f"TimeTable: timeScale must be > 0, got {timeScale!r}")
        object.__setattr__(self, "_times", data[:, 0] * float(timeScale))
        object.__setattr__(self, "_values", data[:, index - 1].copy())
        object.__setattr__(self, "_smoothness", smoothness)
        object.__setattr__(self, "_extrapolation", extrapolation)
        # a CSV with a 'time' column in seconds stays a file: exported FMUs carry it
        from_file = names is not None and names[0] == "time" and timeScale == 1.0
        object.__setattr__(self, "_file", (str(table), names[index - 1]) if from_file
                           else None)
        super().__init__(**modifiers)

    def equations(self):
        if self._file is not None:
            table = time_table(interpolation=self._smoothness, extrapolation=self._extrapolation,
                               file=self._file[0], column=self._file[1])
        else:
            table = time_table(self._times, self._values, self._smoothness, self._extrapolation)
        yield self.y == self.offset + table


def _read_table(table) -> tuple[np.ndarray, list[str] | None]:
    """(N x M float array, header names or None) from an array or a CSV path with a header."""
    names = None
    if isinstance(table, (str, Path)):
        path = Path(table)
        if not path.is_file():
            raise ValueError(f"TimeTable: table file {path} does not exist")
        with path.open(newline="") as fh:
            rows = [r for r in csv.reader(fh) if r and any(c.strip() for c in r)]
        if len(rows) < 2:
            raise ValueError(f"TimeTable: {path} needs a header row and data rows")
        names = [h.strip() for h in rows[0]]
        try:
            data = np.array([[float(v) for v in r] for r in rows[1:]], dtype=float)
        except ValueError as err:
            raise ValueError(f"TimeTable: {path}: {err}") from None
        if data.ndim != 2 or data.shape[1] != len(names):
            raise ValueError(f"TimeTable: {path}: rows and header have different numbers of "
                             "columns")
    else:
        data = np.array(table, dtype=float)
        if data.ndim != 2:
            raise ValueError(f"TimeTable: table must be an N x M array, got shape {data.shape}")
    if data.shape[0] < 1 or data.shape[1] < 2:
        raise ValueError(f"TimeTable: table needs a time column and a value column, got shape "
                         f"{data.shape}")
    return data, names
