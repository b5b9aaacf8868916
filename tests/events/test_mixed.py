"""Mixed systems at events: relations on algebraic variables whose equations depend on the
relations (the stuck/sliding logic of the MSL's friction elements, ideal diodes)."""

from __future__ import annotations

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica.modelica import load_modelica_text

FRICTION = """
model SlidingMass "A mass on Coulomb friction with the stuck/sliding logic of the MSL"
  parameter Real m = 0.1;
  parameter Real F_c = 1;
  parameter Real f0_max = 1.001*F_c;
  Real s(start = 0, fixed = true);
  Real v(start = 2, fixed = true);
  Real a;
  Real f;
  Real sa;
  Real F_ext = if time < 1 then 0.5 else 0.5 + (time - 1);
  Boolean startForward(start = false, fixed = true);
  Boolean startBackward(start = false, fixed = true);
  Boolean locked(start = false);
  Integer mode(start = 3, fixed = true);
equation
  der(s) = v;
  der(v) = a;
  m*a = F_ext - f;
  startForward = pre(mode) == 0 and (sa > f0_max or pre(startForward) and sa > F_c)
    or initial() and v > 0;
  startBackward = pre(mode) == 0 and (sa < -f0_max or pre(startBackward) and sa < -F_c)
    or initial() and v < 0;
  locked = not (pre(mode) == 1 or startForward or pre(mode) == -1 or startBackward);
  a = if locked then 0 else if startForward then sa - f0_max
    else if startBackward then sa + f0_max else if pre(mode) == 1 then sa - f0_max
    else sa + f0_max;
  f = if locked then sa else if startForward then F_c else if startBackward then -F_c
    else if pre(mode) == 1 then F_c else -F_c;
  mode = if (pre(mode) == 1 or startForward) and v > 0 then 1
    else if (pre(mode) == -1 or startBackward) and v < 0 then -1 else 0;
end SlidingMass;
"""

BRIDGE = """
model Bridge "A single-phase diode bridge behind a line inductor, feeding a capacitor and a load"
  model Diode
    parameter Real Ron = 1e-3;
    parameter Real Goff = 1e-3;
    parameter Real Vknee = 2;
    Real va;
    Real vb;
    Real i;
    Real s(start = 0);
    Boolean off(start = true);
  equation
    off = s < 0;
    va - vb = s*(if off then 1 else Ron) + Vknee;
    i = s*(if off then Goff else 1) + Goff*Vknee;
  end Diode;
  parameter Real V = 325;
  parameter Real L = 60e-6;
  parameter Real C = 30e-3;
  parameter Real R = 1;
  Diode d1, d2, d3, d4;
  Real iL(start = 0, fixed = true);
  Real vc(start = 0, fixed = true);
  Real va;
  Real vn;
equation
  L*der(iL) = V*sin(2*3.14159265358979*50*time) - va;
  d1.va = va; d1.vb = vn + vc;
  d2.va = 0; d2.vb = vn + vc;
  d3.va = vn; d3.vb = va;
  d4.va = vn; d4.vb = 0;
  iL = d1.i - d3.i;
  d4.i = d2.i + iL;
  d1.i + d2.i = C*der(vc) + vc/R;
end Bridge;
"""


def test_friction_sticks_and_breaks_away():
    """Sliding forward against F_c - F_ext: a = -5 until v = 0 at t = 0.4 (s = 0.4); stuck
    (holding F_ext = 0.5) until F_ext reaches f0_max = 1.001 at t = 1.501; then
    a = (time - 1.5)/m."""
    res = bg.simulate(load_modelica_text(FRICTION), stop_time=2.0, interval=0.01,
                      rtol=1e-10, atol=1e-12)
    times = res.meta["event_times"]
    assert any(abs(t - 0.4) < 1e-9 for t in times)
    assert any(abs(t - 1.501) < 1e-9 for t in times)
    t = res["time"]
    stuck = (t > 0.41) & (t < 1.5)
    assert np.allclose(res["s"][stuck], 0.4, atol=1e-8)
    assert np.allclose(res["v"][stuck], 0.0, atol=1e-8)
    assert np.allclose(res["f"][stuck], res["F_ext"][stuck], atol=1e-8)
    assert np.all(res["mode"][stuck] == 0)
    assert res["v"][-1] == pytest.approx(5 * (0.5**2 - 0.001**2), rel=1e-7)
    assert res["mode"][-1] == 1


def test_ideal_diode_bridge_commutates():
    """Series ideal diodes switch together; the one not located sees its indicator at
    rounding level, so the event iteration must settle instead of cycling."""
    res = bg.simulate(load_modelica_text(BRIDGE), stop_time=0.04, interval=1e-4,
                      rtol=1e-6, atol=1e-8)
    for d in ("d1", "d2", "d3", "d4"):
        on = res[f"{d}.off"] == 0
        assert np.all(res[f"{d}.i"][on] > -1e-6)
        assert np.all(res[f"{d}.s"][~on] < 1e-6)
    on = {d: res[f"{d}.off"] == 0 for d in ("d1", "d2", "d3", "d4")}
    assert not np.any(on["d1"] & on["d3"]) and not np.any(on["d2"] & on["d4"])
    assert np.any(on["d1"] & on["d4"]) and np.any(on["d2"] & on["d3"])   # both half-waves
    assert 300 < res["vc"][-1] < 325 - 4


INVERSE = """
model InverseBrake "A braking force ~ 1/v, regularized below v0"
  parameter Real v0 = 1;
  Real v(start = 10, fixed = true);
equation
  der(v) = if abs(v) < v0 then -100*v/v0 else -100/v;
end InverseBrake;
"""


def test_singular_branch_past_an_unchecked_crossing():
    """v^2 = 100 - 200 t reaches v0 = 1 at t = 0.495; beyond, the frozen 1/v branch blows up
    before the next check, so the integration is retried on shorter stretches."""
    res = bg.simulate(load_modelica_text(INVERSE), stop_time=5.0, interval=1e-3,
                      rtol=1e-10, atol=1e-12)
    assert res.meta["event_times"][0] == pytest.approx(0.495, abs=1e-7)
    t = res["time"]
    k = np.searchsorted(t, 0.52)
    assert res["v"][k] == pytest.approx(np.exp(-100 * (t[k] - 0.495)), rel=1e-4)
    assert abs(res["v"][-1]) < 1e-12
