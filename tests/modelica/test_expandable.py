"""Expandable connectors (specification 9.1.3): bus elements made by ``connect``, sub-buses,
buses joined by ``connect``, declared elements that nothing uses dropped."""

from __future__ import annotations

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica.modelica import ModelicaError, load_modelica_text

_LIB = """
connector RealOutput = output Real;
connector RealInput = input Real;
connector BooleanOutput = output Boolean;
expandable connector SubBus
  Real declaredOnly;
end SubBus;
expandable connector Bus
  Real a "declared, connected";
  Real unused "declared, never connected";
  SubBus sub;
end Bus;
block Ramp
  parameter Real k = 1;
  RealOutput y;
equation
  y = k*time;
end Ramp;
block Gain
  parameter Real k = 1;
  RealInput u;
  RealOutput y;
equation
  y = k*u;
end Gain;
model Part "puts a signal on its own bus"
  parameter Real k = 1;
  Bus bus;
  Ramp ramp(k = k);
  BooleanOutput late = time > 0.5;
equation
  connect(ramp.y, bus.sub.x);
  connect(late, bus.flag);
end Part;
"""


def _at(result, name, t):
    return float(np.interp(t, result["time"], result[name]))


def test_bus_elements_follow_their_connections():
    model = load_modelica_text(_LIB + """
model Top
  Part p1(k = 2);
  Part p2(k = 3);
  Bus bus;
  Bus other;
  Ramp src(k = 5);
  Gain g1(k = 10);
  Gain g2;
  Gain g3;
equation
  connect(src.y, bus.a);
  connect(bus.a, g1.u);
  connect(p1.bus.sub, bus.sub);
  connect(bus, other);
  connect(other.sub.x, g2.u);
  connect(p2.bus.sub.x, g3.u);
end Top;
""", "Top")
    r = bg.simulate(model, stop_time=1.0, interval=0.01)
    for t in (0.3, 0.8):
        assert _at(r, "bus.a", t) == pytest.approx(5 * t)
        assert _at(r, "other.a", t) == pytest.approx(5 * t)
        assert _at(r, "g1.y", t) == pytest.approx(50 * t)
        assert _at(r, "bus.sub.x", t) == pytest.approx(2 * t)
        assert _at(r, "other.sub.x", t) == pytest.approx(2 * t)
        assert _at(r, "g2.y", t) == pytest.approx(2 * t)
        assert _at(r, "g3.y", t) == pytest.approx(3 * t)      # second instance of Part
    assert _at(r, "p1.bus.flag", 0.3) == 0 and _at(r, "p2.bus.flag", 0.8) == 1
    assert not any("unused" in n or "declaredOnly" in n for n in r.all_names())


def test_connecting_two_unknown_bus_elements_is_an_error():
    with pytest.raises(ModelicaError, match=r"neither end is declared"):
        load_modelica_text(_LIB + """
model Top
  Bus b1;
  Bus b2;
equation
  connect(b1.p, b2.q);
end Top;
""", "Top")
