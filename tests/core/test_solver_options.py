"""Integrator settings: linear solver choice and JIT, reported in result.meta, same results."""

from __future__ import annotations

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica.errors import OptionError
from bgmodelica.solver_options import compiler, linear_solver_for
from library.examples import RC, RCLadderVector

TIGHT = {"rtol": 1e-10, "atol": 1e-12}


def test_auto_linear_solver_is_reported_and_explicit_ones_agree():
    m = bg.compile(RCLadderVector(20))
    runs = {ls: bg.simulate(m, stop_time=0.5, interval=0.05, linear_solver=ls, **TIGHT)
            for ls in ("auto", "qr", "csparse", "lapacklu")}
    assert runs["auto"].meta["linear_solver"] == "qr"
    assert runs["auto"].meta["linear_solver_choice"] == "auto"
    assert runs["csparse"].meta["linear_solver"] == "csparse"
    assert runs["csparse"].meta["linear_solver_choice"] == "given"
    for res in runs.values():
        assert np.max(np.abs(res["v[20]"] - runs["qr"]["v[20]"])) < 1e-8


def test_bad_linear_solver_or_jit_is_a_clear_error():
    with pytest.raises(OptionError, match="linear_solver must be one of"):
        bg.simulate(RC(), stop_time=0.1, linear_solver="mumps")
    with pytest.raises(OptionError, match="jit must be True, False or one of"):
        bg.simulate(RC(), stop_time=0.1, jit="fast")
    assert linear_solver_for(10**6) == "qr"


@pytest.mark.skipif(compiler() is None, reason="no C compiler")
def test_jit_gives_the_analytic_rc_and_says_so():
    res = bg.simulate(RC(), stop_time=3.0, interval=0.1, jit=True, **TIGHT)
    assert res.meta["jit"] == "O0"
    assert np.max(np.abs(res["capacitor.v"] - 10.0 * (1 - np.exp(-res.time)))) < 1e-7


class _SmallOscillator(bg.Component):
    """x'' = -w^2 x with x(0) = 1e-5 m, w = 20 1/s; the states declare nominal 1e-5."""

    w = bg.Parameter(20.0, unit="1/s")
    x = bg.Variable(start=1e-5, fixed=True, unit="m", nominal=1e-5)
    v = bg.Variable(start=0.0, fixed=True, unit="m/s", nominal=2e-4)

    def equations(self):
        yield bg.der(self.x) == self.v
        yield bg.der(self.v) == -self.w**2 * self.x


class _SmallOscillatorPlain(_SmallOscillator):
    x = bg.Variable(start=1e-5, fixed=True, unit="m")
    v = bg.Variable(start=0.0, fixed=True, unit="m/s")


def test_default_absolute_tolerance_follows_the_state_nominal():
    """States of nominal 1e-5: the default atol is rtol x 1e-5, and the small oscillation is
    resolved to 2e-3 of its amplitude over 50 periods (atol 1e-8 leaves a far larger error)."""
    t_end = 50 * 2 * np.pi / 20.0
    res = bg.simulate(_SmallOscillator(), stop_time=t_end, interval=t_end / 500)
    assert res.meta["atol"] == pytest.approx(1e-6 * 1e-5)
    exact = 1e-5 * np.cos(20.0 * res.time)
    assert np.max(np.abs(res["x"] - exact)) < 2e-3 * 1e-5
    plain = bg.simulate(_SmallOscillatorPlain(), stop_time=t_end, interval=t_end / 500)
    assert plain.meta["atol"] == 1e-8
    given = bg.simulate(_SmallOscillator(), stop_time=t_end, interval=t_end / 500, atol=1e-8)
    assert given.meta["atol"] == 1e-8
    assert np.max(np.abs(given["x"] - exact)) > 10 * np.max(np.abs(res["x"] - exact))
