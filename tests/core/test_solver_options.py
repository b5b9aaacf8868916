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
