"""The paper's robot under computer control: a sampled PID per joint with a zero-order hold.

At every sample instant t_k = k*Ts (k = 0, 1, ...) each joint controller reads the tracking
error and updates::

    e_k = q*(t_k) - q(t_k)
    I_k = I_(k-1) + Ts*e_k                       (I_(-1) = 0)
    D_k = (e_k - e_(k-1))/Ts                     (e_(-1) = e_0, so D_0 = 0)
    u_k = clamp(Kp*e_k + Ki*I_k + Kd*D_k, -Vmax, Vmax)

and the motor voltage is u_k on [t_k, t_(k+1)): the samples are time events, the voltage is a
discrete variable (piecewise constant), and the arm and motors integrate exactly between them.
"""

from __future__ import annotations

from bgmodelica import (
    Boolean,
    Component,
    Discrete,
    Input,
    Output,
    Parameter,
    connect,
    fmax,
    fmin,
    if_else,
    pre,
    sample,
    when,
)
from library.rotational import AngleSensor

from .motor import DCMotor
from .params import PID, VMAX
from .robot import _RobotBase

__all__ = ["DigitalJointPID", "RobotDigitalPID"]


class DigitalJointPID(Component):
    """Sampled PID with output limits (the law in the module docstring).

    Inputs: u_s (reference) [rad], u_m (measurement) [rad]. Output: y [V] (held between
    samples). Parameters: Kp [V/rad], Ki [V/(rad.s)], Kd [V.s/rad], Ts [s], y_max [V].
    Discrete variables: e (last sampled error) [rad], I (error integral) [rad.s], u (last
    output) [V], first (true before the first sample).
    """

    Kp = Parameter(1.0, unit="V/rad", description="Proportional gain")
    Ki = Parameter(0.0, unit="V/(rad.s)", description="Integral gain")
    Kd = Parameter(0.0, unit="V.s/rad", description="Derivative gain")
    Ts = Parameter(1e-3, unit="s", description="Sample period")
    y_max = Parameter(VMAX, unit="V", description="Output limit (symmetric)")
    u_s = Input(unit="rad", description="Reference")
    u_m = Input(unit="rad", description="Measurement")
    y = Output(unit="V", description="Held control output")
    e = Discrete(unit="rad", start=0.0, description="Error at the last sample")
    I = Discrete(unit="rad.s", start=0.0, description="Sum of Ts*e over the samples")
    u = Discrete(unit="V", start=0.0, description="Output computed at the last sample")
    first = Boolean(start=True, description="No sample taken yet")

    def equations(self):
        e_k = self.u_s - self.u_m
        d_k = if_else(pre(self.first), 0.0, (e_k - pre(self.e)) / self.Ts)
        raw = self.Kp * e_k + self.Ki * self.I + self.Kd * d_k
        yield when(sample(0.0, self.Ts),
                   self.e == e_k,
                   self.I == pre(self.I) + self.Ts * e_k,
                   self.u == fmax(-self.y_max, fmin(self.y_max, raw)),
                   self.first == False)  # noqa: E712 -- assigns the Boolean
        yield self.y == self.u


class RobotDigitalPID(_RobotBase):
    """:class:`~library.robots.robot.RobotPID` with each LimPID replaced by a sampled PID
    (:class:`DigitalJointPID`, period ``Ts``) whose output drives the motor through a
    zero-order hold.

    Parameters (top level): m1, m2, l1, l2, lc1, lc2, I1, I2, g (arm); motor1.*, motor2.*:
    R, L, k1, Jm, b, k2; Kp1, Ki1, Kd1, Kp2, Ki2, Kd2; A1, f1, A2, f2 (references); Vmax [V];
    Ts [s]. Variables of interest (as in RobotPID): arm.q1, arm.q2, motor1.i, motor2.i,
    motor1.u, motor2.u, e1, e2; controllers pid1, pid2 (discrete e, I, u).
    Starts at rest at q = (0, 0) with zero currents.
    """

    Kp1 = Parameter(PID["Kp1"], unit="V/rad", description="Proportional gain, joint 1")
    Ki1 = Parameter(PID["Ki1"], unit="V/(rad.s)", description="Integral gain, joint 1")
    Kd1 = Parameter(PID["Kd1"], unit="V.s/rad", description="Derivative gain, joint 1")
    Kp2 = Parameter(PID["Kp2"], unit="V/rad", description="Proportional gain, joint 2")
    Ki2 = Parameter(PID["Ki2"], unit="V/(rad.s)", description="Integral gain, joint 2")
    Kd2 = Parameter(PID["Kd2"], unit="V.s/rad", description="Derivative gain, joint 2")
    Vmax = Parameter(VMAX, unit="V", description="Motor voltage limit")
    Ts = Parameter(1e-3, unit="s", description="Controller sample period")

    def _build_control(self) -> None:
        self.motor1 = DCMotor()
        self.motor2 = DCMotor()
        self.sensor1 = AngleSensor()
        self.sensor2 = AngleSensor()
        for k, (kp, ki, kd) in enumerate(((self.Kp1, self.Ki1, self.Kd1),
                                          (self.Kp2, self.Ki2, self.Kd2)), start=1):
            self.add(f"pid{k}", DigitalJointPID(Kp=kp, Ki=ki, Kd=kd, Ts=self.Ts,
                                                y_max=self.Vmax))

    def equations(self):
        for ref, pid, sensor, motor, flange in (
                (self.ref1, self.pid1, self.sensor1, self.motor1, self.arm.flange1),
                (self.ref2, self.pid2, self.sensor2, self.motor2, self.arm.flange2)):
            yield connect(ref.q, pid.u_s)
            yield connect(sensor.phi, pid.u_m)
            yield connect(pid.y, motor.u)
            yield connect(motor.flange, flange)
            yield connect(sensor.flange, flange)
