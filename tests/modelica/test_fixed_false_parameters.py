"""Parameters declared ``fixed = false`` and given by initial equations."""

from __future__ import annotations

import numpy as np

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
