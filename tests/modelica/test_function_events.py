"""Relations inside a function body trigger no events (specification 12.7) unless the
function says ``GenerateEvents=true``; relations in its arguments still do."""

from __future__ import annotations

import numpy as np

import bgmodelica as bg
from bgmodelica.modelica import load_modelica_text

TEXT = """
package P
  function ramp "linear above zero"
    input Real x;
    output Real y;
  algorithm
    y := if x > 0 then x else 0;
  end ramp;
  function rampEvents
    extends ramp;
    annotation(GenerateEvents = true);
  end rampEvents;
  model M
    Real a = ramp(sin(10*time));
    Real b = ramp(if time > 0.5 then 1 else -1);
  end M;
  model E
    Real a = rampEvents(sin(10*time));
  end E;
end P;
"""


def _relations(name):
    compiled = bg.compile(load_modelica_text(TEXT, name))
    events = compiled.event_summary()
    return compiled, [] if events is None else [c["relation"] for c in events["conditions"]]


def test_function_body_relations_are_literal():
    compiled, relations = _relations("P.M")
    assert len(relations) == 1 and "time" in relations[0]     # the argument's, not the body's
    res = bg.simulate(compiled, stop_time=1.0, interval=0.01)
    np.testing.assert_allclose(res["a"], np.maximum(np.sin(10 * res.time), 0), atol=1e-9)


def test_generate_events_keeps_them():
    _, relations = _relations("P.E")
    assert len(relations) == 1
