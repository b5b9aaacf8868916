"""Forward sensitivities against central finite differences; refusal across events."""

from __future__ import annotations

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica.errors import ParameterError
from bgmodelica.studies.sensitivity import SensitivityError

from .models import LoopCircuit


def _central(compiled, name, rel, outputs, **kw):
    names = [q.name for q in compiled.dae.parameters]
    p0 = float(compiled.dae.p_default[names.index(name)])
    h = rel * p0
    up = bg.simulate(compiled, params={name: p0 + h}, outputs=outputs, **kw)
    dn = bg.simulate(compiled, params={name: p0 - h}, outputs=outputs, **kw)
    return {o: (up[o] - dn[o]) / (2 * h) for o in outputs}


def test_dc_motor_speed_sensitivities_match_central_differences(dcmotor):
    """Acceptance: d(speed)/dR and d(speed)/dk of the DC motor from forward sensitivities
    agree with central finite differences to 1e-6 relative (max over the trajectory)."""
    kw = dict(stop_time=1.0, interval=0.01, rtol=1e-12, atol=1e-12)
    res = bg.simulate(dcmotor, sensitivities=["resistor.R", "emf.k"],
                      outputs=["rotor.w", "inductor.i"], **kw)
    assert "forward" in res.meta["sensitivity_method"]
    plain = bg.simulate(dcmotor, outputs=["rotor.w"], **kw)
    np.testing.assert_allclose(res["rotor.w"], plain["rotor.w"], atol=1e-8)
    for p in ("resistor.R", "emf.k"):
        fd = _central(dcmotor, p, 1e-4, ["rotor.w"], **kw)["rotor.w"]
        ad = res.sensitivity("rotor.w", p)
        rel = np.max(np.abs(ad - fd)) / np.max(np.abs(ad))
        assert rel < 1e-6, (p, rel)
        assert ad[0] == 0.0                        # the start values do not depend on R, k
    # steady state (t -> inf): w = kV / (R d + k^2): the sign of the sensitivities is right
    assert res.sensitivity("rotor.w", "resistor.R")[-1] < 0
    assert res.sensitivity("rotor.w", "emf.k")[-1] > 0
    # a parameter answers too: d(emf.k)/d(emf.k) = 1
    np.testing.assert_array_equal(res.sensitivity("emf.k", "emf.k"), 1.0)


def test_dae_with_algebraic_loop_and_parameter_dependent_start():
    """An algebraic variable (nonlinear loop, IDAS) and a fixed start value of a non-state
    (the initial state depends on the parameters: initial sensitivities by the implicit
    function theorem)."""
    c = bg.compile(LoopCircuit())
    assert c.dae.z.numel() == 1
    outs = ["C.v", "g.v", "R1.i", "i2"]
    kw = dict(stop_time=1.0, interval=0.01, rtol=1e-11, atol=1e-13)
    res = bg.simulate(c, sensitivities=["R1.R", "g.a"], outputs=outs, **kw)
    assert res.meta["solver"] == "idas"
    assert res.sensitivity("C.v", "R1.R")[0] == pytest.approx(-0.005, rel=1e-9)
    assert res.sensitivity("i2", "R1.R")[0] == pytest.approx(0.0, abs=1e-12)  # fixed start
    for p in ("R1.R", "g.a"):
        fd = _central(c, p, 1e-3, outs, rtol=1e-12, atol=1e-14, stop_time=1.0,
                      interval=0.01)
        for o in outs:
            ad = res.sensitivity(o, p)
            assert np.max(np.abs(ad - fd[o])) <= 2e-5 * np.max(np.abs(ad)), (p, o)


def test_models_with_events_refused_or_finite_differences():
    from library.examples.hybrid import BouncingBall

    ball = bg.compile(BouncingBall())
    with pytest.raises(SensitivityError, match="events.*finite differences"):
        bg.simulate(ball, 1.0, 0.01, sensitivities=["g"])
    res = bg.simulate(ball, 0.4, 0.01, sensitivities=["g"], sensitivity_method="fd",
                      rtol=1e-10, atol=1e-12, outputs=["h"])
    assert res.meta["sensitivity_method"].startswith("central finite differences")
    t = res.time                                    # free fall before the first impact
    np.testing.assert_allclose(res.sensitivity("h", "g"), -0.5 * t**2, atol=1e-6)


def test_bad_sensitivity_requests(dcmotor):
    with pytest.raises(SensitivityError, match="did you mean resistor.R"):
        bg.simulate(dcmotor, 0.1, sensitivities=["R"])
    with pytest.raises(SensitivityError, match="is a variable"):
        bg.simulate(dcmotor, 0.1, sensitivities=["rotor.w"])
    with pytest.raises(SensitivityError, match="'forward' or 'fd'"):
        bg.simulate(dcmotor, 0.1, sensitivities=["emf.k"], sensitivity_method="magic")
    res = bg.simulate(dcmotor, 0.1)
    with pytest.raises(ParameterError, match="no sensitivities"):
        res.sensitivity("rotor.w", "emf.k")
