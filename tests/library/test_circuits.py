"""Example circuits against their analytic solutions."""

from __future__ import annotations

import numpy as np
from library_testing import TIGHT, rel_error

import bgmodelica as bg
from library.examples import RC, SeriesRLC


def test_rc_time_constant():
    result = bg.simulate(RC(), stop_time=5.0, interval=1e-3, **TIGHT)
    t = result.time
    tau, v_source = 1e3 * 1e-3, 10.0
    assert rel_error(result["capacitor.v"], v_source * (1 - np.exp(-t / tau))) < 1e-6
    assert rel_error(result["resistor.i"], v_source / 1e3 * np.exp(-t / tau)) < 1e-6
    # one time constant: 63.2 % of the final value
    k = int(round(tau / 1e-3))
    assert abs(result["capacitor.v"][k] / v_source - (1 - np.exp(-1))) < 1e-7


def test_rc_parameter_override():
    result = bg.simulate(RC(), stop_time=1.0, interval=1e-3, params={"resistor.R": 500.0},
                         **TIGHT)
    t = result.time
    assert rel_error(result["capacitor.v"], 10.0 * (1 - np.exp(-t / 0.5))) < 1e-6


def test_series_rlc_damped_oscillation():
    result = bg.simulate(SeriesRLC(), stop_time=0.2, interval=1e-4, **TIGHT)
    t = result.time
    R, L, C, V = 10.0, 0.1, 1e-3, 1.0
    alpha = R / (2 * L)
    w0 = 1 / np.sqrt(L * C)
    wd = np.sqrt(w0**2 - alpha**2)
    v_c = V * (1 - np.exp(-alpha * t) * (np.cos(wd * t) + alpha / wd * np.sin(wd * t)))
    i_l = V / (L * wd) * np.exp(-alpha * t) * np.sin(wd * t)
    assert rel_error(result["capacitor.v"], v_c) < 1e-6
    assert rel_error(result["inductor.i"], i_l) < 1e-6
    # measured frequency and decay: zero crossings of the current are pi/wd apart,
    # successive current peaks shrink by exp(-alpha*pi/wd)
    i = result["inductor.i"]
    cross = [t[k] - i[k] * (t[k + 1] - t[k]) / (i[k + 1] - i[k])
             for k in range(1, len(t) - 1) if i[k] > 0 >= i[k + 1] or i[k] < 0 <= i[k + 1]]
    assert len(cross) >= 4
    assert abs(np.mean(np.diff(cross)) - np.pi / wd) / (np.pi / wd) < 1e-4
    peaks = [k for k in range(1, len(t) - 1) if abs(i[k]) >= abs(i[k - 1])
             and abs(i[k]) >= abs(i[k + 1])]
    ratio = abs(i[peaks[1]]) / abs(i[peaks[0]])
    assert abs(ratio - np.exp(-alpha * np.pi / wd)) < 1e-3
