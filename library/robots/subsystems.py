"""The PID robot (:class:`~library.robots.robot.RobotPID`) split into causal subsystems for
co-simulation: two motors, the arm and the controller, each exportable as an FMU.

Coupling (per joint k; default ``coupling="lumped"``)::

    controller --u_k [V]--> motor k --tau_k [N.m]--> arm --q_k, w_k--> controller
                               ^                      |
                               +------w_k [rad/s]-----+

Three exact rearrangements make every subsystem causal and the explicit coupling benign.
None changes the physics: :class:`RobotFromSubsystems` (the subsystems connected back into
one model) reproduces :class:`RobotPID` to the integrator tolerance.

1. *Rotor inertia in the arm.* Each rotor (Jm) is rigidly geared to its joint
   (``w_m = k2 w``). A motor holding Jm could not be driven by the joint speed (its torque
   would need d(w)/dt of an input) and one driven by a torque would need the arm's
   acceleration (an algebraic loop through the mass matrix). The arm therefore carries the
   rigid-gear equivalent ``Jd_k = k2^2 Jm`` on joint k (kinetic energy ``Jm (k2 w)^2 / 2``);
   the motor keeps the armature circuit, the rotor friction ``b`` and the gear and maps the
   joint speed to the joint torque ``tau_shaft = k2 (k1 i - b k2 w)``.
2. *Drive damping in the arm.* Quasi-statically the drive is a torque source with a steep
   speed-torque line, ``tau_shaft ~ k1 k2 u / R - d w`` with ``d = k2^2 (k1^2/R + b)``
   (100 N.m.s/rad): against joint 2's 0.23 kg.m2 that is a 430 rad/s loop, which an explicit
   coupling only survives for macro steps below ~4 ms. The arm holds the linear part as a
   joint damper ``d_k`` (integrated implicitly inside the arm FMU) and the motor sends
   ``tau = tau_shaft + d w`` (output ``tau``; ``tau_shaft`` is output too), which depends on
   the speed only through the armature transient.
3. *Derivative part on the measured speed.* LimPID filters the derivative of the angle:
   ``D = Nd (-q - x_d)``, ``Td x_d' = Nd (-q - x_d)``; with ``q' = w`` this is
   ``(Td/Nd) D' = -Td w - D`` (:class:`RateLimPID`, ``D(0) = 0`` as in LimPID). The
   controller takes the joint speeds from the arm instead of differentiating a sampled and
   held angle (for macro steps above ``Td/Nd`` = 0.5 ms on joint 2 the held angle's steps
   reach the voltage with the gain ``k Nd`` = 4000 V/rad).

``coupling="plain"`` builds the direct split for comparison (motor ``tau_shaft`` to the arm
without dampers, LimPID on the angle: :class:`PIDController`); it is unstable above a few
milliseconds and first order with a ten times larger constant (see ``fmus/README.md``).

Direct feedthrough: the controller's voltages depend directly on the measured angles (P part);
the motor torque on the joint speed; the arm's outputs are states. No algebraic loop.

Subsystems (FMU variable names are the monolithic names below the element name, so results
read ``arm.q1``, ``motor1.i``, ``motor1.inductor.i``, ``controller.pid1.y``):

- :func:`arm_subsystem` (FMU ``Arm``): inputs tau1, tau2 [N.m]; outputs q1, q2 [rad], w1, w2
  [rad/s]; parameters m1 ... g, Jd1, Jd2 [kg.m2], d1, d2 [N.m.s/rad];
- :func:`motor_subsystem` (``Motor``): inputs u [V], w [rad/s]; outputs tau, tau_shaft [N.m],
  i [A], w_m [rad/s]; parameters R, L, k1, b, k2;
- :func:`controller_subsystem` (``Controller``): inputs q1, q2 [rad], w1, w2 [rad/s]; outputs
  u1, u2 [V]; parameters Kp1, Ki1, Kd1, Kp2, Ki2, Kd2, Nd, Vmax, A1, f1, A2, f2
  (``coupling="plain"``: ``ControllerAngleD`` without w1, w2).

:func:`export_robot_setup` builds the FMUs and writes the SSP set-ups (see ``fmus/README.md``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from bgmodelica import (
    Component,
    Input,
    Output,
    Parameter,
    StateSelect,
    Variable,
    connect,
    der,
)
from bgmodelica.core.expressions import fmax, fmin
from bgmodelica.cosim.wrap import FlowInput, FlowOutput, PotentialInput, expose
from library.blocks import LimPID
from library.rotational import Damper, Fixed, Inertia

from .arm import ARM_PARAMETERS, TwoLinkArm
from .motor import GearedMotor
from .params import MOTOR, PID, REFERENCE, VMAX
from .robot import SineReference

__all__ = ["GearedMotor", "DrivenArm", "RateLimPID", "PIDController", "RatePIDController",
           "RobotFromSubsystems", "arm_subsystem", "motor_subsystem", "controller_subsystem",
           "reflected_inertia", "drive_damping", "robot_parameters", "robot_system",
           "build_robot_fmus", "export_robot_setup", "COUPLINGS"]

COUPLINGS = ("lumped", "plain")
_DEFAULT = dict(state_select=StateSelect.DEFAULT)


def reflected_inertia(Jm: float = MOTOR["Jm"], k2: float = MOTOR["k2"]) -> float:
    """Rotor inertia seen at the joint through a rigid gear: ``k2^2 Jm`` [kg.m2]."""
    return float(k2) ** 2 * float(Jm)


def drive_damping(R: float = MOTOR["R"], k1: float = MOTOR["k1"], b: float = MOTOR["b"],
                  k2: float = MOTOR["k2"]) -> float:
    """Slope of the drive's quasi-static speed-torque line at the joint,
    ``k2^2 (k1^2 / R + b)`` [N.m.s/rad]."""
    return float(k2) ** 2 * (float(k1) ** 2 / float(R) + float(b))


def _check_coupling(coupling: str) -> None:
    if coupling not in COUPLINGS:
        raise ValueError(f"coupling must be one of {COUPLINGS}, not {coupling!r}")


class DrivenArm(TwoLinkArm):
    """:class:`~library.robots.arm.TwoLinkArm` with what the drives put on its joints: the
    reflected rotor inertias ``Jd1``, ``Jd2`` [kg.m2] (``k2^2 Jm``, default 0.125;
    sub-components drive1, drive2) and the drives' linear damping ``d1``, ``d2``
    [N.m.s/rad] (``k2^2 (k1^2/R + b)``, default 100.25; ``0`` for the plain coupling;
    sub-components damper1, damper2)."""

    Jd1 = Parameter(reflected_inertia(), unit="kg.m2",
                    description="Rotor inertia of drive 1 reflected to joint 1 (k2^2 Jm)")
    Jd2 = Parameter(reflected_inertia(), unit="kg.m2",
                    description="Rotor inertia of drive 2 reflected to joint 2 (k2^2 Jm)")
    d1 = Parameter(drive_damping(), unit="N.m.s/rad",
                   description="Linear damping of drive 1 at joint 1 (k2^2 (k1^2/R + b))")
    d2 = Parameter(drive_damping(), unit="N.m.s/rad",
                   description="Linear damping of drive 2 at joint 2 (k2^2 (k1^2/R + b))")

    def __init__(self, **modifiers: Any):
        super().__init__(**modifiers)
        self.drive1 = Inertia(J=self.Jd1, phi=dict(_DEFAULT), w=dict(_DEFAULT))
        self.drive2 = Inertia(J=self.Jd2, phi=dict(_DEFAULT), w=dict(_DEFAULT))
        self.damper1 = Damper(d=self.d1)
        self.damper2 = Damper(d=self.d2)
        self.housing1 = Fixed()
        self.housing2 = Fixed()

    def equations(self):
        yield connect(self.drive1.flange_b, self.flange1)
        yield connect(self.drive2.flange_b, self.flange2)
        yield connect(self.damper1.flange_a, self.housing1.flange)
        yield connect(self.damper2.flange_a, self.housing2.flange)
        yield connect(self.damper1.flange_b, self.flange1)
        yield connect(self.damper2.flange_b, self.flange2)


def arm_subsystem(**modifiers: Any) -> DrivenArm:
    """The arm with the drives' reflected inertias and linear damping, driven by the joint
    torques ``tau1``, ``tau2`` (inputs [N.m]) and returning ``q1``, ``q2`` [rad], ``w1``,
    ``w2`` [rad/s] (outputs). FMU model name ``Arm``."""
    arm = DrivenArm(name="Arm", **modifiers)
    return expose(arm, inputs={"tau1": FlowInput("flange1"), "tau2": FlowInput("flange2")},
                  outputs={n: n for n in ("q1", "q2", "w1", "w2")})


def motor_subsystem(**modifiers: Any) -> GearedMotor:
    """A geared motor driven by the voltage ``u`` [V] and the joint speed ``w`` [rad/s]
    (inputs). Outputs: ``tau_shaft = k2 (k1 i - b k2 w)`` [N.m], the torque on the joint;
    ``tau = tau_shaft + d w`` with ``d = k2^2 (k1^2/R + b)`` (the coupling torque when the
    arm holds the damping ``d``); ``i`` [A]; ``w_m`` [rad/s]. FMU model name ``Motor``."""
    motor = GearedMotor("Motor", **modifiers)
    expose(motor, inputs={"w": PotentialInput("flange", order=1)},
           outputs={"tau_shaft": FlowOutput("flange")})
    tau = _output(motor, "tau", "N.m", "Coupling torque tau_shaft + k2^2 (k1^2/R + b) w "
                                       "(the arm holds the linear damping)")
    motor.equation(tau == motor.tau_shaft
                   + motor.k2 ** 2 * (motor.k1 ** 2 / motor.R + motor.b) * motor.w)
    return motor


def _output(component: Component, name: str, unit: str, description: str) -> Any:
    from bgmodelica.cosim.wrap import add_signal

    return add_signal(component, name, Output(unit=unit, description=description))


class RateLimPID(Component):
    """:class:`~library.blocks.LimPID` (``wp = 1``, ``wd = 0``: derivative on the measurement)
    with the measurement's rate ``w_m = der(u_m)`` as an input for the derivative part:

        P = u_s - u_m,  Ti x_i' = u_s - u_m + (y - y_unlim)/(k Ni),
        (Td/Nd) D' = -Td w_m - D,  D(0) = 0,
        y_unlim = k (P + x_i + D),  y = max(y_min, min(y_max, y_unlim)).

    LimPID's ``D = Nd (-u_m - x_d)``, ``Td x_d' = Nd (-u_m - x_d)`` obeys exactly this
    equation when ``w_m = der(u_m)``. Inputs u_s, u_m, w_m; output y; parameters k, Ti, Td,
    Nd, Ni, y_max, y_min; states x_i, D.
    """

    k = Parameter(1.0, description="Proportional gain")
    Ti = Parameter(0.5, unit="s", description="Integral time constant")
    Td = Parameter(0.1, unit="s", description="Derivative time constant")
    Nd = Parameter(10.0, description="Derivative filter: filter time constant is Td/Nd")
    Ni = Parameter(0.9, description="Anti-windup gain (tracking time constant Ni*Ti)")
    y_max = Parameter(1.0, description="Upper output limit")
    y_min = Parameter(-1.0, description="Lower output limit")
    u_s = Input(description="Setpoint")
    u_m = Input(description="Measurement")
    w_m = Input(description="Rate of the measurement, der(u_m)")
    y = Output(description="Limited controller output")
    y_unlim = Variable(description="Controller output before the limiter")
    P = Variable(description="Proportional part (before k)")
    D = Variable(start=0.0, fixed=True, description="Derivative part (before k)")
    x_i = Variable(start=0.0, fixed=True, description="Integral part (before k)")

    def equations(self):
        yield self.P == self.u_s - self.u_m
        yield self.Ti * der(self.x_i) == self.u_s - self.u_m + \
            (self.y - self.y_unlim) / (self.k * self.Ni)
        yield self.Td * der(self.D) == self.Nd * (-self.Td * self.w_m - self.D)
        yield self.y_unlim == self.k * (self.P + self.x_i + self.D)
        yield self.y == fmax(self.y_min, fmin(self.y_max, self.y_unlim))


class PIDController(Component):
    """The robot's two LimPIDs with their sine references, as in :class:`RobotPID`
    (derivative of the measured angle; the ``plain`` coupling).

    Inputs: q1, q2 (measured joint angles [rad]). Outputs: u1, u2 (motor voltages [V]).
    Parameters: Kp1, Ki1, Kd1, Kp2, Ki2, Kd2, Nd, Vmax, A1, f1, A2, f2 (names and defaults of
    :class:`~library.robots.robot.RobotPID`). Variables e1, e2 (tracking errors [rad]).
    Sub-components ref1, ref2 (:class:`SineReference`), pid1, pid2.
    """

    Kp1 = Parameter(PID["Kp1"], unit="V/rad", description="PID proportional gain, joint 1")
    Ki1 = Parameter(PID["Ki1"], unit="V/(rad.s)", description="PID integral gain, joint 1")
    Kd1 = Parameter(PID["Kd1"], unit="V.s/rad", description="PID derivative gain, joint 1")
    Kp2 = Parameter(PID["Kp2"], unit="V/rad", description="PID proportional gain, joint 2")
    Ki2 = Parameter(PID["Ki2"], unit="V/(rad.s)", description="PID integral gain, joint 2")
    Kd2 = Parameter(PID["Kd2"], unit="V.s/rad", description="PID derivative gain, joint 2")
    Nd = Parameter(PID["Nd"], unit="1", description="Derivative filter: T = Kd/(Kp Nd)")
    Vmax = Parameter(VMAX, unit="V", description="Motor voltage limit (PID saturation)")
    A1 = Parameter(REFERENCE["A1"], unit="rad", description="Reference amplitude, joint 1")
    f1 = Parameter(REFERENCE["f1"], unit="Hz", description="Reference frequency, joint 1")
    A2 = Parameter(REFERENCE["A2"], unit="rad", description="Reference amplitude, joint 2")
    f2 = Parameter(REFERENCE["f2"], unit="Hz", description="Reference frequency, joint 2")
    q1 = Input(unit="rad", description="Measured angle of joint 1")
    q2 = Input(unit="rad", description="Measured angle of joint 2")
    u1 = Output(unit="V", description="Voltage command of motor 1")
    u2 = Output(unit="V", description="Voltage command of motor 2")
    e1 = Variable(unit="rad", description="Tracking error q1* - q1")
    e2 = Variable(unit="rad", description="Tracking error q2* - q2")

    def __init__(self, name: str | None = None, **modifiers: Any):
        nested = {k: modifiers.pop(k) for k in list(modifiers) if "." in k}
        super().__init__(name, **modifiers)
        self.ref1 = SineReference(A=self.A1, f=self.f1)
        self.ref2 = SineReference(A=self.A2, f=self.f2)
        for k, (kp, ki, kd) in enumerate(((self.Kp1, self.Ki1, self.Kd1),
                                          (self.Kp2, self.Ki2, self.Kd2)), start=1):
            self.add(f"pid{k}", self._pid(k=kp, Ti=kp / ki, Td=kd / kp, Nd=self.Nd,
                                          y_max=self.Vmax, y_min=-self.Vmax))
        if nested:
            self.modify(**nested)

    def _pid(self, **parameters: Any) -> Component:
        return LimPID(**parameters)

    def equations(self):
        yield connect(self.ref1.q, self.pid1.u_s)
        yield connect(self.ref2.q, self.pid2.u_s)
        yield connect(self.q1, self.pid1.u_m)
        yield connect(self.q2, self.pid2.u_m)
        yield self.u1 == self.pid1.y
        yield self.u2 == self.pid2.y
        yield self.e1 == self.ref1.q - self.q1
        yield self.e2 == self.ref2.q - self.q2


class RatePIDController(PIDController):
    """:class:`PIDController` whose derivative parts act on the measured joint speeds
    ``w1``, ``w2`` (inputs [rad/s]; :class:`RateLimPID`): the same control law."""

    w1 = Input(unit="rad/s", description="Measured speed of joint 1")
    w2 = Input(unit="rad/s", description="Measured speed of joint 2")

    def _pid(self, **parameters: Any) -> Component:
        return RateLimPID(**parameters)

    def equations(self):
        yield connect(self.w1, self.pid1.w_m)
        yield connect(self.w2, self.pid2.w_m)


def controller_subsystem(coupling: str = "lumped", **modifiers: Any) -> PIDController:
    """The controller FMU model: :class:`RatePIDController` named ``Controller``
    (``coupling="plain"``: :class:`PIDController` named ``ControllerAngleD``)."""
    _check_coupling(coupling)
    if coupling == "plain":
        return PIDController("ControllerAngleD", **modifiers)
    return RatePIDController("Controller", **modifiers)


#: Elements of the robot set-up: element name -> FMU factory key, in the Gauss-Seidel order
#: (arm first: controller and motors then see the new angles and speeds at once).
ROBOT_ELEMENTS = {"arm": "Arm", "controller": "Controller", "motor1": "Motor",
                  "motor2": "Motor"}


def robot_connections(coupling: str = "lumped") -> list[tuple[str, str, str, str]]:
    """Connections of the robot set-up: (from element, output, to element, input)."""
    _check_coupling(coupling)
    torque = "tau" if coupling == "lumped" else "tau_shaft"
    out = [("controller", "u1", "motor1", "u"), ("controller", "u2", "motor2", "u"),
           ("motor1", torque, "arm", "tau1"), ("motor2", torque, "arm", "tau2"),
           ("arm", "w1", "motor1", "w"), ("arm", "w2", "motor2", "w"),
           ("arm", "q1", "controller", "q1"), ("arm", "q2", "controller", "q2")]
    if coupling == "lumped":
        out += [("arm", "w1", "controller", "w1"), ("arm", "w2", "controller", "w2")]
    return out


class RobotFromSubsystems(Component):
    """The four subsystems connected back into one model (the connections of the SSP
    set-up). Simulated monolithically it equals :class:`RobotPID`: the split changes no
    physics. Parameters live in the subsystems (``arm.m1``, ``motor1.R``,
    ``controller.Kp1``); the arm's ``Jd_k = k2^2 Jm`` and ``d_k`` are bound to motor k's
    parameters and to the rotor inertia ``Jm`` [kg.m2] (a parameter of this model: the motor
    subsystems leave their rotor inertia to the arm).
    """

    Jm = Parameter(MOTOR["Jm"], unit="kg.m2", description="Rotor inertia of both motors "
                                                           "(lumped into the arm as k2^2 Jm)")

    def __init__(self, coupling: str = "lumped", name: str | None = None, **modifiers: Any):
        _check_coupling(coupling)
        object.__setattr__(self, "coupling", coupling)
        nested = {k: modifiers.pop(k) for k in list(modifiers) if "." in k}
        super().__init__(name, **modifiers)
        self.add("arm", arm_subsystem())
        self.add("motor1", motor_subsystem())
        self.add("motor2", motor_subsystem())
        self.add("controller", controller_subsystem(coupling))
        mods: dict[str, Any] = {}
        for k in (1, 2):
            m = getattr(self, f"motor{k}")
            mods[f"Jd{k}"] = self.Jm * m.k2 ** 2
            mods[f"d{k}"] = m.k2 ** 2 * (m.k1 ** 2 / m.R + m.b) if coupling == "lumped" else 0.0
        self.arm.modify(**mods)
        if nested:
            self.modify(**nested)

    def equations(self):
        for a, out, b, inp in robot_connections(self.coupling):
            yield connect(getattr(getattr(self, a), out), getattr(getattr(self, b), inp))


def robot_parameters(params: dict[str, float] | None = None, coupling: str = "lumped"
                     ) -> dict[str, dict[str, float]]:
    """Per-element parameter values of the set-up (every physical and controller parameter:
    the defaults of :mod:`library.robots.params`, overridden by ``params``).

    ``params`` uses the monolithic names of :class:`RobotPID` (m1, Kp1, motor1.R, motor2.Jm,
    ...); the result maps element -> {FMU parameter: value}, with the arm's ``Jd_k = k2^2 Jm``
    and ``d_k`` (drive damping, 0 for the plain coupling) from motor k. Unknown names raise
    ``KeyError``.
    """
    from .params import ARM

    _check_coupling(coupling)
    out: dict[str, dict[str, float]] = {
        "arm": {n: float(ARM[n]) for n in ARM_PARAMETERS},
        "controller": {**{n: float(v) for n, v in PID.items()},
                       **{n: float(v) for n, v in REFERENCE.items()}, "Vmax": float(VMAX)},
        "motor1": {}, "motor2": {}}
    motor = {k: dict(MOTOR) for k in (1, 2)}
    for name, value in (params or {}).items():
        if name in ARM_PARAMETERS:
            out["arm"][name] = float(value)
        elif name in PID or name in REFERENCE or name == "Vmax":
            out["controller"][name] = float(value)
        elif name[:7] in ("motor1.", "motor2.") and name[7:] in MOTOR:
            motor[int(name[5])][name[7:]] = float(value)
        else:
            raise KeyError(f"unknown robot parameter {name!r}")
    for k in (1, 2):
        mp = motor[k]
        out[f"motor{k}"].update({p: v for p, v in mp.items() if p != "Jm"})
        out["arm"][f"Jd{k}"] = reflected_inertia(mp["Jm"], mp["k2"])
        out["arm"][f"d{k}"] = drive_damping(mp["R"], mp["k1"], mp["b"], mp["k2"]) \
            if coupling == "lumped" else 0.0
    return out


def robot_system(fmus: dict[str, str | Path], params: dict[str, float] | None = None,
                 coupling: str = "lumped", name: str = "robot", step_size: float = 1e-3):
    """The robot set-up as a :class:`bgmodelica.cosim.ssp.SystemStructure` on the FMU files
    ``fmus`` (FMU model name -> path: ``Arm``, ``Motor`` and ``Controller`` or, for the
    plain coupling, ``ControllerAngleD``)."""
    from bgmodelica.cosim.ssp import system_from_fmus

    _check_coupling(coupling)
    ctrl = "Controller" if coupling == "lumped" else "ControllerAngleD"
    missing = [m for m in ("Arm", "Motor", ctrl) if m not in fmus]
    if missing:
        raise KeyError(f"robot_system({coupling!r}) needs the FMU(s) {', '.join(missing)}; "
                       f"build them with build_robot_fmus(couplings=({coupling!r},))")
    files = {el: fmus[ctrl if model == "Controller" else model]
             for el, model in ROBOT_ELEMENTS.items()}
    return system_from_fmus(
        name, files, robot_connections(coupling), parameters=robot_parameters(params, coupling),
        stop_time=10.0, master={"step_size": step_size, "order": "gauss-seidel",
                                "extrapolation": False},
        description=("Two-link robot (Baghli & El Bakkali 2014) under PID control, split into "
                     f"arm, controller and two motors ({coupling} coupling: "
                     + ("rotor inertia and drive damping in the arm, PID derivative on the "
                        "measured speed)" if coupling == "lumped" else
                        "rotor inertia in the arm, motor shaft torque to the arm)")))


_FACTORIES = {
    "Arm": arm_subsystem,
    "Motor": motor_subsystem,
    "Controller": lambda: controller_subsystem("lumped"),
    "ControllerAngleD": lambda: controller_subsystem("plain"),
}


def build_robot_fmus(out_dir: str | Path, fmi_version: int = 2, fmu_type: str = "both",
                     couplings: tuple[str, ...] = ("lumped",), stop_time: float = 10.0,
                     tolerance: float = 1e-8) -> dict[str, Path]:
    """Compile and export the subsystem FMUs into ``out_dir`` (``Arm``, ``Motor``,
    ``Controller``; ``ControllerAngleD`` when ``"plain"`` is in ``couplings``); returns FMU
    model name -> path. ``tolerance`` is the default ``solver.tolerance`` of the embedded
    Co-Simulation solver (tight, so the macro step dominates the error). Needs a C compiler
    (a few seconds per FMU)."""
    from bgmodelica.fmi.from_model import export_model

    for c in couplings:
        _check_coupling(c)
    wanted = ["Arm", "Motor"] + (["Controller"] if "lumped" in couplings else []) \
        + (["ControllerAngleD"] if "plain" in couplings else [])
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    return {name: export_model(_FACTORIES[name](), out, fmi_version=fmi_version,
                               fmu_type=fmu_type, stop_time=stop_time, tolerance=tolerance)
            for name in wanted}


def export_robot_setup(out_dir: str | Path = "fmus", fmi_version: int = 2,
                       params: dict[str, float] | None = None,
                       couplings: tuple[str, ...] = ("lumped", "plain")) -> dict[str, Path]:
    """Build the subsystem FMUs and write the robot's SSP set-ups into ``out_dir``.

    Writes ``robot.ssp`` (the lumped coupling; FMUs with Model Exchange and Co-Simulation
    interfaces, parameter values bound in the SSD), ``robot_plain.ssp`` (the direct split,
    for comparison) and ``robot_container.json`` (the lumped set-up as an ``fmucontainer``
    description next to the FMUs in ``out_dir/cosim``). Returns their paths (keys ``ssp``,
    ``ssp_plain``, ``container_json``) and the FMUs (``Arm``, ``Motor``, ...). Works from a
    clean checkout: the FMUs are built here.
    """
    from bgmodelica.cosim.ssp import write_ssp
    from bgmodelica.cosim.xcheck import container_description

    out = Path(out_dir)
    fmus = build_robot_fmus(out / "cosim", fmi_version=fmi_version, couplings=couplings)
    paths: dict[str, Path] = {}
    if "lumped" in couplings:
        system = robot_system(fmus, params, "lumped")
        paths["ssp"] = write_ssp(system, out / "robot.ssp")
        paths["container_json"] = container_description(
            robot_system(fmus, params, "lumped"), out / "cosim" / "robot_container.json",
            step_size=1e-3, order="gauss-seidel")
    if "plain" in couplings:
        paths["ssp_plain"] = write_ssp(robot_system(fmus, params, "plain", name="robot_plain"),
                                       out / "robot_plain.ssp")
    return {**paths, **fmus}
