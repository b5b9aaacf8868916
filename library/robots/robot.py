"""Closed-loop robots of the paper: the two-link arm driven by two geared DC motors.

- :class:`RobotPID` (paper Sec. 9, Fig. 13-15): one PID per joint on the motor voltage, tracking
  ``q_i* = A_i sin(2 pi f_i t)``; the PID output saturates at ``+-Vmax``.
- :class:`RobotComputedTorque` (paper Sec. 8, Fig. 12): joint torques from a computed-torque
  feedforward on the desired trajectory, ``M(q*) q*'' + C(q*, q*') q*' + G(q*)``, plus PD
  feedback; M, C and G are *extracted from the compiled multibody arm* (see
  :func:`arm_dynamics_functions`), not typed in.
- :class:`RobotOpenLoop`: the same arm and motors as :class:`RobotPID` without controller or
  references; the motor voltages ``U1``, ``U2`` are model inputs, the joint angles ``q1``,
  ``q2`` model outputs (the plant of the PID loop, e.g. for an FMU or identification).

Parameters at the top level follow the paper: m1, m2, l1, l2, lc1, lc2, I1, I2, g (arm),
motor1.* / motor2.* (R, L, k1, Jm, b, k2), Kp1, Ki1, Kd1, Kp2, Ki2, Kd2 (PID), A1, f1, A2, f2
(references), Vmax; computed torque: model.m1 ... model.g. Defaults and sources:
:mod:`library.robots.params`.
"""

from __future__ import annotations

import math
from functools import lru_cache

import casadi as ca

from bgmodelica import (
    Component,
    Input,
    Output,
    Parameter,
    Variable,
    compile,
    connect,
    cos,
    sin,
    time,
)
from library.blocks import LimPID
from library.rotational import AngleSensor, Torque

from .arm import ARM_PARAMETERS, ArmWithTorques, TwoLinkArm, _ArmParameters, bond_graph_arm
from .motor import DCMotor
from .params import PID, REFERENCE, VMAX

__all__ = ["RobotPID", "RobotOpenLoop", "RobotComputedTorque", "SineReference",
           "arm_dynamics_functions"]

_TWO_PI = 2 * math.pi


class SineReference(Component):
    """Joint reference ``q = A sin(2 pi f t + phase)`` with its exact derivatives.

    Outputs: q [rad], qd [rad/s], qdd [rad/s2]. Parameters: A [rad], f [Hz], phase [rad].
    """

    A = Parameter(1.0, unit="rad", description="Amplitude")
    f = Parameter(0.25, unit="Hz", description="Frequency")
    phase = Parameter(0.0, unit="rad", description="Phase at t = 0")
    q = Output(unit="rad", description="Reference angle")
    qd = Output(unit="rad/s", description="Reference speed")
    qdd = Output(unit="rad/s2", description="Reference acceleration")

    def equations(self):
        om = _TWO_PI * self.f
        arg = om * time + self.phase
        yield self.q == self.A * sin(arg)
        yield self.qd == self.A * om * cos(arg)
        yield self.qdd == -self.A * om * om * sin(arg)


class _RobotArm(_ArmParameters):
    """Arm parameters at the top level and the arm.

    ``arm="multibody"`` (default): :class:`~library.robots.arm.TwoLinkArm` built from
    :mod:`library.planar`; ``arm="bondgraph"``: the paper's bond graph
    (:func:`~library.robots.arm.bond_graph_arm`). Start values ``q1``, ``q2``, ``w1``, ``w2``
    go to the arm; dotted modifiers (``**{"motor1.R": 2}``) reach the subcomponents.
    Subclasses add their parts in :meth:`_build`.
    """

    def __init__(self, arm: str = "multibody", **modifiers):
        if arm not in ("multibody", "bondgraph"):
            raise ValueError(f"arm must be 'multibody' or 'bondgraph', not {arm!r}")
        # start values of the arm (q1=..., w1=...) and dotted modifiers of subcomponents
        # (motor1.R=..., model.m2=...) apply once the subcomponents exist
        starts = {k: modifiers.pop(k) for k in list(modifiers) if k in ("q1", "q2", "w1", "w2")}
        nested = {k: modifiers.pop(k) for k in list(modifiers) if "." in k}
        super().__init__(**modifiers)
        make_arm = TwoLinkArm if arm == "multibody" else bond_graph_arm
        self.arm = make_arm(**{n: getattr(self, n) for n in ARM_PARAMETERS}, **starts)
        self._build()
        if nested:
            self.modify(**nested)

    def _build(self) -> None:
        """Add the drive (and controller) subcomponents."""


class _RobotBase(_RobotArm):
    """:class:`_RobotArm` plus the two joint references ref1, ref2 and the tracking errors."""

    A1 = Parameter(REFERENCE["A1"], unit="rad", description="Reference amplitude, joint 1")
    f1 = Parameter(REFERENCE["f1"], unit="Hz", description="Reference frequency, joint 1")
    A2 = Parameter(REFERENCE["A2"], unit="rad", description="Reference amplitude, joint 2")
    f2 = Parameter(REFERENCE["f2"], unit="Hz", description="Reference frequency, joint 2")
    e1 = Variable(unit="rad", description="Tracking error q1* - q1")
    e2 = Variable(unit="rad", description="Tracking error q2* - q2")

    def _build(self) -> None:
        self.ref1 = SineReference(A=self.A1, f=self.f1)
        self.ref2 = SineReference(A=self.A2, f=self.f2)
        self._build_control()

    def _build_control(self) -> None:
        """Add the drive and controller subcomponents."""

    def equations(self):
        yield self.e1 == self.ref1.q - self.arm.q1
        yield self.e2 == self.ref2.q - self.arm.q2


class RobotPID(_RobotBase):
    """The paper's PID-controlled robot (Fig. 13): per joint a LimPID (Modelica form, derivative
    on the measurement with filter time constant Kd/(Kp Nd), back-calculation anti-windup,
    output limited to +-Vmax) drives the motor voltage; angle sensors on the joints close the
    loop; the motors drive the arm's joint flanges through their gears.

    Parameters (top level): m1, m2, l1, l2, lc1, lc2, I1, I2, g; Kp1, Ki1, Kd1, Kp2, Ki2, Kd2
    [V/rad, V/(rad.s), V.s/rad]; A1, f1, A2, f2 (references); Vmax [V]; motor1.*, motor2.*:
    R, L, k1, Jm, b, k2. Subcomponents: arm, motor1, motor2, pid1, pid2, ref1, ref2, sensor1,
    sensor2. Variables of interest: arm.q1, arm.q2, ref1.q, ref2.q, e1, e2, motor1.i,
    motor2.i, motor1.u, motor2.u.
    States: arm.joint1.q/w, arm.joint2.q/w, motor currents, PID integral and filter states.

    ``saturate=False`` makes the default Vmax 1e6 V (no saturation in practice);
    ``arm="bondgraph"`` uses the paper's bond-graph arm instead of the multibody one.
    """

    Kp1 = Parameter(PID["Kp1"], unit="V/rad", description="PID proportional gain, joint 1")
    Ki1 = Parameter(PID["Ki1"], unit="V/(rad.s)", description="PID integral gain, joint 1")
    Kd1 = Parameter(PID["Kd1"], unit="V.s/rad", description="PID derivative gain, joint 1")
    Kp2 = Parameter(PID["Kp2"], unit="V/rad", description="PID proportional gain, joint 2")
    Ki2 = Parameter(PID["Ki2"], unit="V/(rad.s)", description="PID integral gain, joint 2")
    Kd2 = Parameter(PID["Kd2"], unit="V.s/rad", description="PID derivative gain, joint 2")
    Nd = Parameter(PID["Nd"], unit="1", description="Derivative filter: T = Kd/(Kp Nd)")
    Vmax = Parameter(VMAX, unit="V", description="Motor voltage limit (PID saturation)")

    def __init__(self, saturate: bool = True, **modifiers):
        if not saturate:
            modifiers.setdefault("Vmax", 1e6)
        super().__init__(**modifiers)

    def _build_control(self) -> None:
        self.motor1 = DCMotor()
        self.motor2 = DCMotor()
        self.sensor1 = AngleSensor()
        self.sensor2 = AngleSensor()
        for k, (kp, ki, kd) in enumerate(((self.Kp1, self.Ki1, self.Kd1),
                                          (self.Kp2, self.Ki2, self.Kd2)), start=1):
            self.add(f"pid{k}", LimPID(k=kp, Ti=kp / ki, Td=kd / kp, Nd=self.Nd,
                                       y_max=self.Vmax, y_min=-self.Vmax))

    def equations(self):
        for ref, pid, sensor, motor, flange in (
                (self.ref1, self.pid1, self.sensor1, self.motor1, self.arm.flange1),
                (self.ref2, self.pid2, self.sensor2, self.motor2, self.arm.flange2)):
            yield connect(ref.q, pid.u_s)
            yield connect(sensor.phi, pid.u_m)
            yield connect(pid.y, motor.u)
            yield connect(motor.flange, flange)
            yield connect(sensor.flange, flange)


class RobotOpenLoop(_RobotArm):
    """The PID robot's plant: the same arm and geared DC motors as :class:`RobotPID`, without
    controller or references. The motor voltages are the top-level inputs ``U1``, ``U2`` [V]
    (held constant over a simulation; ``--set U1=2``); the joint angles the top-level outputs
    ``q1``, ``q2`` [rad] (= arm.q1, arm.q2).

    Parameters (top level): m1, m2, l1, l2, lc1, lc2, I1, I2, g; motor1.*, motor2.*: R, L, k1,
    Jm, b, k2. Subcomponents: arm, motor1, motor2. Variables of interest (named as in
    :class:`RobotPID`): arm.q1, arm.q2, arm.w1, arm.w2, motor1.i, motor2.i, motor1.u,
    motor2.u. Starts at rest at q = (0, 0) with zero currents; other start angles with
    ``RobotOpenLoop(q1=0.3)`` or ``simulate(..., params={"arm.q1": 0.3})``.
    States: arm.joint1.q/w, arm.joint2.q/w, motor currents. ``arm="bondgraph"`` uses the
    paper's bond-graph arm.
    """

    U1 = Input(unit="V", description="Motor 1 armature voltage")
    U2 = Input(unit="V", description="Motor 2 armature voltage")
    q1 = Output(unit="rad", description="Joint 1 angle (link 1 from the x axis)")
    q2 = Output(unit="rad", description="Joint 2 angle (link 2 relative to link 1)")

    def _build(self) -> None:
        self.motor1 = DCMotor()
        self.motor2 = DCMotor()

    def equations(self):
        yield connect(self.U1, self.motor1.u)
        yield connect(self.U2, self.motor2.u)
        yield connect(self.motor1.flange, self.arm.flange1)
        yield connect(self.motor2.flange, self.arm.flange2)
        yield self.q1 == self.arm.q1
        yield self.q2 == self.arm.q2


# -- computed torque -------------------------------------------------------------------------

@lru_cache(maxsize=1)
def arm_dynamics_functions() -> dict[str, ca.Function]:
    """M(q, p), h(q, w, p) = C(q, w) w + G(q, p), G(q, p) of the *compiled multibody arm*.

    The arm is compiled with the joint torques as model inputs; its ODE right-hand side gives
    the joint accelerations ``a(q, w, tau) = M^-1 (tau - h)``, affine in tau. Hence
    ``M^-1 = da/dtau`` and ``h = -M a(q, w, 0)``; ``G = h(q, 0)``. ``p`` stacks the arm
    parameters in :data:`library.robots.arm.ARM_PARAMETERS` order. Returns CasADi Functions
    ``M``, ``h``, ``G``, ``C`` (``C(q, w, p) @ w = h - G``; C is the Christoffel form, exact on
    this arm since the velocity terms are quadratic) and ``inverse`` (``tau(q, w, a, p)``).
    """
    compiled = compile(ArmWithTorques())
    dae = compiled.dae
    names = dae.state_names
    pos = {n: names.index(f"arm.joint{n[-1]}.{n[0]}") for n in ("q1", "q2", "w1", "w2")}
    q = ca.SX.sym("q", 2)
    w = ca.SX.sym("w", 2)
    tau = ca.SX.sym("tau", 2)
    p = ca.SX.sym("p", len(ARM_PARAMETERS))
    x_full = [None] * len(names)
    x_full[pos["q1"]], x_full[pos["q2"]] = q[0], q[1]
    x_full[pos["w1"]], x_full[pos["w2"]] = w[0], w[1]
    if any(v is None for v in x_full) or dae.z.numel():
        raise RuntimeError(f"unexpected states of the compiled arm: {names}")
    pvec = []
    for k, pp in enumerate(dae.parameters):
        pvec.append(p[ARM_PARAMETERS.index(pp.name)] if pp.name in ARM_PARAMETERS
                    else float(dae.p_default[k]))
    inputs = {u.name: tau[int(u.name[-1]) - 1] for u in dae.inputs}
    pvec += [inputs[u.name] for u in dae.inputs]
    f = ca.Function("arm_ode", [dae.x, dae.p, dae.t], [dae.ode])
    xd = f(ca.vertcat(*x_full), ca.vertcat(*pvec), 0)
    acc = ca.vertcat(xd[pos["w1"]], xd[pos["w2"]])
    minv = ca.jacobian(acc, tau)
    a0 = ca.substitute(acc, tau, ca.DM.zeros(2))
    M = ca.inv(minv)
    h = -ca.mtimes(M, a0)
    G = ca.substitute(h, w, ca.DM.zeros(2))
    # C with C w = h - G: h - G is quadratic in w, C = 1/2 d(h - G)/dw (exact for quadratics)
    C = 0.5 * ca.jacobian(h - G, w)
    acc_in = ca.SX.sym("a", 2)
    return {
        "M": ca.Function("M", [q, p], [M], ["q", "p"], ["M"]),
        "h": ca.Function("h", [q, w, p], [h], ["q", "w", "p"], ["h"]),
        "G": ca.Function("G", [q, p], [G], ["q", "p"], ["G"]),
        "C": ca.Function("C", [q, w, p], [C], ["q", "w", "p"], ["C"]),
        "inverse": ca.Function("tau", [q, w, acc_in, p], [ca.mtimes(M, acc_in) + h],
                               ["q", "w", "a", "p"], ["tau"]),
    }


class RobotComputedTorque(_RobotBase):
    """Computed-torque control of the arm (paper Fig. 12), torques applied at the joints:

        tau = M(q*) q*'' + C(q*, q*') q*' + G(q*) + Kp (q* - q) + Kd (q*' - q')      (feedforward)
        tau = M(q) (q*'' + Kp e + Kd e') + C(q, q') q' + G(q)     (mode="inverse_dynamics")

    M, C, G are the compiled multibody arm's (:func:`arm_dynamics_functions`) evaluated with
    the controller's model parameters model.m1 ... model.g (default: bound to the arm's own,
    i.e. a perfect model; ``RobotComputedTorque(**{"model.m2": 1.5})`` makes it imperfect).
    Parameters: the arm's; Kp1, Kd1, Kp2, Kd2 (PD, [N.m/rad], [N.m.s/rad] in feedforward
    mode, [1/s2], [1/s] in inverse-dynamics mode); A1, f1, A2, f2; model.m1 ... model.g.
    Inputs: none. Variables: tau1, tau2 [N.m], e1, e2 [rad].
    """

    Kp1 = Parameter(400.0, description="PD proportional gain, joint 1")
    Kd1 = Parameter(40.0, description="PD derivative gain, joint 1")
    Kp2 = Parameter(400.0, description="PD proportional gain, joint 2")
    Kd2 = Parameter(40.0, description="PD derivative gain, joint 2")
    tau1 = Output(unit="N.m", description="Joint 1 torque command")
    tau2 = Output(unit="N.m", description="Joint 2 torque command")

    def __init__(self, mode: str = "feedforward", **modifiers):
        if mode not in ("feedforward", "inverse_dynamics"):
            raise ValueError(f"mode must be 'feedforward' or 'inverse_dynamics', not {mode!r}")
        object.__setattr__(self, "mode", mode)
        super().__init__(**modifiers)

    def _build_control(self) -> None:
        self.model = _ModelParameters(**{n: getattr(self, n) for n in ARM_PARAMETERS})
        self.torque1 = Torque()
        self.torque2 = Torque()

    def equations(self):
        fns = arm_dynamics_functions()
        p = ca.vertcat(*[getattr(self.model, n) for n in ARM_PARAMETERS])
        qr = ca.vertcat(self.ref1.q, self.ref2.q)
        wr = ca.vertcat(self.ref1.qd, self.ref2.qd)
        ar = ca.vertcat(self.ref1.qdd, self.ref2.qdd)
        q = ca.vertcat(self.arm.q1, self.arm.q2)
        w = ca.vertcat(self.arm.w1, self.arm.w2)
        kp = ca.vertcat(self.Kp1, self.Kp2)
        kd = ca.vertcat(self.Kd1, self.Kd2)
        e, ed = qr - q, wr - w
        if self.mode == "feedforward":
            tau = fns["inverse"](qr, wr, ar, p) + kp * e + kd * ed
        else:
            tau = fns["inverse"](q, w, ar + kp * e + kd * ed, p)
        yield self.tau1 == tau[0]
        yield self.tau2 == tau[1]
        yield connect(self.tau1, self.torque1.tau)
        yield connect(self.tau2, self.torque2.tau)
        yield connect(self.torque1.flange, self.arm.flange1)
        yield connect(self.torque2.flange, self.arm.flange2)


#: The controller's model of the arm (``model.m1`` ...), bound to the arm's values by default.
_ModelParameters = type("ModelParameters", (Component,), {
    "__doc__": "The computed-torque controller's model of the arm parameters.",
    **{n: Parameter(0.0, description=f"Controller's model value of {n}")
       for n in ARM_PARAMETERS}})
