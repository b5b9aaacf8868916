"""DC motor examples: open-loop start-up and a PID speed loop."""

from __future__ import annotations

from bgmodelica import Component, connect
from library.blocks import LimPID, Step
from library.electrical import (
    EMF,
    ConstantVoltage,
    Ground,
    Inductor,
    Resistor,
    SignalVoltage,
)
from library.rotational import Damper, Fixed, Inertia, SpeedSensor, Torque

__all__ = ["DCMotor", "PIDSpeedControl"]


class DCMotor(Component):
    """Permanent-magnet DC motor started on a constant voltage, driving an inertia + damper.

    Electrical: source (V = 12 V) -> resistor (R = 1 Ohm) -> inductor (L = 10 mH, i(0) = 0)
    -> emf (k = 0.1 N.m/A) -> ground. Mechanical: emf.flange -> rotor (J = 0.002 kg.m2,
    w(0) = 0) -> load (J = 0.008 kg.m2) -> damper (d = 0.001 N.m.s/rad) -> fixed.
    With J = rotor.J + load.J the model is ``L di/dt = V - R i - k w``, ``J dw/dt = k i - d w``:
    steady state ``w = k V/(R d + k^2)`` = 109.09 rad/s, ``i = d V/(R d + k^2)`` = 1.0909 A;
    electrical time constant ~ L/R = 10 ms, mechanical ~ J R/(k^2 + R d) = 0.91 s.
    """

    source = ConstantVoltage(V=12.0)
    resistor = Resistor(R=1.0)
    inductor = Inductor(L=0.01, i=0.0)
    emf = EMF(k=0.1)
    ground = Ground()
    rotor = Inertia(J=0.002, phi=0.0, w=0.0)
    load = Inertia(J=0.008)
    damper = Damper(d=0.001)
    fixed = Fixed()

    def equations(self):
        yield connect(self.source.p, self.resistor.p)
        yield connect(self.resistor.n, self.inductor.p)
        yield connect(self.inductor.n, self.emf.p)
        yield connect(self.emf.n, self.source.n)
        yield connect(self.source.n, self.ground.p)
        yield connect(self.emf.flange, self.rotor.flange_a)
        yield connect(self.rotor.flange_b, self.load.flange_a)
        yield connect(self.load.flange_b, self.damper.flange_a)
        yield connect(self.damper.flange_b, self.fixed.flange)


class PIDSpeedControl(DCMotor):
    """Speed loop of the :class:`DCMotor` drive: LimPID -> signal voltage source.

    setpoint: Step 0 -> 100 rad/s at t = 0.1 s. load_torque: Step 0 -> 0.5 N.m (braking) at
    t = 1 s, applied through a Torque source on the load. controller: LimPID (PI, k = 4 V.s/rad,
    Ti = 0.2 s, Ni = 0.9, output limited to [-24, 24] V), measuring speed_sensor.w.
    Motor: R = 1 Ohm, L = 10 mH, k = 0.1 N.m/A, rotor J = 0.002, load J = 0.008 kg.m2,
    damper d = 0.001 N.m.s/rad. The speed settles within 1 % about 0.55 s after the step
    (overshoot < 1 rad/s) and recovers from the load step without a steady-state error.
    """

    setpoint = Step(height=100.0, start_time=0.1)
    load_torque = Step(height=-0.5, start_time=1.0)
    controller = LimPID(controller_type="PI", k=4.0, Ti=0.2, Ni=0.9, y_max=24.0, y_min=-24.0)
    source = SignalVoltage()            # redeclares the DCMotor's constant source
    torque = Torque()
    speed_sensor = SpeedSensor()

    def equations(self):                # the drive's connections are inherited
        yield connect(self.setpoint.y, self.controller.u_s)
        yield connect(self.speed_sensor.w, self.controller.u_m)
        yield connect(self.controller.y, self.source.u)
        yield connect(self.load_torque.y, self.torque.tau)
        yield connect(self.torque.flange, self.load.flange_b)
        yield connect(self.speed_sensor.flange, self.rotor.flange_b)
