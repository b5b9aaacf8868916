"""Expressions deeper than Python's recursion limit (a function's loop inlined into a chain
of thousands of operations, like a table's chain of ``if_else``) compile: the unit check,
the relations and the lowering walk them without recursion."""

from __future__ import annotations

import numpy as np

import bgmodelica as bg
from bgmodelica.modelica import load_modelica_text

TEXT = """
package D
  function chain "x, summed in n parts; plus n branches on time that add nothing"
    input Real x(unit = "V");
    input Integer n;
    output Real y(unit = "V");
  algorithm
    y := 0;
    for i in 1:n loop
      y := y + x/n;
    end for;
  end chain;
  model M
    parameter Real k(unit = "1/s") = 2;
    Real x(start = 1, fixed = true, unit = "V");
    Real s(unit = "V");
  equation
    der(x) = -k*chain(x, 3000) + s;
    s = if time < -1 then chain(x, 3000) else 0;
  end M;
end D;
"""


def test_a_deep_expression_compiles_and_simulates():
    res = bg.simulate(load_modelica_text(TEXT, "D.M"), stop_time=1.0, interval=0.1)
    np.testing.assert_allclose(res["x"], np.exp(-2.0 * res.time), rtol=1e-5)
