"""Loops through piecewise equations whose coefficient of an unknown vanishes in one branch
(the limited ideal op-amp's curve parameter): tearing must not solve such an equation for it."""

from __future__ import annotations

import casadi as ca
import numpy as np

import bgmodelica as bg
from bgmodelica.modelica import load_modelica_text
from bgmodelica.passes.symbolic import fails_in_branch, may_vanish, solve_linear_scalar

AMP = """
model LimitedAmp "inverting amplifier, gain -R2/R1, around an op-amp limited to [VMin, VMax]"
  parameter Real R1 = 1000;
  parameter Real R2 = 2000;
  parameter Real VMax = 15;
  parameter Real VMin = -15;
  parameter Real A = 10 "input amplitude (saturates the output)";
  Real vIn = A*sin(6.283185307179586*time);
  Real vn "inverting input (the other one is grounded)";
  Real vOut;
  Real i;
  Real s(start = 0) "curve parameter";
equation
  vIn - vn = R1*i;
  vn - vOut = R2*i;
  0 - vn = smooth(0, if s < -1 then s + 1 else if s > 1 then s - 1 else 0);
  vOut = smooth(0, if s < -1 then VMin else if s > 1 then VMax
    else (VMax - VMin)*s/2 + (VMax + VMin)/2);
end LimitedAmp;
"""


def test_limited_amplifier_saturates_as_the_analytic_answer():
    model = load_modelica_text(AMP, "LimitedAmp")
    r = bg.simulate(model, stop_time=1.0, interval=0.001)
    t = np.asarray(r["time"])
    ideal = -2.0 * 10 * np.sin(2 * np.pi * t)
    out = np.clip(ideal, -15, 15)
    np.testing.assert_allclose(r["vOut"], out, atol=1e-6)
    np.testing.assert_allclose(r["vn"], (out - ideal) / 3, atol=1e-6)   # 0 unless saturated
    assert np.all(np.isfinite(r["s"]))


def _piecewise():
    r0, r1, s, x = (ca.SX.sym(n) for n in ("r0", "r1", "s", "x"))
    branches = ca.if_else(r0, s + 1, 0) + ca.if_else(ca.logic_not(r0),
                                                     ca.if_else(r1, s - 1, 0), 0)
    return r0, r1, s, x, branches


def test_no_symbolic_solve_through_a_vanishing_branch_coefficient():
    r0, r1, s, x, branches = _piecewise()
    discrete = frozenset({r0.element_hash(), r1.element_hash()})
    assert may_vanish(ca.jacobian(x - branches, s), discrete)
    assert solve_linear_scalar(x - branches, s, set(), discrete) is None
    assert solve_linear_scalar(x - branches, s) is not None         # no discretes known
    k = ca.if_else(r0, 2.0, 0) + ca.if_else(ca.logic_not(r0), 3.0, 0)  # 2 or 3: never 0
    assert not may_vanish(k, discrete)
    assert solve_linear_scalar(x - k * s, s, set(), discrete) is not None


def test_a_block_solution_dividing_by_a_branch_pivot_is_rejected():
    r0, _, s, x, _ = _piecewise()
    discrete = frozenset({r0.element_hash()})
    c = ca.if_else(r0, 1.0, 0)                  # s = x in one branch, s = 2 x in the other
    residual = [c * s + (1 - c) * 0.5 * s - x]
    assert not fails_in_branch(residual, [s], ca.SX(x) / (c + (1 - c) * 0.5), discrete)
    assert fails_in_branch(residual, [s], ca.SX(x) / c, discrete)   # naive pivot
