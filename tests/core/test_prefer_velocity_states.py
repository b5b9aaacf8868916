"""A variable declaring StateSelect.prefer that is only a derivative in disguise
(``v_rel = der(s_rel)``, as in the MSL's springs and dampers) becomes a state in place of one
of lower priority, as Modelica tools choose; a ``reinit`` then keeps it."""

from __future__ import annotations

import numpy as np

import bgmodelica as bg
from bgmodelica.modelica import load_modelica_text

TWO_MASSES = """
model TwoMasses
  Real sA(start = 0, fixed = true);
  Real vA(start = 0, fixed = true);
  Real sB(start = 0.5, stateSelect = StateSelect.always);
  Real vB(start = 0, stateSelect = StateSelect.always);
  Real s_rel(start = 0.5, fixed = true, stateSelect = StateSelect.prefer);
  Real v_rel(start = 0, fixed = true, stateSelect = StateSelect.prefer);
  Real f;
equation
  der(sA) = vA;
  der(vA) = f;
  der(sB) = vB;
  der(vB) = 1 - f;
  s_rel = sB - sA;
  v_rel = der(s_rel);
  f = 100*(s_rel - 0.5) + 2*v_rel;
  when time >= 0.5 then
    reinit(vB, 0);
  end when;
end TwoMasses;
"""


def test_relative_speed_with_prefer_is_a_state_and_survives_a_reinit():
    model = load_modelica_text(TWO_MASSES, "TwoMasses")
    states = bg.compile(model).dae.state_names
    assert set(states) == {"sB", "vB", "s_rel", "v_rel"}
    r = bg.simulate(model, stop_time=1.0, interval=0.01, rtol=1e-10, atol=1e-12)
    k = int(np.flatnonzero(r["time"] == 0.5)[0])      # left limit; k + 1: right limit
    assert r["vB"][k] > 0.05 and r["vB"][k + 1] == 0.0
    assert r["v_rel"][k + 1] == np.float64(r["v_rel"][k])  # the kept state: continuous
    assert abs(r["vA"][k + 1] - (r["vB"][k + 1] - r["v_rel"][k + 1])) < 1e-12
    # before the event: the total momentum grows with the unit force on B (m = 1 each)
    t = r["time"][: k + 1]
    np.testing.assert_allclose((r["vA"] + r["vB"])[: k + 1], t, atol=1e-8)
