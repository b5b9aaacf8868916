"""Causality assignment, structural controllability/observability and causal equations, on
the paper's models (Baghli & El bakkali 2014) and on small hand-made graphs."""

from __future__ import annotations

import pytest

from bgmodelica.bondgraph import (
    BGD,
    Graph,
    analyze,
    assign_causality,
    causal_equations,
    controllability,
    graph_of,
    observability,
)
from library.bondgraph import DCMotorDrive, RotatingArm, TwoLinkArm, TwoLinkManipulator


def stroke_at(c, graph, a, b):
    """Name of the end receiving the effort on the bond between a and b."""
    bond = next(x for x in graph.bonds if {x.tail, x.head} == {a, b})
    return c.effort_to[bond.number]


def test_dc_motor_causality_is_fig7():
    g = graph_of(DCMotorDrive())
    c = assign_causality(g)
    assert c.storage == {"motor.ind": "integral", "motor.rotor": "integral"}
    assert c.derivative == [] and c.conflicts == [] and c.loops == [] and c.arbitrary == []
    # Fig. 7: Se:U imposes the effort of 1:i; I:L and I:Jm receive effort (integral);
    # R:R and R:b in resistance causality (flow in, effort out)
    assert stroke_at(c, g, "motor.src", "motor.i") == "motor.i"
    assert stroke_at(c, g, "motor.i", "motor.ind") == "motor.ind"
    assert stroke_at(c, g, "motor.wm", "motor.rotor") == "motor.rotor"
    assert c.resistors == {"motor.res": "resistance", "motor.fric": "resistance"}
    # gyrator: flows in on both sides (efforts out), transformer passes effort through
    assert stroke_at(c, g, "motor.i", "motor.gy") == "motor.i"
    assert stroke_at(c, g, "motor.gy", "motor.wm") == "motor.wm"
    ctrl = controllability(g, c, inputs=["motor.src"])
    obs = observability(g, c)
    assert ctrl.ok and ctrl.rank == ctrl.n == 2
    assert obs.ok and obs.connected_to["motor.rotor"] == ["Dqa"]
    eqs = causal_equations(c)
    text = "\n".join(e.text() for e in eqs.states)
    assert "U - R*p" in text and "k1*p" in text


def test_rotating_arm_centre_of_mass_inertias_in_derivative_causality():
    c = assign_causality(graph_of(RotatingArm()))
    assert c.integral == ["Iz1"]
    assert sorted(c.derivative) == ["mx1", "my1"]
    assert c.conflicts == []


def test_manipulator_causality_controllability_observability():
    m = TwoLinkManipulator()
    rep = analyze(m, inputs=["motor1.src", "motor2.src"], outputs=["Dq1", "Dq2"])
    c = rep.bgi
    assert sorted(c.integral) == ["Iz1", "Iz2", "motor1.ind", "motor2.ind"]
    # the dependent inertias: centre-of-mass masses, and the rotors geared to the links
    assert {"mx1", "my1", "mx2", "my2"} <= set(c.derivative)
    assert sorted(c.derivative) == ["motor1.rotor", "motor2.rotor", "mx1", "mx2", "my1", "my2"]
    assert sorted(c.forced) == sorted(c.derivative)
    assert c.conflicts == [] and c.loops == []
    # Theorem 1 with the two motor voltages U1, U2 as the only inputs
    assert rep.controllability.ok
    assert rep.controllability.unconnected == [] and rep.controllability.rank == 4
    assert {rep.graph.nodes[s].label for xs in rep.controllability.connected_to.values()
            for s in xs} == {"U1", "U2"}
    # Theorem 2 with detectors on the joint angles
    assert rep.observability.ok and rep.observability.rank == 4
    assert set(rep.observability.connected_to["Iz2"]) == {"Dq2", "Dq1"}
    text = rep.to_text()
    for needle in ("derivative causality: mx1 (I:m1)", "Structural controllability (Theorem 1)"
                   ": yes", "Structural observability (Theorem 2): yes", "MTF:r1",
                   "r1 = -lc1*sin(q1)", "causal conflicts: none"):
        assert needle in text, needle
    d = rep.to_dict()
    assert d["controllability"]["ok"] and d["bgi"]["derivative"] == c.derivative
    tex = rep.to_latex()
    assert r"\begin{tabular}" in tex and r"\frac{d}{dt}" in tex


def test_manipulator_without_a_detector_is_not_observable():
    rep = analyze(TwoLinkArm(), outputs=["Dq1"])
    # joint 1 angle alone: still causally connected (coupled arm)
    assert rep.observability.unconnected == []
    g = graph_of(TwoLinkArm())
    del g.nodes["Dq1"], g.nodes["Dq2"]
    g.bonds = [b for b in g.bonds if "Dq1" not in (b.tail, b.head)
               and "Dq2" not in (b.tail, b.head)]
    obs = observability(g)
    assert not obs.ok and sorted(obs.unconnected) == ["Iz1", "Iz2"]


def test_bgd_view_all_storage_derivative():
    g = graph_of(TwoLinkManipulator())
    bgd = assign_causality(g, BGD, check=False)
    assert bgd.integral == []


def rc_ladder() -> Graph:
    g = Graph("ladder")
    for name, kind in (("E", "Se"), ("a", "1"), ("R1", "R"), ("b", "0"), ("R2", "R"),
                       ("c", "1"), ("R3", "R"), ("C", "C")):
        g.add(name, kind)
    for t, h in (("E", "a"), ("a", "R1"), ("a", "b"), ("b", "R2"), ("b", "c"), ("c", "R3"),
                 ("c", "C")):
        g.bond(t, h)
    return g


def test_zero_order_causal_path_is_reported():
    c = assign_causality(rc_ladder())
    assert c.integral == ["C"] and c.conflicts == []
    assert c.arbitrary                        # an R needed an arbitrary choice
    assert len(c.loops) == 1
    assert set(c.loops[0]["resistors"]) >= {"R1", "R2"}


def test_causal_conflict_is_reported():
    g = Graph("two-efforts")
    g.add("E1", "Se")
    g.add("E2", "Se")
    g.add("j", "0")
    g.add("R", "R")
    g.bond("E1", "j")
    g.bond("E2", "j")
    g.bond("j", "R")
    c = assign_causality(g)
    assert [x.element for x in c.conflicts] == ["E2"]
    assert c.conflicts[0].at == "j"


def test_storage_forced_into_derivative_by_a_flow_source():
    g = Graph()
    g.add("F", "Sf")
    g.add("j", "1")
    g.add("m", "I")
    g.bond("F", "j")
    g.bond("j", "m")
    c = assign_causality(g)
    assert c.derivative == ["m"] and c.forced == ["m"]
    assert not controllability(g, c).states


@pytest.mark.parametrize("model", [DCMotorDrive, RotatingArm, TwoLinkArm, TwoLinkManipulator])
def test_reports_render(model):
    rep = analyze(model())
    assert rep.to_text().startswith("Bond graph")
    assert rep.to_dict()["bonds"]
