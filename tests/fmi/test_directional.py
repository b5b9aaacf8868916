"""Directional derivatives of the FMUs equal central finite differences of the FMU itself."""

from __future__ import annotations

import numpy as np
import pytest
from fmi_harness import open_fmu
from fmi_models import VERSIONS

H = 1e-6


def _me_fd(o, unknowns: list[str], known: str, kind: str, x: np.ndarray, states: list[str]):
    """Central difference of the unknowns w.r.t. one known, in Continuous-Time Mode (states,
    inputs) or Event Mode (parameters)."""
    def value(delta: float) -> np.ndarray:
        if kind == "state":
            xx = x.copy()
            xx[states.index(known)] += delta
            o.fmu.setContinuousStates(np.ctypeslib.as_ctypes(xx), len(xx))
        else:
            base = o.get([known])[0]
            o.set({known: base + delta})
        vals = np.array(o.get(unknowns))
        if kind == "state":
            o.fmu.setContinuousStates(np.ctypeslib.as_ctypes(x.copy()), len(x))
        else:
            o.set({known: base})
        return vals
    ref = x[states.index(known)] if kind == "state" else o.get([known])[0]
    h = H * max(abs(ref), 1e-3)
    return (value(h) - value(-h)) / (2 * h)


CASES = [
    ("osc", ["der(mass.s)", "der(mass.v)", "pos", "spring.f", "mass.Ekin"],
     ["mass.s", "mass.v"], ["force"], ["mass.m", "damper.d", "spring.c"], [0.3, -1.2]),
    ("loop", ["der(cap.v)", "res.i", "res.v_plus"], ["cap.v"], ["source.U"],
     ["res.R", "res.a", "cap.C", "cap.v0"], [1.7]),
    ("motor", ["der(motor.i)", "der(motor.w)", "speed", "torque", "power"],
     ["motor.i", "motor.w"], ["U"], ["motor.R", "motor.L", "motor.k", "motor.J", "motor.b"],
     [2.0, 30.0]),
]


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("model,unknowns,states,inputs,params,x", CASES,
                         ids=[c[0] for c in CASES])
def test_me_directional_derivatives(build_fmu, version, model, unknowns, states, inputs,
                                    params, x):
    o = open_fmu(build_fmu(model, version, "me"), "me")
    try:
        o.initialize()
        o.fmu.enterContinuousTimeMode()
        x = np.array(x, dtype=float)
        o.fmu.setContinuousStates(np.ctypeslib.as_ctypes(x.copy()), len(x))
        o.fmu.setTime(0.3)
        for known in states + inputs:
            kind = "state" if known in states else "input"
            dd = o.dir_der(unknowns, [known], [1.0])
            fd = _me_fd(o, unknowns, known, kind, x, states)
            np.testing.assert_allclose(dd, fd, rtol=1e-6, atol=1e-6 * (1 + np.max(np.abs(fd))),
                                       err_msg=f"d/d{known}")
        o.fmu.enterEventMode()
        for known in params:
            dd = o.dir_der(unknowns, [known], [1.0])
            fd = _me_fd(o, unknowns, known, "parameter", x, states)
            np.testing.assert_allclose(dd, fd, rtol=1e-6, atol=1e-6 * (1 + np.max(np.abs(fd))),
                                       err_msg=f"d/d{known}")
        # a combined seed is the linear combination
        seed = np.linspace(0.5, 1.5, len(states + inputs))
        combo = o.dir_der(unknowns, states + inputs, list(seed))
        single = np.array([o.dir_der(unknowns, [k], [1.0]) for k in states + inputs])
        np.testing.assert_allclose(combo, seed @ single, rtol=1e-12, atol=1e-12)
        assert o.errors() == []
    finally:
        o.close()


@pytest.mark.parametrize("version", VERSIONS)
def test_directional_derivatives_in_initialization_through_init(build_fmu, version):
    """With an init function the states are initial unknowns of the parameters."""
    o = open_fmu(build_fmu("loop", version, "me"), "me")
    try:
        o.initialize(exit_init=False)
        unknowns = ["cap.v", "der(cap.v)", "res.i"]
        for known in ("cap.v0", "source.U", "res.R"):
            dd = o.dir_der(unknowns, [known], [1.0])
            base = o.get([known])[0]
            o.set({known: base + H})
            plus = np.array(o.get(unknowns))
            o.set({known: base - H})
            minus = np.array(o.get(unknowns))
            o.set({known: base})
            np.testing.assert_allclose(dd, (plus - minus) / (2 * H), rtol=1e-6, atol=1e-7)
        assert o.dir_der(["cap.v"], ["cap.v0"], [1.0]) == pytest.approx([1.0])
        o.fmu.exitInitializationMode()
        assert o.errors() == []
    finally:
        o.close()


@pytest.mark.parametrize("version", VERSIONS)
def test_cs_directional_derivative(build_fmu, version):
    o = open_fmu(build_fmu("osc", version, "cs"), "cs")
    try:
        o.initialize()
        dd = o.dir_der(["pos", "spring.f", "der(mass.v)"], ["mass.s", "spring.c", "force"],
                       [1.0, 0.0, 0.0])
        assert dd == pytest.approx([1.0, 4.0, -4.0])
        dd = o.dir_der(["der(mass.v)"], ["force"], [2.0])
        assert dd == pytest.approx([2.0])
    finally:
        o.close()
