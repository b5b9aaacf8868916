"""Signal constructs of the Modelica Standard Library's blocks, in small models: arrays indexed
by time-varying Integers, Integer and Boolean outputs at events, fixed=false parameters from
initial algorithms, connecting outputs of a block itself, connectors with parameters,
modifiers that read later siblings."""

from __future__ import annotations

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica.modelica import ModelicaError, load_modelica_text


def _at(result, name, t):
    return float(np.interp(t, result["time"], result[name]))


def test_array_indexed_by_a_time_varying_integer():
    """``a[k]`` reads and ``buf[i] := u`` writes with ``k``, ``i`` changing at events."""
    model = load_modelica_text("""
model Index
  parameter Real a[3] = {10, 20, 30};
  Integer k = if time < 0.3 then 0 elseif time < 0.6 then 2 else 3;
  Real y = if k == 0 then -1 else a[k];
  discrete Real buf[3](each start = 0, each fixed = true);
  Integer i(start = 0, fixed = true);
algorithm
  when sample(0, 0.1) then
    i := pre(i) + 1;
    if i <= 3 then
      buf[i] := 10*i;
    end if;
  end when;
end Index;
""", "Index")
    r = bg.simulate(model, stop_time=1.0, interval=0.01)
    assert [_at(r, "y", t) for t in (0.1, 0.45, 0.9)] == [-1, 20, 30]
    assert [_at(r, f"buf[{j}]", 0.05) for j in (1, 2, 3)] == [10, 0, 0]
    assert [_at(r, f"buf[{j}]", 0.5) for j in (1, 2, 3)] == [10, 20, 30]


def test_integer_and_boolean_outputs_at_events():
    """An Integer output assigned in a when-equation, and a Boolean output that keeps
    ``pre(y)``: it latches the instant's edge (true from 0.5 s on)."""
    model = load_modelica_text("""
model Latch
  output Integer n(start = 0, fixed = true);
  output Boolean y;
  Boolean u = time >= 0.5;
  Boolean rising = edge(u);
initial equation
  pre(y) = false;
  pre(u) = false;
equation
  when sample(0, 0.25) then
    n = pre(n) + 1;
  end when;
  y = if rising then true else pre(y);
end Latch;
""", "Latch")
    r = bg.simulate(model, stop_time=1.0, interval=0.01)
    assert [_at(r, "n", t) for t in (0.1, 0.3, 0.9)] == [1, 2, 4]
    assert [_at(r, "y", t) for t in (0.4, 0.6, 0.95)] == [0, 1, 1]


def test_initial_algorithm_assigns_array_elements():
    model = load_modelica_text("""
model Codes
  output Integer c[2];
  Real x(start = 0, fixed = true);
initial algorithm
  for i in 1:2 loop
    c[i] := 3*i;
  end for;
algorithm
  when time > 0.5 then
    c[2] := 7;
  end when;
equation
  der(x) = 1;
end Codes;
""", "Codes")
    r = bg.simulate(model, stop_time=1.0, interval=0.01)
    assert [_at(r, "c[1]", 0.2), _at(r, "c[2]", 0.2), _at(r, "c[2]", 0.8)] == [3, 6, 7]


def test_fixed_false_boolean_parameter_from_an_initial_algorithm():
    """``big`` (fixed=false) is computed by the initial algorithm and selects a branch of an
    if-equation when the model is built: lim = 2 a = 6 > 5, so y = lim."""
    text = """
model Limits
  parameter Real a = 3;
  parameter Boolean big(fixed = false);
  parameter Real lim(fixed = false);
  Real y;
initial algorithm
  lim := 2*a;
  big := false;
  if lim > 5 then
    big := true;
  end if;
equation
  if big then
    y = lim;
  else
    y = -lim;
  end if;
end Limits;
"""
    r = bg.simulate(load_modelica_text(text, "Limits"), stop_time=0.1, interval=0.05)
    np.testing.assert_allclose(r["y"], 6.0)
    r = bg.simulate(load_modelica_text(text, "Limits", a=2), stop_time=0.1, interval=0.05)
    np.testing.assert_allclose(r["y"], -4.0)


def test_connect_two_outputs_of_the_block_itself():
    model = load_modelica_text("""
package P
  block B
    output Real y1;
    output Real y2;
  protected
    output Real z;
  equation
    z = 2*time;
    connect(z, y1);
    connect(y2, y1);
  end B;
  model M
    B b;
  end M;
end P;
""", "P.M")
    r = bg.simulate(model, stop_time=1.0, interval=0.5)
    np.testing.assert_allclose(r["b.y2"], 2*r["time"], atol=1e-12)


def test_connector_with_a_parameter():
    """A connector's parameter sizes its pins; it is not a connection variable."""
    model = load_modelica_text("""
package P
  connector Pin
    Real v;
    flow Real i;
  end Pin;
  connector Plug
    parameter Integer m = 2;
    Pin pin[m];
  end Plug;
  model Load
    parameter Integer m = 2;
    Plug plug(m = m);
  equation
    for k in 1:plug.m loop
      plug.pin[k].i = plug.pin[k].v/k;
    end for;
  end Load;
  model Source
    parameter Integer m = 2;
    Plug plug(m = m);
  equation
    for k in 1:m loop
      plug.pin[k].v = k*time;
    end for;
  end Source;
  model M
    Source s(m = 3);
    Load l(m = 3);
  equation
    connect(s.plug, l.plug);
  end M;
end P;
""", "P.M")
    r = bg.simulate(model, stop_time=1.0, interval=0.5)
    np.testing.assert_allclose(r["l.plug.pin[3].i"], r["time"], atol=1e-12)


def test_modifier_reads_a_later_sibling():
    model = load_modelica_text("""
package P
  model Holder
    Real x;
  end Holder;
  model Src
    Real v = 2*time;
  end Src;
  model M
    Holder h(x = s.v);
    Src s;
  end M;
end P;
""", "P.M")
    r = bg.simulate(model, stop_time=1.0, interval=0.5)
    np.testing.assert_allclose(r["h.x"], 2*r["time"], atol=1e-12)


def test_a_value_not_known_when_built_names_the_equation():
    text = """
model Loop
  Integer k = 2;
  Real x[3];
equation
  for i in 1:k loop
    x[i] = i;
  end for;
  x[3] = 0;
end Loop;
"""
    with pytest.raises(ModelicaError, match=r"<string>:6:\d+: cannot evaluate when the model "
                                            r"is built: k is a variable"):
        bg.compile(load_modelica_text(text, "Loop"))


def test_later_record_read_with_its_own_modifiers():
    """``t(R1 = data.v)`` with ``data`` declared later: ``data.v``'s binding reads
    ``data``'s modifier ``C1`` (the transformer data of a 12-pulse rectifier), not the
    record's default, and ``t.VG`` is the value its class's extends clause sets."""
    model = load_modelica_text("""
model Top
  partial model Base
    constant String VG = "Yy00";
    parameter Real R1 = 0;
    Real x;
  equation
    x = R1;
  end Base;
  model Delta
    extends Base(final VG = "Dd00");
  end Delta;
  record Data
    parameter String C1;
    parameter Real v = if C1 == "Dd00" then 1 else 2;
  end Data;
  Delta t(R1 = data.v);
  parameter Data data(C1 = t.VG);
  Real y = data.v;
end Top;
""", "Top")
    r = bg.simulate(model, stop_time=0.1, interval=0.1)
    assert r["t.x"][-1] == 1.0 and r["y"][-1] == 1.0


def test_parameter_bindings_chained_in_any_order():
    """``p2 = 2*p3`` before ``p3 = p1/5`` before... with ``p1 = 10*k``: each binding resolves
    to the free parameters whatever the declaration order (a chain like a transformer's
    ``L1 = L1sigma + M*n`` with ``M = Lm1/n``), also with events in the model."""
    model = load_modelica_text("""
model Chain
  parameter Real k = 1;
  parameter Real p1 = 10*k;
  parameter Real p2 = 2*p3;
  parameter Real p3 = p1/5;
  Real x(start = 0, fixed = true);
  Real y = if time < 0.5 then 0 else 1;
equation
  der(x) = p2;
end Chain;
""", "Chain")
    r = bg.simulate(model, stop_time=1.0, interval=0.5, params={"k": 2.0})
    np.testing.assert_allclose(r["x"][-1], 8.0, rtol=1e-9)
    assert r.parameters["p2"] == 8.0
