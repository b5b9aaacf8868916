"""Bad input gets a typed exception whose message names the component / variable at fault."""

from __future__ import annotations

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica import Component, Connector, Flow, Parameter, Potential, Variable, connect, der
from bgmodelica.errors import (
    ConnectError,
    DeclarationError,
    DuplicateNameError,
    InitializationError,
    ModelLoadError,
    ParameterError,
    SimulationError,
    UnbalancedModelError,
)
from bgmodelica.loader import load_model
from library.electrical import Capacitor, ConstantVoltage, Ground, Pin, Resistor
from library.rotational import Flange, Inertia


def rc(**kw) -> Component:
    m = Component(name="RC")
    m.add("src", ConstantVoltage(V=1.0))
    m.add("R", Resistor(R=2.0))
    m.add("C", Capacitor(C=0.5, v=0.0))
    m.add("gnd", Ground())
    m.connect(m.src.p, m.R.p)
    m.connect(m.R.n, m.C.p)
    m.connect(m.C.n, m.src.n)
    m.connect(m.src.n, m.gnd.p)
    return m


def test_missing_equation_names_variable_and_component():
    class Leaky(Component):
        x = Variable(unit="m", start=0.0, fixed=True)
        y = Variable(unit="m")

        def equations(self):
            yield der(self.x) == 1.0

    m = Component(name="top")
    m.add("leak", Leaky())
    with pytest.raises(UnbalancedModelError) as err:
        bg.compile(m)
    msg = str(err.value)
    assert "1 equations for 2 unknowns" in msg
    assert "leak.y" in msg and "declared in leak" in msg
    assert err.value.missing and "leak.y" in err.value.missing[0]


def test_surplus_equation_is_named():
    class Over(Component):
        x = Variable(start=0.0, fixed=True)

        def equations(self):
            yield der(self.x) == 1.0
            yield self.x == 2.0

    with pytest.raises(UnbalancedModelError) as err:
        bg.compile(Over(name="over"))
    assert "2 equations for 1 unknowns" in str(err.value)
    assert err.value.surplus and "Over" in err.value.surplus[0]


def test_structurally_singular_names_parts():
    class Singular(Component):
        a = Variable()
        b = Variable()

        def equations(self):
            yield self.a == 1.0
            yield 2 * self.a == 3.0 + 0 * self.b

    with pytest.raises(UnbalancedModelError) as err:
        bg.compile(Singular(name="s"))
    msg = str(err.value)
    assert "structurally singular" in msg and "b" in msg


def test_incompatible_connectors():
    with pytest.raises(ConnectError) as err:
        connect(Resistor(name="R1").p, Inertia(name="J").flange_a)
    assert "Pin" in str(err.value) and "Flange" in str(err.value)


def test_flow_connected_to_potential():
    r, c = Resistor(name="R1"), Capacitor(name="C1")
    with pytest.raises(ConnectError) as err:
        connect(r.p.i, c.p.v)
    msg = str(err.value)
    assert "flow variable i" in msg and "potential variable v" in msg


def test_connector_kind_mismatch():
    class OddPin(Connector):
        v = Flow(unit="V")
        i = Potential(unit="A")

    with pytest.raises(ConnectError) as err:
        connect(Pin(name="a"), OddPin(name="b"))
    assert "potential" in str(err.value) and "flow" in str(err.value)


def test_unit_mismatch_between_connectors():
    class MilliFlange(Connector):
        phi = Potential(unit="deg")
        tau = Flow(unit="N.m")

    with pytest.raises(ConnectError, match="unit"):
        connect(Flange(name="a"), MilliFlange(name="b"))


def test_duplicate_component_names():
    m = Component(name="top")
    m.add("R", Resistor())
    with pytest.raises(DuplicateNameError, match="'R'"):
        m.add("R", Resistor())


def test_unknown_modifier():
    with pytest.raises(DeclarationError) as err:
        Resistor(Rx=3)
    assert "Resistor" in str(err.value) and "'Rx'" in str(err.value)


def test_unknown_parameter_in_set():
    with pytest.raises(ParameterError) as err:
        bg.simulate(rc(), stop_time=0.1, params={"R.Rx": 1.0})
    assert "R.Rx" in str(err.value) and "R.R" in str(err.value)


def test_non_numeric_parameter_value():
    with pytest.raises(ParameterError, match="not a number"):
        bg.simulate(rc(), stop_time=0.1, params={"R.R": "ten"})


def test_missing_model_file_and_name(tmp_path):
    with pytest.raises(ModelLoadError, match="does not exist"):
        load_model(str(tmp_path / "nope.py") + ":M")
    f = tmp_path / "m.py"
    f.write_text("from library.electrical import Resistor\n")
    with pytest.raises(ModelLoadError, match="no model named 'Missing'"):
        load_model(f"{f}:Missing")
    with pytest.raises(ModelLoadError, match="no module"):
        load_model("no_such_module_xyz:M")


def test_conflicting_fixed_aliases():
    class Twice(Component):
        a = Variable(start=1.0, fixed=True)
        b = Variable(start=2.0, fixed=True)

        def equations(self):
            yield der(self.a) == -self.a
            yield self.a == self.b

    with pytest.raises(InitializationError) as err:
        bg.compile(Twice(name="t"))
    assert "a" in str(err.value) and "b" in str(err.value)


def test_overdetermined_initialization_names_variables():
    from library.examples.constrained import Pendulum

    p = Pendulum(name="pend", x=0.5)          # x fixed as well as y, off the circle
    with pytest.raises(InitializationError) as err:
        bg.simulate(p, stop_time=0.1)
    assert "over-determined" in str(err.value)
    assert "x" in str(err.value) or "y" in str(err.value)


def test_solver_failure_reports_time_and_keeps_partial_result():
    class BlowUp(Component):
        x = Variable(start=1.0, fixed=True)

        def equations(self):
            yield der(self.x) == self.x**2          # x = 1/(1-t): blows up at t = 1

    with pytest.raises(SimulationError) as err:
        bg.simulate(BlowUp(name="b"), stop_time=2.0, interval=0.05)
    e = err.value
    assert 0.8 <= e.time_reached < 1.0
    assert e.result is not None and len(e.result.time) > 10
    assert np.allclose(e.result["x"], 1 / (1 - e.result.time), rtol=1e-3)
    assert "t =" in str(e)


def test_equation_must_be_an_equation():
    class Bad(Component):
        x = Variable()

        def equations(self):
            yield self.x + 1

    with pytest.raises(bg.errors.EquationError, match="lhs == rhs"):
        bg.compile(Bad(name="bad"))


def test_parameter_override_and_unknown_parameter_at_construction():
    r = bg.simulate(rc(), stop_time=1.0, params={"R.R": 1.0, "C.C": 1.0})
    assert abs(r.final("C.v") - (1 - np.exp(-1.0))) < 1e-5
    with pytest.raises(DeclarationError):
        Capacitor(C=1.0, nonsense=2)


def test_parameter_bound_to_parent_parameter():
    class Divider(Component):
        Rtot = Parameter(4.0, unit="Ohm")

        def __init__(self, **kw):
            super().__init__(**kw)
            self.src = ConstantVoltage(V=2.0)
            self.R1 = Resistor(R=self.Rtot / 2)
            self.R2 = Resistor(R=self.Rtot / 2)
            self.gnd = Ground()
            self.connect(self.src.p, self.R1.p)
            self.connect(self.R1.n, self.R2.p)
            self.connect(self.R2.n, self.src.n)
            self.connect(self.src.n, self.gnd.p)

    r = bg.simulate(Divider(name="d"), stop_time=0.1, params={"Rtot": 8.0})
    assert abs(r.final("R1.i") - 0.25) < 1e-9
    assert abs(r.final("R2.v") - 1.0) < 1e-9


def test_subcomponent_cannot_shadow_a_method():
    m = Component(name="top")
    with pytest.raises(DeclarationError, match="method"):
        m.add("connect", Resistor())
