"""Analog electrical components (Modelica.Electrical.Analog conventions).

Connector :class:`Pin`: potential ``v`` [V], flow ``i`` [A] (positive into the component).
"""

from __future__ import annotations

from bgmodelica import (
    Boolean,
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
           "SineCurrent", "SignalCurrent", "EMF", "VoltageSensor", "CurrentSensor",
           "IdealSemiconductor", "IdealDiode", "IdealSwitch", "IdealOpeningSwitch",
           "IdealClosingSwitch", "PartialCommutingSwitch", "IdealCommutingSwitch",
           "ControlledIdealOpeningSwitch", "ControlledIdealClosingSwitch",
           "ControlledIdealCommutingSwitch"]


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


# -- ideal switching elements (Modelica.Electrical.Analog.Ideal) ---------------------------------
#
# Each is piecewise linear in an auxiliary variable ``s`` (a parametric description of the
# characteristic, so the equations stay regular in both modes): with the Boolean ``off``,
#     v = s*(if off then 1 else Ron) [+ Vknee],    i = s*(if off then Goff else 1) [+ Goff*Vknee].
# ``off`` changes only at events: a zero crossing of a relation (diode, controlled switches) or
# a change of the Boolean control signal. Units of s: V while off, A while on (MSL multiplies by
# constants of 1 V / 1 A; here s declares no unit, "", so the unit check lets it take both).


class IdealSemiconductor(OnePort):
    """Ideal semiconductor (Modelica.Electrical.Analog.Interfaces.IdealSemiconductor).

    Piecewise linear: conducting (``off`` false) it is a resistance Ron in series with the knee
    voltage Vknee, blocking (``off`` true) a conductance Goff::

        off = s < 0
        v = s*(if off then 1 else Ron) + Vknee
        i = s*(if off then Goff else 1) + Goff*Vknee

    so at the switching point s = 0 both branches give v = Vknee, i = Goff*Vknee (continuous
    characteristic). The relation ``s < 0`` is a state event.
    Tolerances: while conducting, ``i = (v - Vknee)/Ron`` amplifies the integration error of
    the circuit's voltages by 1/Ron; with Ron = 1e-5 Ohm at ~10 V use rtol <= 1e-8, or the
    current's error (up to ~rtol*10 V/Ron) can reach zero before the real turn-off and cause
    spurious off/on event pairs.
    Parameters: Ron [Ohm] (>= 0), Goff [S] (>= 0), Vknee [V] (>= 0).
    Variables: s (auxiliary, V or A: no declared unit); Boolean ``off`` (start true).
    """

    Ron = Parameter(1e-5, unit="Ohm", min=0.0, description="Forward state-on differential "
                    "resistance (closed resistance)")
    Goff = Parameter(1e-5, unit="S", min=0.0, description="Backward state-off conductance "
                     "(opened conductance)")
    Vknee = Parameter(0.0, unit="V", min=0.0, description="Forward threshold voltage")
    off = Boolean(start=True, description="Switching state (true: blocking)")
    s = Variable(unit="", start=0.0, description="Auxiliary variable for the characteristic: "
                 "actual current if conducting, actual voltage if blocking (minus Vknee)")

    def equations(self):
        yield self.off == (self.s < 0)
        yield self.v == self.s * if_else(self.off, 1.0, self.Ron) + self.Vknee
        yield self.i == self.s * if_else(self.off, self.Goff, 1.0) + self.Goff * self.Vknee


class IdealDiode(IdealSemiconductor):
    """Ideal diode (Modelica.Electrical.Analog.Ideal.IdealDiode): conducting for s >= 0 with
    ``v = Ron*i + Vknee`` (i >= Goff*Vknee), blocking for s < 0 with ``i = Goff*v``
    (v < Vknee). Pins: p (anode), n (cathode).

    Parameters: Ron [Ohm] = 1e-5, Goff [S] = 1e-5, Vknee [V] = 0.
    Variables: v [V], i [A] (p -> n), s (no unit); Boolean ``off``. See :class:`IdealSemiconductor`.
    """


class IdealSwitch(OnePort):
    """Partial ideal switch (Modelica.Electrical.Analog.Interfaces.IdealSwitch)::

        v = s*(if off then 1 else Ron),    i = s*(if off then Goff else 1)

    closed (``off`` false): a resistance Ron; open (``off`` true): a conductance Goff.
    A subclass defines the Boolean ``off``.
    Parameters: Ron [Ohm] (>= 0), Goff [S] (>= 0). Variables: s (no unit); Boolean ``off``.
    """

    Ron = Parameter(1e-5, unit="Ohm", min=0.0, description="Closed switch resistance")
    Goff = Parameter(1e-5, unit="S", min=0.0, description="Opened switch conductance")
    off = Boolean(start=False, description="Switch state (true: open)")
    s = Variable(unit="", start=0.0, description="Auxiliary variable: current if closed, "
                 "voltage if open")

    def equations(self):
        yield self.v == self.s * if_else(self.off, 1.0, self.Ron)
        yield self.i == self.s * if_else(self.off, self.Goff, 1.0)


class IdealOpeningSwitch(IdealSwitch):
    """Ideal electrical opener (Modelica.Electrical.Analog.Ideal.IdealOpeningSwitch):
    ``off = control``: control true => switch open (conductance Goff), false => p--n
    connected (resistance Ron).

    Boolean input: ``control`` (a signal, 1 = true, 0 = false; it should change only at
    events, e.g. a time relation or a Boolean of a block). Parameters: Ron [Ohm] = 1e-5,
    Goff [S] = 1e-5. See :class:`IdealSwitch`.
    """

    control = Input(description="true (1) => switch open, false (0) => p--n connected")

    def equations(self):
        yield self.off == self.control


class IdealClosingSwitch(IdealSwitch):
    """Ideal electrical closer (Modelica.Electrical.Analog.Ideal.IdealClosingSwitch):
    ``off = not control``: control true => p--n connected (resistance Ron), false => switch
    open (conductance Goff).

    Boolean input: ``control`` (1 = true, 0 = false). Parameters: Ron [Ohm] = 1e-5,
    Goff [S] = 1e-5. See :class:`IdealSwitch`.
    """

    control = Input(description="true (1) => p--n connected, false (0) => switch open")

    def equations(self):
        yield self.off == ~self.control


class PartialCommutingSwitch(Component):
    """Pins, parameters and equations shared by the commuting switches (no equations of its
    own; a subclass yields ``self.switched(to_n2)`` with its Boolean condition ``to_n2``)::

        0 = p.i + n1.i + n2.i
        p.v - n1.v = s1*(if to_n2 then 1 else Ron),   n1.i = -s1*(if to_n2 then Goff else 1)
        p.v - n2.v = s2*(if to_n2 then Ron else 1),   n2.i = -s2*(if to_n2 then 1 else Goff)

    Pins: p, n1, n2 (currents positive into the switch). Parameters: Ron [Ohm] (>= 0),
    Goff [S] (>= 0). Variables: s1, s2 [1] (auxiliary: current if closed, voltage if open).
    """

    Ron = Parameter(1e-5, unit="Ohm", min=0.0, description="Closed switch resistance")
    Goff = Parameter(1e-5, unit="S", min=0.0, description="Opened switch conductance")
    p = Pin()
    n1 = Pin()
    n2 = Pin()
    s1 = Variable(unit="", start=0.0, description="Auxiliary variable of the p--n1 path")
    s2 = Variable(unit="", start=0.0, description="Auxiliary variable of the p--n2 path")

    def switched(self, to_n2):
        """The switch equations with ``to_n2`` (true: p--n2 connected, p--n1 open)."""
        yield 0 == self.p.i + self.n1.i + self.n2.i
        yield self.p.v - self.n1.v == self.s1 * if_else(to_n2, 1.0, self.Ron)
        yield self.n1.i == -self.s1 * if_else(to_n2, self.Goff, 1.0)
        yield self.p.v - self.n2.v == self.s2 * if_else(to_n2, self.Ron, 1.0)
        yield self.n2.i == -self.s2 * if_else(to_n2, 1.0, self.Goff)


class IdealCommutingSwitch(PartialCommutingSwitch):
    """Ideal commuting switch (Modelica.Electrical.Analog.Ideal.IdealCommutingSwitch):
    control true => p--n2 connected (p--n1 open), false => p--n1 connected (p--n2 open).
    Equations of :class:`PartialCommutingSwitch` with ``to_n2 = control``.

    Pins: p, n1, n2. Boolean input: ``control`` (1 = true, 0 = false). Parameters:
    Ron [Ohm] = 1e-5, Goff [S] = 1e-5. Variables: s1, s2 [1].
    """

    control = Input(description="true (1) => p--n2 connected, false (0) => p--n1 connected")

    def equations(self):
        yield from self.switched(self.control)


class ControlledIdealOpeningSwitch(IdealSwitch):
    """Controlled ideal electrical opener
    (Modelica.Electrical.Analog.Ideal.ControlledIdealOpeningSwitch): ``off = control.v >
    level``: control.v > level => switch open (conductance Goff), otherwise p--n connected
    (resistance Ron). The control pin draws no current; its potential (against ground) is
    compared to ``level`` by a relation, i.e. the switch changes at a state event.

    Pins: p, n, control. Parameters: level [V] = 0.5, Ron [Ohm] = 1e-5, Goff [S] = 1e-5.
    See :class:`IdealSwitch`.
    """

    level = Parameter(0.5, unit="V", description="Switch level")
    control = Pin()

    def equations(self):
        yield self.control.i == 0
        yield self.off == (self.control.v > self.level)


class ControlledIdealClosingSwitch(IdealSwitch):
    """Controlled ideal electrical closer
    (Modelica.Electrical.Analog.Ideal.ControlledIdealClosingSwitch): ``off = not (control.v >
    level)``: control.v > level => p--n connected (resistance Ron), otherwise switch open
    (conductance Goff). The control pin draws no current; the relation is a state event.

    Pins: p, n, control. Parameters: level [V] = 0.5, Ron [Ohm] = 1e-5, Goff [S] = 1e-5.
    See :class:`IdealSwitch`.
    """

    level = Parameter(0.5, unit="V", description="Switch level")
    control = Pin()

    def equations(self):
        yield self.control.i == 0
        yield self.off == ~(self.control.v > self.level)


class ControlledIdealCommutingSwitch(PartialCommutingSwitch):
    """Controlled ideal commuting switch
    (Modelica.Electrical.Analog.Ideal.ControlledIdealCommutingSwitch): control.v > level =>
    p--n2 connected, otherwise p--n1 connected (equations of :class:`PartialCommutingSwitch`
    with ``to_n2`` the relation ``control.v > level``, a state event).

    Pins: p, n1, n2, control (draws no current). Parameters: level [V] = 0.5,
    Ron [Ohm] = 1e-5, Goff [S] = 1e-5. Variables: s1, s2 [1].
    """

    level = Parameter(0.5, unit="V", description="Switch level")
    control = Pin()

    def equations(self):
        yield self.control.i == 0
        yield from self.switched(self.control.v > self.level)
