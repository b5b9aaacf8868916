"""High-index models compile to index 1 and simulate with IDAS (issue: structural analysis)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import bgmodelica as bg
from bgmodelica.errors import SimulationError
from bgmodelica.passes.index_reduction import reduce_index
from library.examples.constrained import (
    DoublePendulum,
    GearedLoad,
    MotorGearLoad,
    Pendulum,
    PendulumPreferXY,
    RigidInertias,
)

G = 9.81


def theta_reference(times: np.ndarray) -> np.ndarray:
    """Angle from the x axis of the same pendulum in minimal coordinates (L = 1)."""
    sol = solve_ivp(lambda t, s: [s[1], -G * np.cos(s[0])], [times[0], times[-1]], [0.0, 0.0],
                    t_eval=times, rtol=1e-13, atol=1e-13, method="DOP853")
    return sol.y[0]


@pytest.mark.parametrize("cls", [Pendulum, PendulumPreferXY])
def test_pendulum_constraint_energy_and_exact_solution(cls):
    compiled = bg.compile(cls())
    summary = compiled.summary()
    assert summary["structural_index"] == 3
    assert len(summary["states"]) == 2
    r = bg.simulate(compiled, stop_time=10.0, interval=0.01, rtol=1e-12, atol=1e-12)
    x, y, vx, vy = r["x"], r["y"], r["vx"], r["vy"]
    assert np.max(np.abs(x**2 + y**2 - 1.0)) < 1e-8
    energy = 0.5 * (vx**2 + vy**2) + G * y
    assert np.max(np.abs(energy - energy[0])) / (G * 1.0) < 1e-6
    th = theta_reference(r.time)
    assert np.max(np.abs(x - np.cos(th))) < 1e-6
    assert np.max(np.abs(y - np.sin(th))) < 1e-6
    assert r.meta["state_switches"], "the pendulum passes both singular points of x and y"


def test_rigid_inertias_analytic():
    r = bg.simulate(RigidInertias(), stop_time=2.0, rtol=1e-10, atol=1e-12)
    assert np.allclose(r["j2.w"], 3.0 / 3.0 * r.time, rtol=1e-8, atol=1e-10)
    assert np.allclose(r["j1.phi"], 0.5 * r.time**2, rtol=1e-8, atol=1e-10)


def test_geared_load_analytic():
    r = bg.simulate(GearedLoad(), stop_time=1.0, rtol=1e-10, atol=1e-12)
    a_load = 10.0 * 1.0 / (1.0 + 100 * 0.01)
    assert np.allclose(r["load.w"], a_load * r.time, rtol=1e-8, atol=1e-10)
    assert np.allclose(r["motor.w"], 10 * r["load.w"], rtol=1e-10, atol=1e-10)


def test_motor_gear_load_steady_state():
    r = bg.simulate(MotorGearLoad(), stop_time=20.0, rtol=1e-10, atol=1e-12)
    # steady state: 12 = R i + k w_m ; k i n = d w_l ; w_m = n w_l
    k, n, d, R = 0.1, 50.0, 0.01, 1.0
    w_l = 12 * k * n / (R * d + (k * n) ** 2)
    assert abs(r.final("load.w") - w_l) / w_l < 1e-6
    assert abs(r.final("rotor.w") - n * w_l) / (n * w_l) < 1e-6


def test_double_pendulum_keeps_constraints_and_energy():
    r = bg.simulate(DoublePendulum(), stop_time=5.0, interval=0.005, rtol=1e-11, atol=1e-11)
    c1 = r["x1"] ** 2 + r["y1"] ** 2 - 1.0
    c2 = (r["x2"] - r["x1"]) ** 2 + (r["y2"] - r["y1"]) ** 2 - 0.64
    assert max(np.max(np.abs(c1)), np.max(np.abs(c2))) < 1e-8
    e = (0.5 * 1.0 * (r["vx1"] ** 2 + r["vy1"] ** 2) + 0.5 * 0.5 * (r["vx2"] ** 2 + r["vy2"] ** 2)
         + G * (1.0 * r["y1"] + 0.5 * r["y2"]))
    assert np.max(np.abs(e - e[0])) / (G * 1.5) < 1e-6


def test_reduction_is_idempotent():
    compiled = bg.compile(Pendulum())
    again = reduce_index(compiled.reduced)
    assert again.differentiated == []
    assert len(again.model.equations) == len(compiled.reduced.model.equations)
    assert again.states == compiled.reduced.states
    assert again.dummies == compiled.reduced.dummies


def test_check_reports_structure():
    s = bg.compile(DoublePendulum()).summary()
    assert s["structural_index"] == 3
    assert len(s["states"]) == 4 and len(s["dummy_derivatives"]) == 8
    assert s["dynamic_state_selection"] is True
    assert any(loop["size"] > 1 for loop in s["algebraic_loops"])


# -- accuracy independent of the output grid (dynamic state selection inside the run) ---------

def _pendulum_error(res):
    """Largest position error against the angle ODE integrated at 1e-13."""
    from scipy.integrate import solve_ivp

    ref = solve_ivp(lambda _t, s: [s[1], -9.81 * np.sin(s[0])], (0.0, res.time[-1]),
                    [np.pi / 2, 0.0], method="DOP853", rtol=1e-13, atol=1e-13,
                    dense_output=True)
    th = ref.sol(res.time)[0]
    return max(np.max(np.abs(res["x"] - np.sin(th))), np.max(np.abs(res["y"] + np.cos(th))))


@pytest.mark.parametrize("interval", [0.1, 0.01, 0.001])
def test_pendulum_accuracy_independent_of_output_grid(interval):
    compiled = bg.compile(Pendulum())
    res = bg.simulate(compiled, stop_time=5.0, interval=interval)
    assert _pendulum_error(res) <= 1e-4
    assert res.meta["state_switches"]
    # the pivot checks do not depend on the grid: the same switches on every grid
    times = [round(t, 9) for t, _ in res.meta["state_switches"]]
    ref = bg.simulate(compiled, stop_time=5.0, interval=0.1)
    assert times == [round(t, 9) for t, _ in ref.meta["state_switches"]]


def test_pendulum_tight_tolerance():
    res = bg.simulate(Pendulum(), stop_time=5.0, interval=0.01, rtol=1e-10, atol=1e-12)
    assert _pendulum_error(res) <= 1e-7


def test_static_choice_that_degenerates_is_an_error():
    with pytest.raises(SimulationError, match="degenerates at t = 0.58"):
        bg.simulate(Pendulum(), stop_time=5.0, interval=0.01, dynamic=False)


@pytest.mark.parametrize(("cls", "stop", "interval"), [(Pendulum, 5.0, 0.001),
                                                       (DoublePendulum, 1.0, 0.002)])
def test_every_output_time_once_across_state_switches(cls, stop, interval):
    # the switches fall on output times (t = 2.855 s, 3.735 s for the pendulum): none is lost
    res = bg.simulate(cls(), stop_time=stop, interval=interval)
    assert res.meta["state_switches"]
    n = int(round(stop / interval)) + 1
    assert len(res.time) == n
    np.testing.assert_allclose(res.time, np.linspace(0.0, stop, n), rtol=0, atol=1e-12)


def test_consistent_over_specified_start_values_are_accepted():
    # x and y both fixed on the circle: the rod constraint makes one of them redundant
    res = bg.simulate(Pendulum(x={"start": 0.6, "fixed": True}, y={"start": -0.8, "fixed": True}),
                      stop_time=2.0, interval=0.01, rtol=1e-9, atol=1e-10)
    assert any("over-specifies" in n for n in res.meta["init_notes"])
    ref = solve_ivp(lambda _t, s: [s[1], -G * np.sin(s[0])], (0.0, 2.0),
                    [np.arctan2(0.6, 0.8), 0.0], method="DOP853", rtol=1e-12, atol=1e-12,
                    t_eval=res.time)
    np.testing.assert_allclose(res["x"], np.sin(ref.y[0]), atol=1e-5)
    np.testing.assert_allclose(res["y"], -np.cos(ref.y[0]), atol=1e-5)
    rest = bg.simulate(Pendulum(x={"start": 0.0, "fixed": True}, y={"start": -1.0, "fixed": True}),
                       stop_time=1.0)
    assert np.allclose(rest["y"], -1.0) and np.allclose(rest["x"], 0.0)


def test_inconsistent_over_specified_start_values_are_refused():
    from bgmodelica.errors import InitializationError

    with pytest.raises(InitializationError, match=r"over-determined: fixed start value x = 0.5"
                                                  r".*off by"):
        bg.simulate(Pendulum(x={"start": 0.5, "fixed": True}, y={"start": -1.0, "fixed": True}),
                    stop_time=1.0)
