"""Signal blocks: sources, algebra, integrator, lags, derivative, LimPID."""

from __future__ import annotations

import numpy as np
import pytest
from library_testing import TIGHT, rel_error
from scipy.linalg import expm

import bgmodelica as bg
from bgmodelica import Component
from library.blocks import (
    Add,
    Constant,
    Derivative,
    Feedback,
    FirstOrder,
    Gain,
    Integrator,
    Limiter,
    LimPID,
    Product,
    Ramp,
    Sine,
    Step,
)


def chain(*pairs: tuple, **blocks) -> Component:
    """A model of ``blocks`` (name=block) joined by ``(from "a.y", to "b.u")`` pairs."""
    m = Component(name="Chain")
    for name, block in blocks.items():
        m.add(name, block)
    for a, b in pairs:
        (ca, sa), (cb, sb) = a.split("."), b.split(".")
        m.connect(getattr(m.children()[ca], sa), getattr(m.children()[cb], sb))
    return m


def test_integrator_of_constant_is_ramp():
    m = chain(("c.y", "integ.u"), c=Constant(k=3.0), integ=Integrator(k=0.5, y_start=2.0))
    result = bg.simulate(m, stop_time=4.0, interval=0.01, **TIGHT)
    assert rel_error(result["integ.y"], 2.0 + 1.5 * result.time) < 1e-9
    # the start value is a tunable fixed start
    result = bg.simulate(m, stop_time=1.0, interval=0.01, params={"integ.y": -1.0}, **TIGHT)
    assert rel_error(result["integ.y"], -1.0 + 1.5 * result.time) < 1e-9


def test_first_order_step_response():
    m = chain(("s.y", "lag.u"), s=Step(height=2.0, offset=0.5, start_time=0.0),
              lag=FirstOrder(k=3.0, T=0.25, y_start=1.5))
    result = bg.simulate(m, stop_time=2.0, interval=1e-3, **TIGHT)
    t = result.time
    y_ss = 3.0 * 2.5
    assert rel_error(result["lag.y"], y_ss + (1.5 - y_ss) * np.exp(-t / 0.25)) < 1e-6


def test_delayed_step_and_ramp_sources():
    m = chain(s=Step(height=2.0, offset=-1.0, start_time=0.5),
              r=Ramp(height=4.0, duration=2.0, offset=1.0, start_time=1.0),
              c=Constant(k=0.0), g=Gain(k=0.0))
    m.connect(m.c.y, m.g.u)
    result = bg.simulate(m, stop_time=4.0, interval=0.25, **TIGHT)
    t = result.time
    # the step is a time event: two rows at t = 0.5, the left limit (-1) then the right (1)
    k = int(np.nonzero(t == 0.5)[0][0])
    assert t[k + 1] == 0.5 and result.meta["event_times"] == [0.5]
    right = np.where(t > 0.5, 1.0, -1.0)
    right[k + 1] = 1.0
    assert np.allclose(result["s.y"], right, rtol=0, atol=1e-12)
    ramp = 1.0 + 4.0 * np.clip((t - 1.0) / 2.0, 0, 1)
    assert np.allclose(result["r.y"], ramp, rtol=0, atol=1e-12)


def test_algebraic_blocks():
    m = chain(("sine.y", "adder.u1"), ("c.y", "adder.u2"), ("adder.y", "gain.u"),
              ("gain.y", "fb.u1"), ("sine.y", "fb.u2"), ("fb.y", "prod.u1"),
              ("sine.y", "prod.u2"), ("prod.y", "lim.u"),
              sine=Sine(amplitude=2.0, f=1.5, phase=0.3, offset=0.1), c=Constant(k=0.7),
              adder=Add(k1=2.0, k2=-1.0), gain=Gain(k=0.5), fb=Feedback(), prod=Product(),
              lim=Limiter(u_max=0.5, u_min=-0.8))
    result = bg.simulate(m, stop_time=1.0, interval=0.01, **TIGHT)
    t = result.time
    s = 0.1 + 2.0 * np.sin(2 * np.pi * 1.5 * t + 0.3)
    add = 2.0 * s - 0.7
    fb = 0.5 * add - s
    assert np.allclose(result["sine.y"], s, rtol=0, atol=1e-12)
    assert np.allclose(result["adder.y"], add, rtol=0, atol=1e-12)
    assert np.allclose(result["fb.y"], fb, rtol=0, atol=1e-12)
    assert np.allclose(result["prod.y"], fb * s, rtol=0, atol=1e-12)
    assert np.allclose(result["lim.y"], np.clip(fb * s, -0.8, 0.5), rtol=0, atol=1e-12)


def test_filtered_derivative_of_ramp():
    m = chain(("r.y", "d.u"), r=Ramp(height=10.0, duration=10.0),
              d=Derivative(k=2.0, T=0.05))
    result = bg.simulate(m, stop_time=1.0, interval=1e-3, **TIGHT)
    assert rel_error(result["d.y"], 2.0 * (1 - np.exp(-result.time / 0.05))) < 1e-6


class Loop(Component):
    """Unit setpoint, a LimPID and a plant ``plant`` (given), plant output fed back."""

    def __init__(self, controller: LimPID, plant: Component, setpoint: float = 1.0, **kw):
        super().__init__(**kw)
        self.setpoint = Step(height=setpoint)
        self.controller = controller
        self.plant = plant
        self.connect(self.setpoint.y, self.controller.u_s)
        self.connect(self.plant.y, self.controller.u_m)
        self.connect(self.controller.y, self.plant.u)


def test_pi_on_integrator_plant_matches_analytic():
    # x' = u, u = k*(e + x_i), Ti*x_i' = e, e = 1 - x with k = 2, Ti = 1:
    # e'' + 2 e' + 2 e = 0, e(0) = 1, e'(0) = -2  =>  x = 1 - exp(-t)*(cos t - sin t)
    loop = Loop(LimPID(controller_type="PI", k=2.0, Ti=1.0, y_max=1e6, y_min=-1e6),
                Integrator())
    result = bg.simulate(loop, stop_time=8.0, interval=1e-3, **TIGHT)
    t = result.time
    assert rel_error(result["plant.y"], 1 - np.exp(-t) * (np.cos(t) - np.sin(t))) < 1e-6
    e = np.exp(-t) * (np.cos(t) - np.sin(t))
    assert rel_error(result["controller.y"], 2 * np.exp(-t) * np.cos(t)) < 1e-6
    assert rel_error(1 - result["plant.y"], e) < 1e-6


def test_pid_on_first_order_plant_matches_linear_solution():
    k, ti, td, nd, tp = 1.5, 0.4, 0.2, 8.0, 0.5
    loop = Loop(LimPID(k=k, Ti=ti, Td=td, Nd=nd, y_max=1e6, y_min=-1e6),
                FirstOrder(k=1.0, T=tp), setpoint=1.0)
    result = bg.simulate(loop, stop_time=5.0, interval=1e-3, **TIGHT)
    # states z = [x (plant), x_i, x_d, r (= 1, constant)], derivative on measurement (wd = 0):
    # D = nd*(-x - x_d), y = k*(r - x + x_i + D), tp x' = y - x, ti x_i' = r - x,
    # (td/nd) x_d' = -x - x_d; D(0) = 0 => x_d(0) = -x(0) = 0.
    a = np.zeros((4, 4))
    y_row = k * np.array([-1 - nd, 1.0, -nd, 1.0])
    a[0] = (y_row - np.array([1.0, 0, 0, 0])) / tp
    a[1] = np.array([-1.0, 0, 0, 1.0]) / ti
    a[2] = np.array([-1.0, 0, -1.0, 0]) * nd / td
    z = np.array([expm(a * tk) @ np.array([0, 0, 0, 1.0]) for tk in result.time])
    assert rel_error(result["plant.y"], z[:, 0]) < 1e-6
    assert rel_error(result["controller.x_i"], z[:, 1]) < 1e-6
    assert rel_error(result["controller.y"], z @ y_row) < 1e-6


def test_parallel_gains_and_controller_types():
    pid = LimPID(Kp=2.0, Ki=4.0, Kd=0.3)
    loop = Loop(pid, FirstOrder())
    params = bg.simulate(loop, stop_time=0.01).parameters
    assert params["controller.k"] == 2.0
    assert params["controller.Ti"] == pytest.approx(0.5)
    assert params["controller.Td"] == pytest.approx(0.15)
    p_only = bg.simulate(Loop(LimPID(controller_type="P", k=3.0, y_max=1e6, y_min=-1e6),
                              FirstOrder()), stop_time=10.0, **TIGHT)
    assert p_only.final("plant.y") == pytest.approx(3.0 / 4.0, rel=1e-8)  # P: offset remains
    assert np.all(p_only["controller.x_i"] == 0) and np.all(p_only["controller.D"] == 0)
    with pytest.raises(ValueError):
        LimPID(controller_type="ID")


def test_limiter_holds_output_in_range():
    loop = Loop(LimPID(controller_type="PID", k=50.0, Ti=0.1, Td=0.05, y_max=0.8, y_min=-0.3),
                FirstOrder(k=2.0, T=0.2), setpoint=1.2)
    result = bg.simulate(loop, stop_time=3.0, interval=1e-3, rtol=1e-8, atol=1e-10)
    y = result["controller.y"]
    assert np.max(y) <= 0.8 + 1e-12 and np.min(y) >= -0.3 - 1e-12
    assert np.max(result["controller.y_unlim"]) > 10.0     # the limits were active
    assert np.isclose(np.max(y), 0.8)
    assert result.final("plant.y") == pytest.approx(1.2, rel=1e-4)


def settling_time(t: np.ndarray, x: np.ndarray, target: float, band: float) -> float:
    outside = np.nonzero(np.abs(x - target) > band * abs(target))[0]
    return float(t[outside[-1] + 1]) if len(outside) else float(t[0])


def test_anti_windup_recovers_faster():
    def run(ni: float):
        loop = Loop(LimPID(controller_type="PI", k=5.0, Ti=0.2, Ni=ni, y_max=1.0, y_min=-1.0),
                    FirstOrder(k=1.0, T=1.0), setpoint=0.8)
        return bg.simulate(loop, stop_time=15.0, interval=1e-3, rtol=1e-8, atol=1e-10)

    with_aw, without = run(0.9), run(1e9)
    t = with_aw.time
    t_aw = settling_time(t, with_aw["plant.y"], 0.8, 0.02)
    t_no = settling_time(t, without["plant.y"], 0.8, 0.02)
    over_aw = np.max(with_aw["plant.y"]) - 0.8
    over_no = np.max(without["plant.y"]) - 0.8
    assert t_aw < 0.7 * t_no
    assert over_aw < 0.5 * over_no
    assert np.max(with_aw["controller.y"]) <= 1.0 + 1e-12
    assert with_aw.final("plant.y") == pytest.approx(0.8, rel=1e-5)


def test_pid_derivative_starts_without_kick():
    loop = Loop(LimPID(k=1.0, Ti=0.5, Td=0.2, y_max=1e6, y_min=-1e6), FirstOrder(y_start=0.3))
    result = bg.simulate(loop, stop_time=0.5, **TIGHT)
    assert result["plant.y"][0] == pytest.approx(0.3)
    assert result["controller.D"][0] == pytest.approx(0.0, abs=1e-12)
    assert result["controller.x_d"][0] == pytest.approx(-0.3)
    assert result["controller.y"][0] == pytest.approx(1.0 - 0.3)
