"""The Modelica subset: packages, imports, types and units, extends and modifiers, redeclare,
arrays, for/if/when-equations, conditional components, enumerations, the MSL mapping."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica.errors import UnitError
from bgmodelica.modelica import ModelicaError, load_modelica, load_modelica_text

MODELS = Path(__file__).parent / "models"


def _sim(model, **kw):
    return bg.simulate(model, **{"stop_time": 1.0, "interval": 0.01, **kw})


def test_pid_speed_control_from_msl_blocks():
    """extends with redeclare, Modelica.Blocks (LimPID with an enumeration-valued parameter),
    renamed members (SignalVoltage.v): identical to library.examples.PIDSpeedControl."""
    from library.examples import PIDSpeedControl

    model = load_modelica(MODELS / "motors.mo", "Motors.PIDSpeedControlMSL")
    kw = dict(stop_time=2.0, interval=0.01, rtol=1e-10, atol=1e-10)
    a, b = bg.simulate(model, **kw), bg.simulate(PIDSpeedControl(), **kw)
    assert list(a.names) == list(b.names)
    for n in ("rotor.w", "controller.y", "controller.x_i", "inductor.i"):
        np.testing.assert_allclose(a[n], b[n], rtol=0, atol=1e-10)


ARRAYS = """
package Demo
  constant Real k0 = 2 "package constant";
  type Speed = Real(unit = "m/s");
  type Mode = enumeration(off, slow, fast);
  model Arrays
    import Demo.Speed;
    parameter Integer n = 3;
    parameter Real A[n, n] = [-1, 0, 0; 0, -2, 0; 0, 0, -3];
    parameter Mode mode = Mode.slow;
    parameter Real rate(unit = "1/s") = 1;
    Real x[n](each start = 1, each fixed = true);
    Speed v[2](start = {0.5, 0.25}, each fixed = true);
    Real total = sum(x[i] for i in 1:n) "a declaration equation";
    Real y;
  equation
    der(x) = A*x;
    for i in 1:2 loop
      der(v[i]) = -i*rate*v[i];
    end for;
    if mode == Mode.fast then
      y = k0*total;
    else
      y = total/k0;
    end if;
  end Arrays;
end Demo;
"""


def test_arrays_for_if_enumerations_constants():
    model = load_modelica_text(ARRAYS, "Demo.Arrays")
    assert model._symbols["v[1]"].decl.unit == "m/s"
    res = _sim(model, rtol=1e-8)
    t = np.asarray(res.time)
    for i in (1, 2, 3):
        np.testing.assert_allclose(res[f"x[{i}]"], np.exp(-i * t), rtol=1e-5)
    np.testing.assert_allclose(res["v[2]"], 0.25 * np.exp(-2 * t), rtol=1e-5)
    total = sum(np.exp(-i * t) for i in (1, 2, 3))
    np.testing.assert_allclose(res["total"], total, rtol=1e-5)
    np.testing.assert_allclose(res["y"], total / 2, rtol=1e-5)     # mode = slow
    fast = load_modelica_text(ARRAYS, "Demo.Arrays", mode=3)
    assert _sim(fast)["y"][0] == pytest.approx(2 * 3.0)
    bigger = load_modelica_text(ARRAYS, "Demo.Arrays", n=4, A=np.diag([-1.0] * 4).tolist())
    assert "x[4]" in bigger._symbols


HYBRID = """
model Hybrid
  parameter Real T = 0.1 "sample period";
  Real x(start = 1, fixed = true);
  Real u;
  Integer count(start = 0);
  discrete Real held(start = 0);
  Boolean high(start = false);
equation
  if time < 0.5 then
    u = 1;
  else
    u = -1;
  end if;
  der(x) = u;
  high = x > 1.2;
  when sample(0, T) then
    count = pre(count) + 1;
    held = x;
  end when;
  when x > 1.4 then
    reinit(x, 1);
  end when;
end Hybrid;
"""


def test_when_sample_pre_reinit_if_equation():
    res = _sim(load_modelica_text(HYBRID), rtol=1e-8, atol=1e-10)
    assert res["count"][-1] == 11                  # samples at 0, 0.1, ..., 1.0
    times = res.meta["event_times"]
    assert any(abs(t - 0.4) < 1e-9 for t in times)  # x reaches 1.4 at t = 0.4
    assert float(np.max(res["x"])) <= 1.4 + 1e-9
    assert res["high"][-1] == 0


CONDITIONAL = """
package P
  connector Pin
    Real v(unit = "V");
    flow Real i(unit = "A");
  end Pin;
  model Res
    parameter Real R(unit = "Ohm") = 1;
    Pin p, n;
  equation
    p.v - n.v = R*p.i;
    p.i + n.i = 0;
  end Res;
  model Src
    parameter Real V(unit = "V") = 1;
    Pin p, n;
  equation
    p.v - n.v = V;
    p.i + n.i = 0;
  end Src;
  model Gnd
    Pin p;
  equation
    p.v = 0;
  end Gnd;
  model Circuit
    parameter Boolean second = false;
    parameter Real Rtot(unit = "Ohm") = 4;
    Src s(V = 2);
    Gnd g;
    replaceable Res r1(R = Rtot/2);
    Res r2(R = Rtot/2) if second;
  equation
    connect(s.p, r1.p);
    connect(r1.n, r2.p);
    connect(r2.n, s.n);
    connect(r1.n, s.n);
    connect(s.n, g.p);
  end Circuit;
  model Twice
    Circuit a(second = false);
    Circuit b(Rtot = 8, r1(R = 1));
  end Twice;
end P;
"""


def test_conditional_components_nested_modifiers_parameter_bindings():
    model = load_modelica_text(CONDITIONAL, "P.Twice")
    assert "r2" not in model.a.children()
    res = bg.simulate(model, stop_time=0.01, params={"a.Rtot": 8.0})
    assert res["a.r1.p.i"][-1] == pytest.approx(2 / 4)    # R = Rtot/2 follows the new Rtot
    assert res["b.r1.p.i"][-1] == pytest.approx(2 / 1)    # the outer modifier wins


def test_extends_modifiers_and_msl_interfaces():
    text = """
    model MyR
      extends Modelica.Electrical.Analog.Interfaces.OnePort(v(start = 0.5));
      parameter Modelica.Units.SI.Resistance R = 1;
    equation
      v = R*i;
    end MyR;
    model Use
      MyR r(R = 10);
      Modelica.Electrical.Analog.Sources.SineVoltage s(V = 1, f = 2);
      Modelica.Electrical.Analog.Basic.Ground g;
      Modelica.Electrical.Analog.Basic.Capacitor c(C = 0.01, v(start = 0, fixed = true));
    equation
      connect(s.p, r.p);
      connect(r.n, c.p);
      connect(c.n, s.n);
      connect(s.n, g.p);
    end Use;
    """
    model = load_modelica_text(text, "Use")
    assert model.r.v.sym.decl.start == 0.5
    assert model.r.R.sym.decl.unit == "Ohm"
    res = _sim(model, rtol=1e-9, atol=1e-12)
    # RC low-pass: tau = 0.1 s, forced at 2 Hz
    w, tau = 2 * np.pi * 2, 0.1
    t = np.asarray(res.time)
    steady = (np.sin(w * t) - w * tau * np.cos(w * t)) / (1 + (w * tau) ** 2)
    transient = w * tau / (1 + (w * tau) ** 2) * np.exp(-t / tau)
    np.testing.assert_allclose(res["c.v"], steady + transient, atol=1e-7)


def test_units_are_checked():
    text = """
    model Bad
      import SI = Modelica.Units.SI;
      SI.Voltage v(start = 1, fixed = true);
      SI.Current i;
    equation
      der(v) = -v;
      i = v;
    end Bad;
    """
    model = load_modelica_text(text)
    with pytest.raises(UnitError, match="i = v|V|A"):
        bg.compile(model)


def test_initial_equation_and_der_of_expression():
    text = """
    model Init
      Real x, y;
    initial equation
      x = 2;
      y = 1;
    equation
      der(x + y) = -(x + y);
      der(x - y) = 0;
    end Init;
    """
    res = _sim(load_modelica_text(text), rtol=1e-10, atol=1e-12)
    t = np.asarray(res.time)
    np.testing.assert_allclose(np.asarray(res["x"]) + res["y"], 3 * np.exp(-t), rtol=1e-7)
    np.testing.assert_allclose(np.asarray(res["x"]) - res["y"], 1.0, atol=1e-8)


def test_cli_accepts_modelica_everywhere(tmp_path, capsys):
    from bgmodelica.cli import main

    ref = f"{MODELS / 'circuits.mo'}:Circuits.RCLadder"
    out = tmp_path / "ladder.csv"
    assert main(["simulate", ref, "--arg", "n=5", "-o", str(out), "--stop-time", "0.1"]) == 0
    header = out.read_text().splitlines()[0]
    assert "C[5].v" in header
    assert main(["check", f"{MODELS / 'mechanics.mo'}:Mechanics.Pendulum", "--json"]) == 0
    assert '"structural_index": 3' in capsys.readouterr().out
    rc = tmp_path / "rc.csv"
    assert main(["simulate", f"{MODELS / 'circuits.mo'}:Circuits.RC", "-o", str(rc)]) == 0
    rows = rc.read_text().splitlines()
    assert len(rows) == 1 + 501 and rows[-1].startswith("5,")    # experiment: 0..5 s by 0.01


def test_cli_export_mo(tmp_path, capsys):
    from bgmodelica.cli import main

    out = tmp_path / "motor.mo"
    assert main(["export-mo", "library.examples:DCMotor", "-o", str(out), "--stop-time", "2",
                 "--interval", "0.01", "--verify"]) == 0
    text = out.read_text()
    assert "annotation(experiment(StopTime = 2, Interval = 0.01));" in text
    assert 'parameter Real J(unit = "kg.m2") = 1' in text
    assert "Inductor inductor(i(fixed = true), L = 0.01);" in text
    assert "verify:" in capsys.readouterr().out
    csv = tmp_path / "motor.csv"
    assert main(["simulate", f"{out}:DCMotor", "-o", str(csv)]) == 0
    assert csv.read_text().splitlines()[-1].startswith("2,")


def test_export_of_bond_graph_lifts_outside_references():
    """Elements whose equations use the bond graph's variables (modulated transformers) get
    local copies bound where both are visible."""
    from bgmodelica.modelica import export_modelica
    from library.bondgraph.paper import DCMotor, TwoLinkManipulator

    text = export_modelica(TwoLinkManipulator())
    assert 'Real ext_q1(unit = "rad") "= q1 (outside)";' in text
    assert bg.compile(load_modelica_text(text)).summary()["balanced"]
    model = DCMotor()                       # Se(E = U): a source bound to the graph's U
    back = load_modelica_text(export_modelica(model))
    kw = dict(stop_time=0.5, interval=0.01, rtol=1e-10, atol=1e-12)
    a, b = bg.simulate(model, **kw), bg.simulate(back, **kw)
    for n in a.names:
        np.testing.assert_allclose(a[n], b[n], rtol=0, atol=1e-12)


def test_structural_parameter_must_be_known():
    text = "model M\n  Real n = 2;\n  Real x[n];\nend M;\n"
    with pytest.raises(ModelicaError, match="array size of x must be known"):
        load_modelica_text(text, file="m.mo")


def test_records_and_time_tables_round_trip():
    from bgmodelica import Component, Variable, der, time_table
    from bgmodelica.modelica import export_modelica

    record = """
    package P
      record Data "motor data"
        parameter Real R(unit = "Ohm") = 1;
        parameter Real L(unit = "H") = 0.1;
      end Data;
      model M
        Data d(R = 2);
        parameter Real V(unit = "V") = 1;
        Real i(unit = "A", start = 0, fixed = true);
      equation
        d.L*der(i) = V - d.R*i;
      end M;
    end P;
    """
    res = _sim(load_modelica_text(record, "P.M"), rtol=1e-10, atol=1e-12)
    t = np.asarray(res.time)
    np.testing.assert_allclose(res["i"], 0.5 * (1 - np.exp(-20 * t)), atol=1e-8)

    class Tabled(Component):
        x = Variable(start=0.0, fixed=True)
        y = Variable()

        def equations(self):
            yield self.y == time_table([0, 1, 1, 2], [0, 1, 5, 6])
            yield der(self.x) == self.y

    text = export_modelica(Tabled())
    assert "elseif (time < 2) then (4 + (1 * time))" in text
    kw = dict(stop_time=2.5, interval=0.05, rtol=1e-10, atol=1e-10)
    a, b = bg.simulate(Tabled(), **kw), bg.simulate(load_modelica_text(text), **kw)
    for n in ("x", "y"):
        np.testing.assert_allclose(a[n], b[n], rtol=0, atol=1e-12)


SIZES = """
package Sizes
  partial block MO
    parameter Integer nout = 1;
    output Real y[nout];
  end MO;
  block Ptp "the output size from a parameter array of the block being built"
    parameter Real q[:] = {1};
    extends MO(final nout = size(q, 1));
  equation
    y = q * time;
  end Ptp;
  model Top
    Ptp p(q = {1, 2, 3});
    Real z[2];
    Real w[2];
  equation
    der(z) = {1, -1};
    w = {size(z, 1), size(p.y, 1)} "sizes of variable arrays";
  end Top;
end Sizes;
"""


def test_size_of_parameter_and_variable_arrays():
    r = _sim(load_modelica_text(SIZES, "Sizes.Top"), stop_time=1.0)
    np.testing.assert_allclose(r["p.y[3]"][-1], 3.0)
    np.testing.assert_allclose([r["w[1]"][-1], r["w[2]"][-1]], [2.0, 3.0])
