"""Bad set-ups are refused before any FMU runs, with messages naming the connectors."""

from __future__ import annotations

import dataclasses
import math

import pytest

from bgmodelica.cosim.errors import (
    AlgebraicLoopError,
    ConnectorMismatchError,
    SetupError,
    UnconnectedInputError,
    UnknownConnectorError,
)
from bgmodelica.cosim.master import Master
from bgmodelica.cosim.ssp import SspConnection, system_from_fmus
from bgmodelica.errors import ModelError
from library.robots.subsystems import robot_connections, robot_system


@pytest.fixture(scope="module")
def blocks(tmp_path_factory):
    """Tiny FMUs: a gain (direct feedthrough) and an integrator (none; its state ``y`` is an
    output, and is exposed as the output ``x`` too)."""
    from bgmodelica.cosim.wrap import expose
    from bgmodelica.fmi.from_model import export_model
    from library.blocks import Gain, Integrator

    out = tmp_path_factory.mktemp("blocks")
    integrator = expose(Integrator(name="Integrator", y_start=1.0), outputs={"x": "y"})
    return {"Gain": export_model(Gain(name="Gain", k=0.5), out, fmu_type="both"),
            "Integrator": export_model(integrator, out, fmu_type="both")}


def _robot(fmus, drop=(), add=()):
    conns = [c for c in robot_connections() if c not in drop] + list(add)
    system = robot_system(fmus)
    system.connections = [SspConnection(*c) for c in conns]
    return system


def test_errors_are_model_errors():
    for cls in (AlgebraicLoopError, ConnectorMismatchError, UnconnectedInputError,
                UnknownConnectorError):
        assert issubclass(cls, SetupError) and issubclass(cls, ModelError)


def test_missing_connection(robot_fmus):
    system = _robot(robot_fmus, drop=[("arm", "w2", "motor2", "w"),
                                      ("arm", "q1", "controller", "q1")])
    with pytest.raises(UnconnectedInputError) as err:
        Master(system)
    assert err.value.inputs == ["controller.q1", "motor2.w"]
    assert "controller.q1" in str(err.value) and "motor2.w" in str(err.value)
    Master(system, allow_unconnected=True)          # explicitly allowed: start values


def test_unit_mismatch(robot_fmus):
    system = _robot(robot_fmus, drop=[("arm", "w1", "motor1", "w")],
                    add=[("arm", "q1", "motor1", "w")])
    with pytest.raises(ConnectorMismatchError,
                       match=r"arm\.q1 -> motor1\.w: unit mismatch, arm\.q1 is in 'rad' "
                             r"and motor1\.w in 'rad/s'"):
        Master(system)


def test_type_mismatch_in_ssd(robot_fmus):
    system = robot_system(robot_fmus)
    arm = system.element("arm")
    arm.connectors = [dataclasses.replace(c, type="Integer") if c.name == "q1" else c
                      for c in arm.connectors]
    with pytest.raises(ConnectorMismatchError, match=r"arm\.q1 is declared Integer"):
        Master(system)


def test_causality_and_duplicates(robot_fmus):
    with pytest.raises(ConnectorMismatchError, match=r"controller\.q1 is a input, not an "
                                                     r"output|controller\.q1 is a input"):
        Master(_robot(robot_fmus, add=[("controller", "q1", "motor1", "u")]))
    with pytest.raises(ConnectorMismatchError, match=r"motor1\.u is a output|motor1\.i is a "
                                                     r"output, not an input"):
        Master(_robot(robot_fmus, add=[("controller", "u1", "motor1", "i")]))
    with pytest.raises(ConnectorMismatchError,
                       match=r"input motor1\.u is driven twice: by controller\.u1 and by "
                             r"controller\.u2"):
        Master(_robot(robot_fmus, add=[("controller", "u2", "motor1", "u")]))


def test_unknown_names(robot_fmus):
    with pytest.raises(UnknownConnectorError, match=r"arm\.q3 does not exist"):
        Master(_robot(robot_fmus, add=[("arm", "q3", "motor1", "u")]))
    with pytest.raises(UnknownConnectorError, match="no element 'gripper'"):
        Master(_robot(robot_fmus, add=[("gripper", "y", "motor1", "u")]))
    system = robot_system(robot_fmus)
    system.element("motor1").parameters["Rx"] = 1.0
    with pytest.raises(UnknownConnectorError, match=r"motor1\.Rx"):
        Master(system)


def test_algebraic_loop(blocks):
    """Two gains in a ring: y1 = k u1, u2 = y1, y2 = k u2, u1 = y2 -- a direct feedthrough
    cycle, reported with the connectors along it."""
    system = system_from_fmus("ring", {"g1": blocks["Gain"], "g2": blocks["Gain"]},
                              [("g1", "y", "g2", "u"), ("g2", "y", "g1", "u")])
    with pytest.raises(AlgebraicLoopError) as err:
        Master(system)
    assert set(err.value.cycle) == {"g1.u", "g1.y", "g2.u", "g2.y"}
    msg = str(err.value)
    assert "algebraic loop" in msg and "g1.y -> g2.u" in msg and "g2.y -> g1.u" in msg


def test_loop_through_a_state_is_fine(blocks):
    """Gain -> integrator -> gain: the integrator's output is a state, no algebraic loop;
    der(x) = k (-x) with the feedback sign in the second gain."""
    system = system_from_fmus(
        "decay", {"g": blocks["Gain"], "i": blocks["Integrator"]},
        [("g", "y", "i", "u"), ("i", "x", "g", "u")], parameters={"g": {"k": -2.0}})
    master = Master(system)
    assert [n for n in master.plan.order if n[2]] == [("i", "x", True), ("i", "y", True),
                                                       ("g", "y", True)]
    res = master.simulate(1.0, 1e-3, order="gauss-seidel", extrapolation=True)
    assert res.final("i.x") == pytest.approx(math.exp(-2.0), rel=1e-5)
    # zero-order hold with the gain's output evaluated at each communication point: the
    # integrator sees u = -2 x_k over the step, i.e. explicit Euler, x_n = (1 - 2h)^n
    coarse = master.simulate(1.0, 1e-2, order="jacobi")
    assert coarse.final("i.x") == pytest.approx((1 - 2e-2) ** 100, rel=1e-12)
    # without propagation the gain's output lags one more step: x_k+1 = x_k - 2h x_k-1
    lag = master.simulate(0.03, 1e-2, order="jacobi", propagate=False)
    assert lag["i.x"] == pytest.approx([1.0, 1.0, 0.98, 0.96])


def test_bad_simulation_options(robot_ssp):
    master = Master(robot_ssp)
    with pytest.raises(SetupError, match="not a multiple"):
        master.simulate(0.01, 3e-3)
    with pytest.raises(SetupError, match="order must be"):
        master.simulate(0.01, 1e-3, order="newton")
    with pytest.raises(SetupError, match="sequence"):
        master.simulate(0.01, 1e-3, order="gauss-seidel", sequence=["arm"])
    with pytest.raises(SetupError, match="no variable 'nope'"):
        master.simulate(0.01, 1e-3, record=["arm.nope"])
    with pytest.raises(SetupError, match="interface"):
        Master(robot_ssp, interface="xx")
