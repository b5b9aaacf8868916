"""The robot's plant without controller (:class:`RobotOpenLoop`: motor voltages in, joint
angles out) against an independent integration of the paper's equations, and start values
set by dotted name (``params={"arm.q1": 0.3}``, ``--set arm.q1=0.3``)."""

from __future__ import annotations

import csv

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from bgmodelica import compile, simulate
from bgmodelica.cli import main as cli_main
from bgmodelica.errors import ParameterError
from library.robots import lagrange
from library.robots.params import ARM, MOTOR
from library.robots.robot import RobotOpenLoop, RobotPID

TIGHT = dict(rtol=1e-10, atol=1e-12, dynamic=False)


@pytest.fixture(scope="module")
def open_loop():
    return compile(RobotOpenLoop())


def plant_rhs(u1: float, u2: float, arm=ARM, motor=MOTOR):
    """Lagrange arm (M, C, G) driven through gears k2 by two DC motors at constant voltages:
    x = [q1, q2, w1, w2, i1, i2];
    (M(q) + Jm k2^2 I) q'' = k1 k2 i - b k2^2 q' - C(q, q') q' - G(q),
    L i' = U - R i - k1 k2 q'."""
    R, L, k1, Jm, b, k2 = (motor[n] for n in ("R", "L", "k1", "Jm", "b", "k2"))
    u = np.array([u1, u2])

    def f(_t, x):
        q, w, cur = x[0:2], x[2:4], x[4:6]
        M = lagrange.mass_matrix(q, arm) + Jm * k2**2 * np.eye(2)
        rhs = (k1 * k2 * cur - b * k2**2 * w - lagrange.coriolis_matrix(q, w, arm) @ w
               - lagrange.gravity_vector(q, arm))
        return np.concatenate([w, np.linalg.solve(M, rhs), (u - R * cur - k1 * k2 * w) / L])

    return f


def test_open_loop_interface(open_loop):
    dae = open_loop.dae
    assert [u.name for u in dae.inputs] == ["U1", "U2"]
    names = {p.name for p in dae.parameters}
    expected = set(ARM) | {f"motor{j}.{n}" for j in (1, 2) for n in MOTOR}
    assert expected <= names
    assert not names & {"Kp1", "Ki1", "Kd1", "Kp2", "Ki2", "Kd2", "Nd", "A1", "f1", "A2",
                        "f2", "Vmax"}
    assert sorted(dae.state_names) == sorted(
        ["arm.joint1.q", "arm.joint1.w", "arm.joint2.q", "arm.joint2.w",
         "motor1.inductor.i", "motor2.inductor.i"])
    assert open_loop.summary()["balanced"] and not dae.algebraic_names
    res = simulate(open_loop, stop_time=0.1, interval=0.05, params={"U1": 3.0, "U2": -1.0},
                   dynamic=False)
    for name in ("arm.q1", "arm.q2", "motor1.i", "motor2.i", "motor1.u", "motor2.u", "q1",
                 "q2"):
        assert res[name].shape == res.time.shape, name
    np.testing.assert_array_equal(res["q1"], res["arm.q1"])
    np.testing.assert_array_equal(res["q2"], res["arm.q2"])
    assert np.all(res["motor1.u"] == 3.0) and np.all(res["motor2.u"] == -1.0)
    for name in ("arm.q1", "arm.q2", "arm.w1", "arm.w2", "motor1.i", "motor2.i"):
        assert res[name][0] == 0.0, name          # at rest, no current


@pytest.mark.parametrize("u, start", [((8.0, -4.0), (0.0, 0.0)), ((6.0, -3.0), (0.3, -0.2))])
def test_open_loop_matches_lagrange(open_loop, u, start):
    """Constant voltages over 1 s against solve_ivp on M, C, G + motor equations."""
    params = {"U1": u[0], "U2": u[1]}
    if any(start):
        params.update({"arm.q1": start[0], "arm.q2": start[1]})
    res = simulate(open_loop, stop_time=1.0, interval=0.01, params=params, **TIGHT)
    ref = solve_ivp(plant_rhs(*u), (0.0, 1.0), [*start, 0.0, 0.0, 0.0, 0.0], method="DOP853",
                    t_eval=res.time, rtol=1e-11, atol=1e-12)
    assert ref.success
    q1, q2, w1, w2, i1, i2 = ref.y
    assert np.max(np.abs(res["arm.q1"] - q1)) < 1e-6
    assert np.max(np.abs(res["arm.q2"] - q2)) < 1e-6
    assert np.max(np.abs(res["arm.w1"] - w1)) < 1e-5
    assert np.max(np.abs(res["arm.w2"] - w2)) < 1e-5
    assert np.max(np.abs(res["motor1.i"] - i1)) < 1e-5
    assert np.max(np.abs(res["motor2.i"] - i2)) < 1e-5
    assert np.ptp(q1) > 0.05            # the arm does move


@pytest.mark.parametrize("model, extra", [(RobotPID, {}),
                                          (RobotOpenLoop, {"U1": 2.0, "U2": 1.0})])
def test_start_by_dotted_name_equals_constructor(model, extra):
    by_name = simulate(compile(model()), stop_time=0.5, interval=0.01,
                       params={"arm.q1": 0.3, "arm.q2": -0.2, **extra}, **TIGHT)
    built = simulate(compile(model(q1=0.3, q2=-0.2)), stop_time=0.5, interval=0.01,
                     params=extra, **TIGHT)
    assert by_name["arm.q1"][0] == 0.3 and by_name["arm.q2"][0] == -0.2
    assert by_name.names == built.names
    for name in by_name.names:
        np.testing.assert_allclose(by_name[name], built[name], rtol=0, atol=1e-12,
                                   err_msg=name)


def test_start_names_state_alias_demoted(open_loop):
    """A state (arm.joint1.q), aliases of states (q2, motor1.i), a variable index reduction
    demoted (the rotor angle motor2.rotor.phi = k2 * arm.q2) and an alias of an input
    (motor2.u is U2) all take start values by name."""
    res = simulate(open_loop, stop_time=0.01, interval=0.01,
                   params={"arm.joint1.q": 0.25, "q2": -0.1, "motor1.i": 0.5, "motor2.u": 1.5},
                   dynamic=False)
    assert res["arm.q1"][0] == 0.25 and res["arm.q2"][0] == -0.1
    assert res["motor1.i"][0] == 0.5 and res["motor1.inductor.i"][0] == 0.5
    assert np.all(res["motor2.u"] == 1.5)
    assert "motor2.rotor.phi" in open_loop.dae.names
    assert "motor2.rotor.phi" not in open_loop.dae.state_names
    # the demoted angle's condition takes precedence over the arm's default rest angle q2 = 0
    with pytest.warns(UserWarning, match="arm.joint2.q = 0"):
        res = simulate(open_loop, stop_time=0.01, interval=0.01,
                       params={"motor2.rotor.phi": -5.0}, dynamic=False)
    assert res["motor2.rotor.phi"][0] == pytest.approx(-5.0, abs=1e-12)
    assert res["arm.q2"][0] == pytest.approx(-5.0 / MOTOR["k2"], abs=1e-12)


def test_start_name_errors(open_loop):
    with pytest.raises(ParameterError, match=r"'arm\.q3'.*did you mean .*arm\.q1"):
        simulate(open_loop, stop_time=0.01, params={"arm.q3": 0.3})
    with pytest.raises(ParameterError, match="conflicting values"):
        simulate(open_loop, stop_time=0.01, params={"arm.q1": 0.3, "q1": 0.2})
    with pytest.raises(ParameterError, match="not a number"):
        simulate(open_loop, stop_time=0.01, params={"arm.q1": "up"})


def test_cli_set_start_values(tmp_path, capsys):
    out = tmp_path / "ol.csv"
    rc = cli_main(["simulate", "library.robots:RobotOpenLoop", "--set", "arm.q1=0.3",
                   "--set", "arm.q2=-0.2", "--set", "U1=2", "--set", "U2=1",
                   "--stop-time", "0.1", "--interval", "0.05", "-o", str(out)])
    assert rc == 0
    with out.open() as fh:
        first = next(csv.DictReader(fh))
    assert float(first["arm.q1"]) == 0.3 and float(first["arm.q2"]) == -0.2
    assert float(first["motor1.u"]) == 2.0
    rc = cli_main(["simulate", "library.robots:RobotOpenLoop", "--set", "arm.q3=1",
                   "-o", str(tmp_path / "x.csv")])
    assert rc == 2 and "did you mean" in capsys.readouterr().err
