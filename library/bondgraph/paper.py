"""Bond-graph models of Baghli & El bakkali (2014), "Modeling and Analysis of the Dynamic
Performance of a Robot Manipulator driving by an Electrical Actuator Using Bond Graph
Methodology" (IJMME-IJENS 14(04)): the DC motor (Fig. 6-7), the rotating arm (Fig. 8) and the
two-link manipulator driven by two DC motors (Fig. 9-11).

Conventions
-----------
* Joint angles ``q1`` (link 1 from the horizontal x axis) and ``q2`` (link 2 relative to
  link 1) are variables of the models, integrated from the joint speeds by displacement
  detectors ``Dq1``, ``Dq2`` (Df + integrator) on the joint 1-junctions ``w1``, ``w2``. Gravity
  acts along -y.
* Centre-of-mass velocities (paper Eq. 2, 4) come from modulated transformers on the joint
  speeds (moduli as strings, shown in reports)::

      vx1 = r1 w1,  vy1 = r2 w1,  vx2 = r3 w1 + r4 w2,  vy2 = r5 w1 + r6 w2
      r1 = -lc1 sin q1          r2 = lc1 cos q1
      r3 = -(l1 sin q1 + lc2 sin(q1+q2))    r4 = -lc2 sin(q1+q2)
      r5 = l1 cos q1 + lc2 cos(q1+q2)       r6 = lc2 cos(q1+q2)

  (the paper's Fig. 11 calls them k1..k6). Link 2 rotates at the absolute speed
  ``w12 = w1 + w2`` (0-junction ``s12``), so its inertia I2 sits on the 1-junction ``w12``.
* DC motor (Fig. 6): ``Se:U -> 1:i {R:R, I:L} -> GY:k1 -> 1:wm {I:Jm, R:b} -> TF:k2 -> joint``.
  The reducer follows the project convention: motor speed = k2 x joint speed, joint torque =
  k2 x motor torque; the TF ``gear`` has its port ``p1`` on the joint side (``e1 = k2 e2``,
  ``f2 = k2 f1``), the power flowing motor -> joint.
* SCAP priorities: the link inertias ``Iz1``, ``Iz2`` get integral causality first, so the
  centre-of-mass masses (and, with motors, the rotor inertias geared to the links) are the
  dependent storage elements in derivative causality.

Default parameter values (SI): links m1 = m2 = 1 kg, l1 = l2 = 1 m, lc1 = lc2 = 0.5 m,
I1 = I2 = m l^2/12 = 1/12 kg.m2 (about the centre of mass), g = 9.81 m/s2. Motors: R = 1 Ohm,
L = 0.01 H, k1 = 0.5 N.m/A, Jm = 1e-4 kg.m2, b = 1e-4 N.m.s/rad, k2 = 20, U = 0 V.
"""

from __future__ import annotations

from bgmodelica import Input, Parameter, StateSelect, Variable
from bgmodelica.bondgraph import GY, J0, J1, MTF, TF, BondGraph, Dq, I, R, Se

__all__ = ["DCMotor", "DCMotorDrive", "RotatingArm", "TwoLinkArm", "TwoLinkManipulator",
           "ARM_MODULI"]

ARM_MODULI = {
    "r1": "-lc1*sin(q1)",
    "r2": "lc1*cos(q1)",
    "r3": "-(l1*sin(q1) + lc2*sin(q1 + q2))",
    "r4": "-lc2*sin(q1 + q2)",
    "r5": "l1*cos(q1) + lc2*cos(q1 + q2)",
    "r6": "lc2*cos(q1 + q2)",
}


class DCMotor(BondGraph):
    """Armature-controlled DC motor with reducer (paper Fig. 6), as a word-bond-graph
    subsystem exposing the joint-side port ``shaft`` (power flows out of it).

    Parameters: U [V] armature voltage, R [Ohm], L [H], k1 [N.m/A] torque / back-EMF
    constant, Jm [kg.m2] rotor inertia, b [N.m.s/rad] viscous friction, k2 [1] gear ratio.
    ``suffix`` is appended to the source label (``Se:U1``). States: ``ind.p`` (L i),
    ``rotor.p`` (Jm wm) when in integral causality.
    """

    U = Parameter(0.0, unit="V", description="Armature voltage")
    R = Parameter(1.0, unit="Ohm", description="Armature resistance")
    L = Parameter(0.01, unit="H", description="Armature inductance")
    k1 = Parameter(0.5, unit="N.m/A", description="Torque and back-EMF constant")
    Jm = Parameter(1e-4, unit="kg.m2", description="Rotor inertia")
    b = Parameter(1e-4, unit="N.m.s/rad", description="Rotor viscous friction")
    k2 = Parameter(20.0, unit="1", description="Gear ratio: motor speed / joint speed")

    def __init__(self, name: str | None = None, *, suffix: str = "", **kw) -> None:
        super().__init__(name, **kw)
        self.add("src", Se(E=self.U, label=f"U{suffix}"), at=(0, 0))
        self.add("i", J1(), at=(1.5, 0))
        self.add("res", R(R=self.R), at=(1.5, 1.3))
        self.add("ind", I(I=self.L), at=(1.5, -1.3))
        self.add("gy", GY(r=self.k1), at=(3, 0))
        self.add("wm", J1(), at=(4.5, 0))
        self.add("rotor", I(I=self.Jm), at=(4.5, 1.3))
        self.add("fric", R(R=self.b), at=(4.5, -1.3))
        self.add("gear", TF(m=self.k2), at=(6, 0))
        self.bond(self.src, self.i)
        self.bond(self.i, self.res)
        self.bond(self.i, self.ind)
        self.bond(self.i, self.gy)
        self.bond(self.gy, self.wm)
        self.bond(self.wm, self.rotor)
        self.bond(self.wm, self.fric)
        self.bond(self.wm, "gear.p2")            # motor side: port 2
        self.expose("shaft", "gear.p1", direction="out")


class DCMotorDrive(BondGraph):
    """The DC motor of Fig. 7 driving its joint 1-junction ``wa`` against a load torque
    ``tau_load`` [N.m] (an effort source), with the joint angle ``qa`` measured by a
    displacement detector. Parameters of the motor: ``motor.U``, ``motor.R``, ..."""

    tau_load = Parameter(0.0, unit="N.m", description="Load torque opposing the joint")
    qa = Variable(unit="rad", description="Joint angle", state_select=StateSelect.PREFER)

    def __init__(self, name: str | None = None, **kw) -> None:
        super().__init__(name, **kw)
        self.add("motor", DCMotor(), at=(0, 0))
        self.add("wa", J1(), at=(7.5, 0))
        self.add("load", Se(E=self.tau_load, label="tau_load"), at=(9, 0))
        self.add("Dqa", Dq(), at=(7.5, 1.3))
        self.bond("motor.shaft", self.wa)
        self.bond(self.wa, self.load)
        self.bond(self.wa, self.Dqa)

    def equations(self):
        yield self.qa == self.Dqa.y


class RotatingArm(BondGraph):
    """One rotating link (paper Fig. 8): joint 1-junction ``w1`` with I:I1, MTFs r1, r2 to
    the centre-of-mass velocity junctions ``vx1``, ``vy1`` (I:m1 each, Se:-m1 g on vy1), and
    the joint torque ``tau1`` as a model input (Se:tau1). ``q1`` is the joint angle."""

    m1 = Parameter(1.0, unit="kg", description="Mass of link 1")
    l1 = Parameter(1.0, unit="m", description="Length of link 1")
    lc1 = Parameter(0.5, unit="m", description="Joint to centre of mass of link 1")
    I1 = Parameter(1.0 / 12.0, unit="kg.m2", description="Inertia of link 1 about its CoM")
    g = Parameter(9.81, unit="m/s2", description="Gravity acceleration (along -y)")
    q1 = Variable(unit="rad", description="Joint angle from the x axis",
                  state_select=StateSelect.PREFER)
    tau1 = Input(unit="N.m", description="Joint torque")

    def __init__(self, name: str | None = None, **kw) -> None:
        super().__init__(name, **kw)
        self.add("T1", Se(value=self.tau1, label="tau1"), at=(-1.5, 0))
        self.add("w1", J1(), at=(0, 0))
        self.add("Iz1", I(I=self.I1, priority=1), at=(0, 1.3))
        self.add("Dq1", Dq(), at=(0, -1.3))
        self.add("r1", MTF(m=ARM_MODULI["r1"]), at=(1.5, 0.8))
        self.add("r2", MTF(m=ARM_MODULI["r2"]), at=(1.5, -0.8))
        self.add("vx1", J1(), at=(3, 0.8))
        self.add("vy1", J1(), at=(3, -0.8))
        self.add("mx1", I(I=self.m1), at=(4.5, 0.8))
        self.add("my1", I(I=self.m1), at=(4.5, -0.8))
        self.add("G1", Se(E=-self.m1 * self.g, label="-m1 g"), at=(3, -2.1))
        self.bond(self.T1, self.w1)
        self.bond(self.w1, self.Iz1)
        self.bond(self.w1, self.Dq1)
        self.bond(self.w1, self.r1)
        self.bond(self.r1, self.vx1)
        self.bond(self.vx1, self.mx1)
        self.bond(self.w1, self.r2)
        self.bond(self.r2, self.vy1)
        self.bond(self.vy1, self.my1)
        self.bond(self.G1, self.vy1)

    def equations(self):
        yield self.q1 == self.Dq1.y


class TwoLinkArm(BondGraph):
    """The two-link arm of Fig. 9/11 without motors.

    ``joints="input"`` (default): joint torques are model inputs ``tau1``, ``tau2`` [N.m]
    (Se:tau1, Se:tau2 on ``w1``, ``w2``); ``joints="ports"``: the joint 1-junctions are exposed
    as ports ``joint1``, ``joint2`` for actuators (an unbonded port locks its joint).
    Parameters m1, m2 [kg], l1, l2, lc1, lc2 [m], I1, I2 [kg.m2] (about the centres of mass),
    g [m/s2]. Variables: joint angles ``q1``, ``q2`` [rad]; joint speeds are the common flows
    ``w1.f``, ``w2.f`` [rad/s].
    """

    m1 = Parameter(1.0, unit="kg", description="Mass of link 1")
    m2 = Parameter(1.0, unit="kg", description="Mass of link 2")
    l1 = Parameter(1.0, unit="m", description="Length of link 1")
    l2 = Parameter(1.0, unit="m", description="Length of link 2")
    lc1 = Parameter(0.5, unit="m", description="Joint 1 to centre of mass of link 1")
    lc2 = Parameter(0.5, unit="m", description="Joint 2 to centre of mass of link 2")
    I1 = Parameter(1.0 / 12.0, unit="kg.m2", description="Inertia of link 1 about its CoM")
    I2 = Parameter(1.0 / 12.0, unit="kg.m2", description="Inertia of link 2 about its CoM")
    g = Parameter(9.81, unit="m/s2", description="Gravity acceleration (along -y)")
    q1 = Variable(unit="rad", description="Angle of link 1 from the x axis",
                  state_select=StateSelect.PREFER)
    q2 = Variable(unit="rad", description="Angle of link 2 relative to link 1",
                  state_select=StateSelect.PREFER)

    def __init__(self, name: str | None = None, *, joints: str = "input", **kw) -> None:
        super().__init__(name, **kw)
        if joints not in ("input", "ports", "motors"):
            raise ValueError(f"joints must be 'input' or 'ports', not {joints!r}")
        add = self.add
        add("w1", J1(), at=(0, 0))
        add("w2", J1(), at=(0, -6))
        add("Iz1", I(I=self.I1, priority=1), at=(0, 1.6))
        add("Dq1", Dq(), at=(0.8, -1.6))
        add("Dq2", Dq(), at=(0.8, -7.5))
        add("s12", J0(), at=(-1.3, -3))
        add("w12", J1(), at=(-2.8, -3))
        add("Iz2", I(I=self.I2, priority=1), at=(-4.3, -3))
        add("r1", MTF(m=ARM_MODULI["r1"]), at=(2.3, 2.6))
        add("r2", MTF(m=ARM_MODULI["r2"]), at=(2.3, 1.3))
        add("r5", MTF(m=ARM_MODULI["r5"]), at=(2.3, 0))
        add("r3", MTF(m=ARM_MODULI["r3"]), at=(2.3, -1.3))
        add("r4", MTF(m=ARM_MODULI["r4"]), at=(2.3, -4.7))
        add("r6", MTF(m=ARM_MODULI["r6"]), at=(2.3, -6))
        add("vx1", J1(), at=(4, 2.6))
        add("vy1", J1(), at=(4, 1.3))
        add("mx1", I(I=self.m1), at=(5.6, 2.6))
        add("my1", I(I=self.m1), at=(5.6, 1.3))
        add("G1", Se(E=-self.m1 * self.g, label="-m1 g"), at=(5.6, 0.2))
        add("sx2", J0(), at=(4, -3))
        add("sy2", J0(), at=(4, -4.5))
        add("vx2", J1(), at=(5.6, -3))
        add("vy2", J1(), at=(5.6, -4.5))
        add("mx2", I(I=self.m2), at=(7.2, -3))
        add("my2", I(I=self.m2), at=(7.2, -4.5))
        add("G2", Se(E=-self.m2 * self.g, label="-m2 g"), at=(5.6, -6))
        bond = self.bond
        # joint 1: link rotation, link-1 centre of mass, link-2 terms
        bond(self.w1, self.Iz1)
        bond(self.w1, self.Dq1)
        for mtf, j in (("r1", "vx1"), ("r2", "vy1")):
            bond(self.w1, mtf)
            bond(mtf, j)
        bond(self.vx1, self.mx1)
        bond(self.vy1, self.my1)
        bond(self.G1, self.vy1)
        bond(self.w1, self.r3)
        bond(self.r3, self.sx2)
        bond(self.w1, self.r5)
        bond(self.r5, self.sy2)
        # joint 2
        bond(self.w2, self.Dq2)
        bond(self.w2, self.r4)
        bond(self.r4, self.sx2)
        bond(self.w2, self.r6)
        bond(self.r6, self.sy2)
        # link-2 centre of mass
        bond(self.sx2, self.vx2)
        bond(self.vx2, self.mx2)
        bond(self.sy2, self.vy2)
        bond(self.vy2, self.my2)
        bond(self.G2, self.vy2)
        # link-2 absolute rotation w12 = w1 + w2
        bond(self.w1, self.s12)
        bond(self.w2, self.s12)
        bond(self.s12, self.w12)
        bond(self.w12, self.Iz2)
        if joints == "input":
            from bgmodelica.bondgraph.elements import declare

            tau1 = declare(self, "tau1", Input(unit="N.m", description="Joint 1 torque"))
            tau2 = declare(self, "tau2", Input(unit="N.m", description="Joint 2 torque"))
            add("T1", Se(value=tau1, label="tau1"), at=(-1.5, 0))
            add("T2", Se(value=tau2, label="tau2"), at=(-1.5, -6))
            bond(self.T1, self.w1)
            bond(self.T2, self.w2)
        elif joints == "ports":
            self.expose("joint1", self.w1)
            self.expose("joint2", self.w2)

    def equations(self):
        yield self.q1 == self.Dq1.y
        yield self.q2 == self.Dq2.y


class TwoLinkManipulator(TwoLinkArm):
    """The complete manipulator (paper Fig. 9-10): the two-link arm driven by ``motor1`` and
    ``motor2`` (:class:`DCMotor`, sources Se:U1, Se:U2) through their reducers. Arm parameters
    at the top level (m1, m2, l1, l2, lc1, lc2, I1, I2, g), motor parameters per motor
    (``motor1.R``, ``motor1.L``, ``motor1.k1``, ``motor1.Jm``, ``motor1.b``, ``motor1.k2``,
    ``motor1.U``; same for ``motor2``)."""

    def __init__(self, name: str | None = None, **kw) -> None:
        super().__init__(name, joints="motors", **kw)
        self.add("motor1", DCMotor(suffix="1"), at=(-7.5, 0))
        self.add("motor2", DCMotor(suffix="2"), at=(-7.5, -6))
        self.bond("motor1.shaft", self.w1)
        self.bond("motor2.shaft", self.w2)
