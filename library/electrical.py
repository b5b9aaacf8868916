"""Analog electrical components (Modelica.Electrical.Analog conventions).

Connector :class:`Pin`: potential ``v`` [V], flow ``i`` [A] (positive into the component).
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
    Variable,
    der,
    sin,
    time,
)
from bgmodelica.core.expressions import if_else

from .rotational import Flange

__all__ = ["Pin", "OnePort", "Ground", "Resistor", "Capacitor", "Inductor", "ConstantVoltage",
           "StepVoltage", "SineVoltage", "SignalVoltage", "ConstantCurrent", "StepCurrent",
           "SineCurrent", "SignalCurrent", "EMF", "VoltageSensor", "CurrentSensor"]


class Pin(Connector):
    """Electrical pin. Potential ``v`` [V]; flow ``i`` [A], positive into the component."""

    v = Potential(unit="V", description="Potential at the pin")
    i = Flow(unit="A", description="Current flowing into the pin")


class OnePort(Component):
    """Two pins ``p``, ``n``; voltage drop ``v = p.v - n.v`` [V], current ``i`` p -> n [A]."""

    p = Pin()
    n = Pin()
    v = Variable(unit="V", description="Voltage drop p.v - n.v")
    i = Variable(unit="A", description="Current from p to n through the component")

    def equations(self):
        yield self.v == self.p.v - self.n.v
        yield 0 == self.p.i + self.n.i
        yield self.i == self.p.i


class Ground(Component):
    """Ground node: ``p.v = 0``. Connector: ``p``."""

    p = Pin()

    def equations(self):
        yield self.p.v == 0


class Resistor(OnePort):
    """Linear resistor ``v = R*i``. Parameter: R [Ohm]."""

    R = Parameter(1.0, unit="Ohm", description="Resistance")

    def equations(self):
        yield self.v == self.R * self.i


class Capacitor(OnePort):
    """Linear capacitor ``i = C*der(v)``. Parameter: C [F]. State: v [V]."""

    C = Parameter(1.0, unit="F", description="Capacitance")

    def equations(self):
        yield self.i == self.C * der(self.v)


class Inductor(OnePort):
    """Linear inductor ``v = L*der(i)``. Parameter: L [H]. State: i [A]."""

    L = Parameter(1.0, unit="H", description="Inductance")

    def equations(self):
        yield self.v == self.L * der(self.i)


class ConstantVoltage(OnePort):
    """Ideal constant voltage source ``v = V``. Parameter: V [V]."""

    V = Parameter(1.0, unit="V", description="Source voltage")

    def equations(self):
        yield self.v == self.V


class StepVoltage(OnePort):
    """Voltage step ``v = offset + (time >= start_time ? V : 0)``.

    Parameters: V [V] height, offset [V], start_time [s]. The step is a discontinuity in time,
    handled by the integrator's error control (no event iteration).
    """

    V = Parameter(1.0, unit="V", description="Height of the step")
    offset = Parameter(0.0, unit="V", description="Voltage before the step")
    start_time = Parameter(0.0, unit="s", description="Time of the step")

    def equations(self):
        yield self.v == self.offset + if_else(time >= self.start_time, self.V, 0)


class SineVoltage(OnePort):
    """Sine voltage ``v = offset + V*sin(2*pi*f*time + phase)``.

    Parameters: V [V] amplitude, f [Hz] frequency, phase [rad], offset [V].
    """

    V = Parameter(1.0, unit="V", description="Amplitude")
    f = Parameter(1.0, unit="Hz", description="Frequency")
    phase = Parameter(0.0, unit="rad", description="Phase at time 0")
    offset = Parameter(0.0, unit="V", description="Offset")

    def equations(self):
        yield self.v == self.offset + self.V * sin(2 * 3.141592653589793 * self.f * time
                                                   + self.phase)


class SignalVoltage(OnePort):
    """Voltage source driven by the signal input ``u`` [V]: ``v = u``."""

    u = Input(unit="V", description="Commanded voltage")

    def equations(self):
        yield self.v == self.u


class ConstantCurrent(OnePort):
    """Ideal constant current source ``i = I`` (from p to n through the source). I [A]."""

    I = Parameter(1.0, unit="A", description="Source current")  # noqa: E741

    def equations(self):
        yield self.i == self.I


class StepCurrent(OnePort):
    """Current step ``i = offset + (time >= start_time ? I : 0)`` (from p to n through the
    source). Parameters: I [A] height, offset [A], start_time [s]."""

    I = Parameter(1.0, unit="A", description="Height of the step")  # noqa: E741
    offset = Parameter(0.0, unit="A", description="Current before the step")
    start_time = Parameter(0.0, unit="s", description="Time of the step")

    def equations(self):
        yield self.i == self.offset + if_else(time >= self.start_time, self.I, 0)


class SineCurrent(OnePort):
    """Sine current ``i = offset + I*sin(2*pi*f*time + phase)`` (from p to n through the
    source). Parameters: I [A] amplitude, f [Hz] frequency, phase [rad], offset [A]."""

    I = Parameter(1.0, unit="A", description="Amplitude")  # noqa: E741
    f = Parameter(1.0, unit="Hz", description="Frequency")
    phase = Parameter(0.0, unit="rad", description="Phase at time 0")
    offset = Parameter(0.0, unit="A", description="Offset")

    def equations(self):
        yield self.i == self.offset + self.I * sin(2 * 3.141592653589793 * self.f * time
                                                   + self.phase)


class SignalCurrent(OnePort):
    """Current source driven by the signal input ``u`` [A]: ``i = u``."""

    u = Input(unit="A", description="Commanded current")

    def equations(self):
        yield self.i == self.u


class EMF(Component):
    """Ideal electromechanical converter of a DC machine (a gyrator).

    ``v = k*w``, ``flange.tau = -k*i``. Parameter: k [N.m/A] (= [V.s/rad]).
    Connectors: pins ``p``, ``n``; rotational ``flange`` (rotor side).
    """

    k = Parameter(1.0, unit="N.m/A", description="Torque / back-EMF constant")
    p = Pin()
    n = Pin()
    flange = Flange()
    v = Variable(unit="V", description="Back EMF p.v - n.v")
    i = Variable(unit="A", description="Current p -> n")
    w = Variable(unit="rad/s", description="Rotor speed")

    def equations(self):
        yield self.v == self.p.v - self.n.v
        yield 0 == self.p.i + self.n.i
        yield self.i == self.p.i
        yield self.w == der(self.flange.phi)
        yield self.v == self.k * self.w
        yield self.flange.tau == -self.k * self.i


class VoltageSensor(Component):
    """Ideal voltmeter: output ``v = p.v - n.v`` [V], draws no current."""

    p = Pin()
    n = Pin()
    v = Output(unit="V", description="Measured voltage")

    def equations(self):
        yield self.p.i == 0
        yield self.n.i == 0
        yield self.v == self.p.v - self.n.v


class CurrentSensor(Component):
    """Ideal ammeter in series: output ``i`` [A] flowing p -> n, zero voltage drop."""

    p = Pin()
    n = Pin()
    i = Output(unit="A", description="Measured current")

    def equations(self):
        yield self.p.v == self.n.v
        yield self.p.i + self.n.i == 0
        yield self.i == self.p.i
