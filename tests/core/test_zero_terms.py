"""Parameters whose value 0 removes a term (``J*der(w)`` with ``J = 0``) are evaluated when
compiling: the structure follows the value instead of dividing by it."""

from __future__ import annotations

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica.errors import ParameterError
from bgmodelica.modelica import load_modelica_text

LAG = """
model Lag
  parameter Real J = 0 "makes the lag algebraic";
  parameter Real k = 2;
  parameter Real T = 4;
  Real w;
equation
  J*der(w) = T - k*w;
end Lag;
"""

WHEEL = """
model Wheel "an inertia J rolling a mass m on a wheel of radius R"
  parameter Real J = 0;
  parameter Real m = 2;
  parameter Real R = 0.5;
  parameter Real T = 3 "driving torque";
  parameter Real offset = 0 "zero, but removes no term";
  Real phi, w, a, tau;
  Real s(start = 0, fixed = true), v(start = 0, fixed = true), f;
equation
  w = der(phi);
  a = der(w);
  J*a = T + tau + offset;
  s = R*phi;
  tau + R*f = 0;
  v = der(s);
  m*der(v) = f;
end Wheel;
"""

CAPACITANCES = """
model Capacitances "a capacitance made of parameters through a variable"
  parameter Real C1 = 0;
  parameter Real C2 = 0;
  parameter Real R = 2;
  parameter Real V = 4;
  Real c "total capacitance";
  Real cj "junction part";
  Real u, i;
equation
  cj = C2*exp(u);
  c = C1 + cj;
  i = c*der(u);
  V - u = R*i;
end Capacitances;
"""


def _sim(model, **kw):
    return bg.simulate(model, **{"stop_time": 1.0, "interval": 0.1, **kw})


def test_zero_coefficient_of_a_derivative_makes_it_algebraic():
    compiled = bg.compile(load_modelica_text(LAG, "Lag"))
    assert compiled.evaluated == {"J": 0.0}
    assert compiled.summary()["states"] == []
    np.testing.assert_allclose(_sim(compiled)["w"], 2.0)


def test_nonzero_coefficient_stays_a_tunable_state():
    compiled = bg.compile(load_modelica_text(LAG.replace("J = 0", "J = 0.5"), "Lag"))
    assert compiled.evaluated == {}
    res = _sim(compiled, params={"J": 0.25, "w": 0.0})
    np.testing.assert_allclose(res["w"], 2.0 * (1 - np.exp(-8.0 * res.time)), atol=1e-5)


def test_zero_inertia_on_a_wheel_leaves_the_mass_alone():
    compiled = bg.compile(load_modelica_text(WHEEL, "Wheel"))
    assert compiled.evaluated == {"J": 0.0}          # offset stays tunable
    res = _sim(compiled)
    np.testing.assert_allclose(res["v"], 3.0 / (0.5 * 2.0) * res.time, atol=1e-8)
    res = _sim(compiled, params={"offset": 1.0, "J": 0.0})
    np.testing.assert_allclose(res["v"], 4.0 / (0.5 * 2.0) * res.time, atol=1e-8)
    with pytest.raises(ParameterError, match="'J' was evaluated when compiling"):
        _sim(compiled, params={"J": 1.0})


def test_a_variable_set_to_zero_removes_its_terms_too():
    """``cj = C2*exp(u)`` and ``c = C1 + cj`` are zero: ``c*der(u)`` goes, u = V."""
    compiled = bg.compile(load_modelica_text(CAPACITANCES, "Capacitances"))
    assert compiled.evaluated == {"C1": 0.0, "C2": 0.0}
    assert compiled.summary()["states"] == []
    res = _sim(compiled)
    np.testing.assert_allclose(res["u"], 4.0)
    np.testing.assert_allclose(res["i"], 0.0, atol=1e-12)


def test_one_zero_of_a_sum_evaluates_nothing():
    text = CAPACITANCES.replace("C2 = 0", "C2 = 1e-3")
    compiled = bg.compile(load_modelica_text(text, "Capacitances"))
    assert compiled.evaluated == {}
    assert compiled.summary()["states"] == ["u"]
