"""The RC ladder (SciML benchmark model) against an independent scipy solve."""

from __future__ import annotations

import numpy as np
import pytest
from library_testing import TIGHT, rel_error
from scipy.integrate import solve_ivp

import bgmodelica as bg
from library.examples import RCLadder


def ladder_rhs(n: int):
    """Node voltages v_1..v_n: C_k v_k' = (v_{k-1} - v_k)/R_k - (v_k - v_{k+1})/R_{k+1},
    v_0 = sin(2 pi 10 t), no resistor after node n; R_k = 1/k, C_k = 1/k^2."""
    k = np.arange(1, n + 1, dtype=float)
    g = k                      # conductances 1/R_k
    c = 1.0 / k**2

    def rhs(t, v):
        left = np.concatenate(([np.sin(2 * np.pi * 10.0 * t)], v[:-1]))
        i_in = g * (left - v)                       # current through R_k into node k
        i_out = np.concatenate((i_in[1:], [0.0]))   # current through R_{k+1} out of node k
        return (i_in - i_out) / c

    def jac(t, v):
        j = np.zeros((n, n))
        for m in range(n):
            j[m, m] = -g[m] - (g[m + 1] if m + 1 < n else 0.0)
            if m > 0:
                j[m, m - 1] = g[m]
            if m + 1 < n:
                j[m, m + 1] = g[m + 1]
        return j / c[:, None]

    return rhs, jac, k.copy()


def test_rc_ladder_10_matches_scipy():
    n, stop = 10, 1.0
    model = RCLadder(n)
    compiled = bg.compile(model)
    assert len(compiled.summary()["states"]) == n
    result = bg.simulate(compiled, stop_time=stop, interval=1e-3, **TIGHT)
    rhs, jac, v0 = ladder_rhs(n)
    ref = solve_ivp(rhs, (0.0, stop), v0, method="Radau", jac=jac, t_eval=result.time,
                    rtol=1e-12, atol=1e-13)
    assert ref.success
    assert rel_error(result["C1.v"], ref.y[0]) < 1e-6
    assert rel_error(result[f"C{n}.v"], ref.y[n - 1]) < 1e-6
    assert result["C1.v"][0] == pytest.approx(1.0) and result["C10.v"][0] == pytest.approx(10.0)


def test_rc_ladder_structure():
    model = RCLadder(3)
    names = set(model.children())
    assert names == {"source", "ground", "R1", "R2", "R3", "C1", "C2", "C3"}
    result = bg.simulate(model, stop_time=0.05, params={"R2.R": 0.25})
    assert result.parameters["R2.R"] == 0.25 and result.parameters["C3.C"] == pytest.approx(1 / 9)
    with pytest.raises(ValueError):
        RCLadder(0)
