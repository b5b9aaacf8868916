"""Parameters declared ``fixed = false`` and given by initial equations."""

from __future__ import annotations

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica.modelica import load_modelica_text

COEFFICIENTS = """
package Q
  function coeffs
    input Real w;
    input Integer n;
    output Real c[n];
  algorithm
    c := zeros(n);
    for i in 1:n loop
      c[i] := w*i;
    end for;
  end coeffs;
  model F
    parameter Integer n = 2;
    parameter Real w = 1;
    parameter Real c[n](each fixed = false);
    Real x(start = 1, fixed = true);
  initial equation
    c = coeffs(w, n);
  equation
    der(x) = -c[n]*x;
  end F;
  model M
    parameter Real w = 3;
    F a(n = 1, w = w);
    F b(n = 2, w = w);
  end M;
end Q;
"""


def test_each_instance_takes_its_values_from_a_function_of_parameters():
    """The second instance's values are computed after the parameters were collected (and
    the function's array output holds expressions of a bound parameter)."""
    res = bg.simulate(load_modelica_text(COEFFICIENTS, "Q.M"), stop_time=0.5, interval=0.1)
    assert [res.parameters[n] for n in ("a.c[1]", "b.c[1]", "b.c[2]")] == [3.0, 3.0, 6.0]
    np.testing.assert_allclose(res["a.x"], np.exp(-3 * res.time), rtol=1e-5)
    np.testing.assert_allclose(res["b.x"], np.exp(-6 * res.time), rtol=1e-5)


IMPLICIT = """
model Implicit
  parameter Real T1 = 1;
  parameter Real T2 = 3;
  parameter Real T(fixed = false, start = 1) "time of the maximum";
  parameter Real eta(fixed = false, start = 1) "the maximum, to scale it to 1";
  Real y;
initial equation
  exp(-T/T2)/T2 = exp(-T/T1)/T1;
  eta = exp(-T/T2) - exp(-T/T1);
equation
  y = (exp(-time/T2) - exp(-time/T1))/eta;
end Implicit;
"""


def _peak(t1: float, t2: float) -> float:
    return np.log(t2 / t1) * t1 * t2 / (t2 - t1)


@pytest.mark.parametrize(("t1", "t2", "start"), [(1.0, 3.0, 1.0), (1e-5, 3.5e-4, 3e-5)])
def test_parameters_from_implicit_initial_equations(t1, t2, start):
    """``T`` solves a nonlinear initial equation (the initialization's unknown, then
    constant); ``eta`` depends on it, so it is not evaluated from T's start value when built.
    The second case (time constants of 1e-5 s) needs the trust-region fallback."""
    text = IMPLICIT.replace("T1 = 1", f"T1 = {t1}").replace("T2 = 3", f"T2 = {t2}") \
        .replace("T(fixed = false, start = 1)", f"T(fixed = false, start = {start})")
    t_max = _peak(t1, t2)
    res = bg.simulate(load_modelica_text(text, "Implicit"), stop_time=3 * t_max,
                      interval=t_max / 50)
    assert res.parameters["T"] == pytest.approx(t_max, rel=1e-8)
    assert res.parameters["eta"] == pytest.approx(np.exp(-t_max / t2) - np.exp(-t_max / t1),
                                                  rel=1e-8)
    assert np.max(res["y"]) == pytest.approx(1.0, abs=1e-6)


def test_a_parameter_without_initial_equation_keeps_its_start():
    text = IMPLICIT.replace("  Real y;", "  parameter Real unused(fixed = false, start = 2);\n"
                            "  Real y;")
    res = bg.simulate(load_modelica_text(text, "Implicit"), stop_time=1.0)
    assert res.parameters["unused"] == 2.0
    assert res.parameters["T"] == pytest.approx(_peak(1.0, 3.0), rel=1e-8)
    assert any("parameter(s) unused" in n for n in res.meta["init_notes"])
