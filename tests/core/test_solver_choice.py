"""The automatic integrator choice (``solver="auto"``): CVODES for models that reduce to an
explicit ODE, IDAS when algebraic unknowns are left; the choice is reported, and a given
solver is kept."""

from __future__ import annotations

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica.errors import OptionError, ParameterError
from library.examples.circuits import RC
from library.examples.constrained import Pendulum


def test_ode_model_runs_on_cvodes_and_matches_idas():
    compiled = bg.compile(RC())
    auto = bg.simulate(compiled, stop_time=3.0, interval=0.1, rtol=1e-10, atol=1e-12,
                       solver="auto")
    assert (auto.meta["solver"], auto.meta["solver_choice"]) == ("cvodes", "auto")
    idas = bg.simulate(compiled, stop_time=3.0, interval=0.1, rtol=1e-10, atol=1e-12,
                       solver="idas")
    assert (idas.meta["solver"], idas.meta["solver_choice"]) == ("idas", "given")
    exact = 10.0 * (1 - np.exp(-auto.time))
    for res in (auto, idas):
        assert np.max(np.abs(res["capacitor.v"] - exact)) < 1e-7


def test_dae_model_runs_on_idas():
    compiled = bg.compile(Pendulum())
    assert compiled.dae.z.numel() > 0
    res = bg.simulate(compiled, stop_time=0.5, interval=0.1, dynamic=False, solver="auto")
    assert (res.meta["solver"], res.meta["solver_choice"]) == ("idas", "auto")
    with pytest.raises(ParameterError, match="cvodes"):
        bg.simulate(compiled, stop_time=0.5, interval=0.1, dynamic=False, solver="cvodes")


def test_unknown_solver_is_refused():
    with pytest.raises(OptionError, match="solver must be 'auto', 'idas' or 'cvodes'"):
        bg.simulate(RC(), stop_time=1.0, solver="euler")
