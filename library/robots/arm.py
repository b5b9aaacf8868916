"""The paper's two-link planar arm (Sec. 3, Fig. 3) in multibody form, built from
:mod:`library.planar`: world -> joint1 -> link1 (body + rod l1) -> joint2 -> link2 (body + rod
l2 to the tip). Angles follow the paper: q1 of link 1 from the world x axis, q2 of link 2
relative to link 1; gravity along -y.
"""

from __future__ import annotations

from bgmodelica import Component, Input, Parameter, StateSelect, Variable, connect
from library.planar import Body, FixedTranslation, Revolute, World
from library.rotational import Flange, Torque

from .params import ARM

__all__ = ["TwoLinkArm", "ArmWithTorques", "ARM_PARAMETERS", "bond_graph_arm"]

#: Top-level parameter names of the arm models (paper Table IV).
ARM_PARAMETERS = ("m1", "m2", "l1", "l2", "lc1", "lc2", "I1", "I2", "g")


class _ArmParameters(Component):
    m1 = Parameter(ARM["m1"], unit="kg", description="Mass of link 1")
    m2 = Parameter(ARM["m2"], unit="kg", description="Mass of link 2")
    l1 = Parameter(ARM["l1"], unit="m", description="Length of link 1")
    l2 = Parameter(ARM["l2"], unit="m", description="Length of link 2")
    lc1 = Parameter(ARM["lc1"], unit="m", description="Joint 1 to centre of mass of link 1")
    lc2 = Parameter(ARM["lc2"], unit="m", description="Joint 2 to centre of mass of link 2")
    I1 = Parameter(ARM["I1"], unit="kg.m2", description="Inertia of link 1 about its COM")
    I2 = Parameter(ARM["I2"], unit="kg.m2", description="Inertia of link 2 about its COM")
    g = Parameter(ARM["g"], unit="m/s2", description="Gravity acceleration (along -y)")


class TwoLinkArm(_ArmParameters):
    """Two-link planar arm, multibody form.

    Connectors: ``flange1``, ``flange2`` (rotational; drive joints 1 and 2; unconnected =
    free joint). Parameters (paper names): m1, m2 [kg], l1, l2, lc1, lc2 [m], I1, I2 [kg.m2],
    g [m/s2]. States (PREFER): q1, q2 [rad], w1, w2 [rad/s] with fixed start values (default 0;
    ``TwoLinkArm(q1=0.3)``). Other variables: joint1/joint2 (Revolute) accelerations ``a`` and
    torques ``tau``, link bodies' Cartesian positions, tip position ``tip.x``, ``tip.y``.
    Subcomponents: world, joint1, link1 (Body), rod1 (FixedTranslation l1), joint2, link2, rod2.
    """

    q1 = Variable(start=0.0, fixed=True, unit="rad", description="Angle of link 1 (from x)",
                  state_select=StateSelect.PREFER)
    q2 = Variable(start=0.0, fixed=True, unit="rad", description="Angle of link 2 (relative)",
                  state_select=StateSelect.PREFER)
    w1 = Variable(start=0.0, fixed=True, unit="rad/s", description="Joint 1 speed",
                  state_select=StateSelect.PREFER)
    w2 = Variable(start=0.0, fixed=True, unit="rad/s", description="Joint 2 speed",
                  state_select=StateSelect.PREFER)
    flange1 = Flange()
    flange2 = Flange()

    def __init__(self, **modifiers):
        super().__init__(**modifiers)
        self.world = World(g=self.g)
        self.joint1 = Revolute()
        self.link1 = Body(m=self.m1, I=self.I1, rcx=self.lc1, g=self.g)
        self.rod1 = FixedTranslation(rx=self.l1)
        self.joint2 = Revolute()
        self.link2 = Body(m=self.m2, I=self.I2, rcx=self.lc2, g=self.g)
        self.rod2 = FixedTranslation(rx=self.l2)

    def equations(self):
        yield connect(self.world.frame_b, self.joint1.frame_a)
        yield connect(self.joint1.frame_b, self.link1.frame_a)
        yield connect(self.joint1.frame_b, self.rod1.frame_a)
        yield connect(self.rod1.frame_b, self.joint2.frame_a)
        yield connect(self.joint2.frame_b, self.link2.frame_a)
        yield connect(self.joint2.frame_b, self.rod2.frame_a)
        yield connect(self.flange1, self.joint1.flange)
        yield connect(self.flange2, self.joint2.flange)
        yield self.q1 == self.joint1.q
        yield self.q2 == self.joint2.q
        yield self.w1 == self.joint1.w
        yield self.w2 == self.joint2.w


class ArmWithTorques(_ArmParameters):
    """The multibody arm driven by the joint torques ``tau1``, ``tau2`` [N.m], top-level
    inputs of the model (held constant over a simulation; set with ``params``). Used to
    extract M, C, G from the compiled model and to check it against the Lagrange formulas.

    Parameters: the arm's (m1 ... g, bound to arm.*). Subcomponents: arm (:class:`TwoLinkArm`),
    torque1, torque2 (rotational Torque sources on the joint flanges).
    """

    tau1 = Input(unit="N.m", description="Joint 1 torque")
    tau2 = Input(unit="N.m", description="Joint 2 torque")

    def __init__(self, **modifiers):
        arm_mods = {k: modifiers.pop(k) for k in list(modifiers)
                    if k in ("q1", "q2", "w1", "w2")}
        super().__init__(**modifiers)
        self.arm = TwoLinkArm(**{n: getattr(self, n) for n in ARM_PARAMETERS}, **arm_mods)
        self.torque1 = Torque()
        self.torque2 = Torque()

    def equations(self):
        yield connect(self.tau1, self.torque1.tau)
        yield connect(self.tau2, self.torque2.tau)
        yield connect(self.torque1.flange, self.arm.flange1)
        yield connect(self.torque2.flange, self.arm.flange2)


def bond_graph_arm(**modifiers) -> Component:
    """The paper's bond-graph arm (:class:`library.bondgraph.paper.TwoLinkArm`, Fig. 9/11) as a
    drop-in for :class:`TwoLinkArm`: same parameters (m1 ... g), rotational ``flange1``,
    ``flange2`` (through :class:`library.bondgraph.adapters.FlangeAdapter` on the joint
    1-junctions) and variables q1, q2 [rad], w1, w2 [rad/s] (fixed start values, default 0;
    give q1, q2 to the constructor, not to ``simulate(params=...)``: the adapters' flange
    angles, which integrate the same joint speeds, start from them too).
    States: the joint angles (displacement detectors Dq1, Dq2) and the link momenta Iz1.p,
    Iz2.p chosen by the bond graph's causality. Imported lazily: needs
    :mod:`library.bondgraph`.
    """
    from bgmodelica.bondgraph import BondGraph
    from library.bondgraph.adapters import FlangeAdapter
    from library.bondgraph.paper import TwoLinkArm as BGTwoLinkArm

    class BondGraphArm(BondGraph, _ArmParameters):
        """Two-link arm, bond-graph form, with rotational joint flanges."""

        q1 = Variable(start=0.0, fixed=True, unit="rad", description="Angle of link 1")
        q2 = Variable(start=0.0, fixed=True, unit="rad", description="Angle of link 2 (rel.)")
        w1 = Variable(start=0.0, fixed=True, unit="rad/s", description="Joint 1 speed")
        w2 = Variable(start=0.0, fixed=True, unit="rad/s", description="Joint 2 speed")
        flange1 = Flange()
        flange2 = Flange()

        def __init__(self, name=None, **mods):
            super().__init__(name, **mods)
            self.add("bg", BGTwoLinkArm(joints="ports",
                                        **{n: getattr(self, n) for n in ARM_PARAMETERS}))
            # the adapters integrate the joint speeds into their flange angles: start them at
            # the joint angles' start values (constructor modifiers q1=..., q2=...)
            for k, q in ((1, self._symbols["q1"]), (2, self._symbols["q2"])):
                self.add(f"drive{k}", FlangeAdapter(**{"flange.phi": dict(
                    start=float(q.decl.start), fixed=bool(q.decl.fixed))}))
            self.bond("bg.joint1", self.drive1)
            self.bond("bg.joint2", self.drive2)

        def equations(self):
            yield connect(self.flange1, self.drive1.flange)
            yield connect(self.flange2, self.drive2.flange)
            yield self.q1 == self.bg.q1
            yield self.q2 == self.bg.q2
            yield self.w1 == self.bg.w1.f
            yield self.w2 == self.bg.w2.f

    return BondGraphArm(**modifiers)
