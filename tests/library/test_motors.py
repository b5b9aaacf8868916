"""DC motor examples: analytic linear response, PID speed loop."""

from __future__ import annotations

import numpy as np
from library_testing import TIGHT, rel_error
from scipy.linalg import expm

import bgmodelica as bg
from library.examples import DCMotor, PIDSpeedControl

V, R, L, K, J, D = 12.0, 1.0, 0.01, 0.1, 0.002 + 0.008, 0.001


def motor_solution(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``L i' = V - R i - K w``, ``J w' = K i - D w`` from rest: (i(t), w(t))."""
    a = np.array([[-R / L, -K / L], [K / J, -D / J]])
    x_ss = np.array([D * V, K * V]) / (R * D + K**2)
    x = np.array([x_ss - expm(a * tk) @ x_ss for tk in t])
    return x[:, 0], x[:, 1]


def test_dc_motor_transient():
    result = bg.simulate(DCMotor(), stop_time=3.0, interval=1e-3, **TIGHT)
    i, w = motor_solution(result.time)
    assert rel_error(result["inductor.i"], i) < 1e-6
    assert rel_error(result["rotor.w"], w) < 1e-6
    assert rel_error(result["load.w"], w) < 1e-6
    # electrical time scale: the current peaks within a few L/R = 10 ms, near V/R,
    # long before the speed builds up (mechanical time scale J R/(K^2 + R D) = 0.91 s)
    k_peak = int(np.argmax(result["inductor.i"]))
    assert 0.01 < result.time[k_peak] < 0.06
    assert result["inductor.i"][k_peak] > 0.8 * V / R
    tau_m = J * R / (K**2 + R * D)
    w_ss = K * V / (R * D + K**2)
    k_tau = int(round(tau_m / 1e-3))
    assert abs(result["rotor.w"][k_tau] / w_ss - (1 - np.exp(-1))) < 0.02


def test_dc_motor_steady_state():
    result = bg.simulate(DCMotor(), stop_time=20.0, interval=0.1, **TIGHT)
    w_ss = K * V / (R * D + K**2)
    i_ss = D * V / (R * D + K**2)
    assert abs(result.final("rotor.w") - w_ss) / w_ss < 1e-6
    assert abs(result.final("inductor.i") - i_ss) / i_ss < 1e-6
    # power balance at steady state: V i = R i^2 + D w^2
    assert abs(V * i_ss - R * i_ss**2 - D * w_ss**2) < 1e-9


def test_pid_speed_control_tracks_and_rejects_load():
    result = bg.simulate(PIDSpeedControl(), stop_time=3.0, interval=1e-3, rtol=1e-8,
                         atol=1e-10)
    w = result["rotor.w"]
    u = result["controller.y"]
    assert np.all(u <= 24.0 + 1e-9) and np.all(u >= -24.0 - 1e-9)
    assert np.max(u) == 24.0                    # saturated during the speed-up
    t = result.time
    assert abs(w[np.searchsorted(t, 0.95)] - 100.0) < 2.0    # before the load step
    assert abs(result.final("rotor.w") - 100.0) < 0.05        # load rejected (integral action)
    # with the load torque, the steady-state current carries it: K i = D w + 0.5
    assert abs(result.final("inductor.i") - (D * 100.0 + 0.5) / K) < 0.01
