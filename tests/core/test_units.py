"""Dimensional analysis of equations at compile time, and values given with units."""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import textwrap
import warnings

import numpy as np
import pytest

import bgmodelica as bg
import library
from bgmodelica import (
    Boolean,
    Component,
    Parameter,
    Variable,
    der,
    if_else,
    reinit,
    sample,
    sin,
    sqrt,
    when,
)
from bgmodelica.cli import _parse_sets, main
from bgmodelica.core.flatten import flatten
from bgmodelica.core.units import convert, parse, quantity_value
from bgmodelica.errors import ModelError, UnitError
from bgmodelica.passes.units import UnitWarning, check_units
from library.electrical import ConstantVoltage, Ground, OnePort

BAD_INDUCTOR = textwrap.dedent('''
    from bgmodelica import Component, Parameter, connect, der
    from library.electrical import ConstantVoltage, Ground, OnePort


    class Inductor(OnePort):
        R = Parameter(1.0, unit="Ohm")
        L = Parameter(1.0, unit="H")

        def equations(self):
            yield self.v == self.R * self.i + self.L * self.i      # should be L*der(i)


    class Circuit(Component):
        src = ConstantVoltage(V=1.0)
        inductor = Inductor()
        gnd = Ground()

        def equations(self):
            yield connect(self.src.p, self.inductor.p)
            yield connect(self.inductor.n, self.src.n)
            yield connect(self.src.n, self.gnd.p)
''')


def _model(*equations_of, **decls):
    """A component class with the given declarations and equations (functions of self)."""
    body = dict(decls)
    body["equations"] = lambda self: (f(self) for f in equations_of)
    return type("M", (Component,), body)


def _check(cls) -> list[str]:
    return check_units(flatten(cls()), "error")


# -- the wrong inductor, through the command line ---------------------------------------------


@pytest.fixture
def bad_model(tmp_path):
    path = tmp_path / "bad_inductor.py"
    path.write_text(BAD_INDUCTOR)
    return f"{path}:Circuit"


def test_wrong_inductor_fails_check(bad_model, capsys):
    assert main(["check", bad_model]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert err.startswith("error: UnitError: inductor (Inductor): v == ")
    assert "cannot add Ohm.A (V) and H.A (Wb)" in err


def test_units_warn_downgrades(bad_model, capsys):
    assert main(["check", bad_model, "--units", "warn"]) == 0
    out = capsys.readouterr()
    warning = [line for line in out.err.splitlines() if line.startswith("warning:")]
    assert len(warning) == 1 and "inductor (Inductor)" in warning[0] and "(Wb)" in warning[0]
    assert "balanced" in out.out
    assert main(["check", bad_model, "--units", "off"]) == 0
    assert "warning" not in capsys.readouterr().err


def test_units_option_of_compile_and_simulate(bad_model):
    from bgmodelica.loader import load_model

    with pytest.raises(UnitError, match=r"inductor \(Inductor\).*\(V\) and H\.A \(Wb\)"):
        bg.compile(load_model(bad_model))
    with pytest.warns(UnitWarning, match="Wb"):
        bg.compile(load_model(bad_model), units="warn")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        bg.compile(load_model(bad_model), units="off")
        bg.simulate(load_model(bad_model), stop_time=0.1, units="off")
    with pytest.raises(UnitError):
        bg.simulate(load_model(bad_model), stop_time=0.1)
    with pytest.raises(ValueError, match="units must be one of"):
        bg.compile(load_model(bad_model), units="strict")


def test_warn_mode_counts_equations_of_one_form():
    class Bad(OnePort):
        R = Parameter(1.0, unit="Ohm")

        def equations(self):
            yield self.v == self.R

    m = Component(name="many")
    gnd = m.add("gnd", Ground())
    for k in range(5):
        r = m.add(f"r{k}", Bad())
        m.connect(r.p, gnd.p)
        m.connect(r.n, gnd.p)
    with pytest.warns(UnitWarning) as rec:
        problems = check_units(flatten(m), "warn")
    assert len(problems) == 1 and len(rec) == 1
    assert "r0 (Bad): v == R: left side is V, right side is Ohm" in problems[0]
    assert "and 4 more equations of the same form and units" in problems[0]


# -- the rules --------------------------------------------------------------------------------


def test_der_divides_by_seconds():
    ok = _model(lambda s: der(s.x) == s.v, lambda s: der(s.v) == s.a,
                lambda s: s.a == -s.x / s.T**2, x=Variable(unit="m"), v=Variable(unit="m/s"),
                a=Variable(unit="m/s2"), T=Parameter(1.0, unit="s"))
    assert _check(ok) == []
    bad = _model(lambda s: der(s.x) == s.v, x=Variable(unit="m"), v=Variable(unit="m"))
    with pytest.raises(UnitError, match=r"der\(x\) == v: left side is m/s, right side is m"):
        _check(bad)
    rate = _model(lambda s: der(s.w) == s.x, w=Variable(unit="rad/s"), x=Variable(unit="1/s"))
    with pytest.raises(UnitError, match=r"left side is rad/s2 \(1/s2\), right side is 1/s"):
        _check(rate)


def test_transcendental_functions_need_dimensionless_arguments():
    bad = _model(lambda s: s.y == sin(s.x), x=Variable(unit="m"), y=Variable(unit="1"))
    with pytest.raises(UnitError, match=r"sin\(\) needs a dimensionless argument, got m"):
        _check(bad)
    ok = _model(lambda s: s.y == s.A * sin(s.w * bg.time + s.phi),
                y=Variable(unit="m"), A=Parameter(1.0, unit="m"), w=Parameter(1.0, unit="rad/s"),
                phi=Parameter(0.0, unit="rad"))
    assert _check(ok) == []                   # rad is 1
    deg = _model(lambda s: s.y == sin(s.q), q=Variable(unit="deg"), y=Variable(unit="1"))
    with pytest.raises(UnitError, match="got deg"):      # sin() takes radians
        _check(deg)
    returns_one = _model(lambda s: s.y == bg.exp(s.k), y=Variable(unit="V"),
                         k=Parameter(1.0, unit="1"))
    with pytest.raises(UnitError, match="left side is V, right side is 1"):
        _check(returns_one)
    atan2 = _model(lambda s: s.q == bg.atan2(s.y, s.x), q=Variable(unit="rad"),
                   y=Variable(unit="m"), x=Variable(unit="s"))
    with pytest.raises(UnitError, match="atan2.*m and s"):
        _check(atan2)


def test_literals_adapt_in_sums_and_are_numbers_in_products():
    ok = _model(lambda s: s.v == 0, lambda s: s.w == s.v + 1.0, lambda s: s.u == 2 * s.v - 3,
                lambda s: s.p == if_else(s.v > 0, s.v, 0.0),
                v=Variable(unit="V"), w=Variable(unit="V"), u=Variable(unit="V"),
                p=Variable(unit="V"))
    assert _check(ok) == []
    no_literal = _model(lambda s: s.y == s.J * s.k, y=Variable(unit="kg.m2"),
                        k=Variable(unit="1"), J=Parameter(1.0, unit="1"))
    with pytest.raises(UnitError, match="left side is kg.m2, right side is 1"):
        _check(no_literal)


def test_literals_in_products_adapt_as_in_modelica():
    # a literal factor takes the unit its context needs: 3.0 is in rad/s, 5 in s, 5e-5 in kg.m2
    ok = _model(lambda s: der(s.q) == sin(3.0 * bg.time),
                lambda s: s.y == bg.exp(-bg.time / 5),
                lambda s: s.z == s.A * sin(2 * np.pi * s.f * bg.time),
                lambda s: s.u == s.k * (s.w - 1),
                lambda s: s.J == 5e-5 * s.y,
                lambda s: s.G == 1 / s.R,
                q=Variable(), y=Variable(unit="1"), z=Variable(unit="m"),
                A=Parameter(1.0, unit="m"), f=Parameter(1.0, unit="Hz"), u=Variable(unit="V"),
                k=Parameter(1.0, unit="V"), w=Variable(unit="1"), J=Variable(unit="kg.m2"),
                G=Variable(unit="S"), R=Parameter(1.0, unit="Ohm"))
    assert _check(ok) == []
    # real mismatches are still refused, also next to an adapting literal product
    cases = [
        (lambda s: s.v == s.i + s.v, "cannot add A and V"),
        (lambda s: s.v == 2 * s.v + s.i, "left side is V, right side is A"),
        (lambda s: der(s.x) == s.c, r"der\(x\) == c: left side is m/s, right side is km/h"),
        (lambda s: s.y == sin(bg.time), r"sin\(\) needs a dimensionless argument, got s"),
        (lambda s: s.y == bg.exp(-bg.time / s.tau + s.x), r"cannot add s/s \(1\) and m"),
    ]
    for eq, message in cases:
        bad = _model(eq, v=Variable(unit="V"), i=Variable(unit="A"), x=Variable(unit="m"),
                     c=Variable(unit="km/h"), y=Variable(unit="1"), tau=Parameter(1.0, unit="s"))
        with pytest.raises(UnitError, match=message):
            _check(bad)


def test_undeclared_unit_adapts():
    ok = _model(lambda s: s.v == s.s * s.R, lambda s: s.i == s.s,
                v=Variable(unit="V"), i=Variable(unit="A"), s=Variable(),
                R=Parameter(1.0, unit="Ohm"))
    assert _check(ok) == []


def test_powers_sqrt_and_scales():
    ok = _model(lambda s: s.E == 0.5 * s.m * s.v**2, lambda s: s.v == sqrt(2 * s.E / s.m),
                E=Variable(unit="J"), m=Parameter(1.0, unit="kg"), v=Variable(unit="m/s"))
    assert _check(ok) == []
    bad = _model(lambda s: s.E == s.m * s.v**3, E=Variable(unit="J"),
                 m=Parameter(1.0, unit="kg"), v=Variable(unit="m/s"))
    with pytest.raises(UnitError, match=r"right side is kg\.\(m/s\)\^3"):
        _check(bad)
    scale = _model(lambda s: s.x == s.y + s.z, x=Variable(unit="m"), y=Variable(unit="m"),
                   z=Variable(unit="km"))
    with pytest.raises(UnitError, match=r"cannot add m and km \(1000\*m\)"):
        _check(scale)
    same = _model(lambda s: s.f == s.w, f=Variable(unit="Hz"), w=Variable(unit="rad/s"))
    assert _check(same) == []


def test_if_else_branches_relations_and_logic():
    branches = _model(lambda s: s.y == if_else(s.b, s.x, s.R), y=Variable(unit="m"),
                      x=Variable(unit="m"), R=Parameter(1.0, unit="Ohm"), b=Boolean())
    with pytest.raises(UnitError, match="if_else branches differ: m and Ohm"):
        _check(branches)
    relation = _model(lambda s: s.b == (s.x < s.t), x=Variable(unit="m"),
                      t=Parameter(1.0, unit="s"), b=Boolean())
    with pytest.raises(UnitError, match="cannot compare m and s"):
        _check(relation)
    logic = _model(lambda s: s.b == (s.c & (s.x > 0)), x=Variable(unit="m"), b=Boolean(),
                   c=Boolean())
    assert _check(logic) == []


def test_hybrid_reinit_and_when_assignments():
    class Ball(Component):
        h = Variable(unit="m", start=1.0, fixed=True)
        v = Variable(unit="m/s")
        g = Parameter(9.81, unit="m/s2")

        def equations(self):
            yield der(self.h) == self.v
            yield der(self.v) == -self.g
            yield when(self.h < 0, reinit(self.v, -self.h))

    with pytest.raises(UnitError, match=r"reinit\(v, -h\): v is in m/s, the new value in m"):
        _check(Ball)

    class Sampler(Component):
        x = Variable(unit="m", start=0.0, fixed=True)
        d = bg.Discrete(unit="m")
        Ts = Parameter(0.1, unit="s")

        def equations(self):
            yield der(self.x) == 1.0
            yield when(sample(0, self.Ts), self.d == self.Ts)

    with pytest.raises(UnitError, match="d == Ts: left side is m, right side is s"):
        _check(Sampler)


def test_parameter_bindings_and_unknown_units():
    class Parent(Component):
        L = Parameter(2.0, unit="m")

        def __init__(self, **kw):
            super().__init__(**kw)
            self.add("child", Child(T=self.L))

        def equations(self):
            return ()

    class Child(Component):
        T = Parameter(1.0, unit="s")
        x = Variable(unit="s")

        def equations(self):
            yield self.x == self.T

    with pytest.raises(UnitError, match=r"parameter child.T = L: declared in s, bound to "
                                        "a value in m"):
        _check(Parent)
    unknown = _model(lambda s: s.x == 1.0, x=Variable(unit="blorf"))
    with pytest.raises(UnitError, match="x is declared in an unknown unit"):
        _check(unknown)


def test_initial_equations_are_checked():
    class Osc(Component):
        x = Variable(unit="m")
        v = Variable(unit="m/s")
        T = Parameter(1.0, unit="s")

        def equations(self):
            yield der(self.x) == self.v
            yield der(self.v) == -self.x / self.T**2

        def initial_equations(self):
            yield self.x == self.T

    with pytest.raises(UnitError, match=r"initial equation x == T: left side is m, right side "
                                        "is s"):
        _check(Osc)


# -- every library model ----------------------------------------------------------------------


def _library_classes():
    out = []
    for info in pkgutil.walk_packages(library.__path__, "library."):
        if info.name.endswith("main_job"):
            continue
        mod = importlib.import_module(info.name)
        for name, obj in sorted(vars(mod).items()):
            if (inspect.isclass(obj) and issubclass(obj, Component)
                    and obj.__module__ == mod.__name__ and not name.startswith("_")):
                try:
                    obj()
                except Exception:               # needs constructor arguments
                    continue
                out.append(pytest.param(obj, id=f"{info.name[8:]}:{name}"))
    return out


@pytest.mark.parametrize("cls", _library_classes())
def test_library_model_units(cls):
    """Every library model compiles with units="error"; a partial model (unbalanced on its
    own) has its equations checked all the same."""
    try:
        bg.compile(cls(), units="error")
    except UnitError:
        raise
    except ModelError:
        check_units(flatten(cls()), "error")


# -- values with units ------------------------------------------------------------------------


def test_quantities_convert_to_the_declared_unit():
    assert quantity_value("R.R", "2 kOhm", "Ohm") == pytest.approx(2000.0)
    assert quantity_value("w", "3000 rpm", "rad/s") == pytest.approx(100 * np.pi)
    assert quantity_value("C", "4.7 uF", "F") == pytest.approx(4.7e-6)
    assert quantity_value("T", "20 degC", "K") == pytest.approx(293.15)
    assert quantity_value("x", 3.0, "m") == 3.0 and quantity_value("x", "3", "m") == 3.0
    assert convert(1.0, "N.m", "J") == 1.0
    assert parse("V/(rad.s)").same(parse("V.s/rad") / parse("s2"))
    with pytest.raises(ValueError, match="declares none"):
        quantity_value("k", "2 V", "")
    assert _parse_sets(["R.R=2 kOhm", "C.C=1e-3"]) == {"R.R": "2 kOhm", "C.C": 1e-3}


def _rc():
    from library.electrical import Capacitor, Resistor

    m = Component(name="rc")
    src, r = m.add("src", ConstantVoltage(V=1.0)), m.add("R", Resistor(R=1000.0))
    c, g = m.add("C", Capacitor(C=1e-3, v=0.0)), m.add("gnd", Ground())
    m.connect(src.p, r.p)
    m.connect(r.n, c.p)
    m.connect(c.n, src.n)
    m.connect(src.n, g.p)
    return m


def test_simulate_params_with_units():
    compiled = bg.compile(_rc())
    a = bg.simulate(compiled, stop_time=2.0, interval=0.1, params={"R.R": "2 kOhm"})
    b = bg.simulate(compiled, stop_time=2.0, interval=0.1, params={"R.R": 2000.0})
    assert a.parameters["R.R"] == 2000.0
    np.testing.assert_array_equal(a["C.v"], b["C.v"])
    start = bg.simulate(compiled, stop_time=0.1, params={"C.v": "500 mV"})
    assert start["C.v"][0] == pytest.approx(0.5)
    with pytest.raises(UnitError, match=r"R\.R is declared in Ohm; '2 kg' is in kg"):
        bg.simulate(compiled, stop_time=0.1, params={"R.R": "2 kg"})
    p = compiled.dae.p_vector({"R.R": "1.5 kOhm"})
    assert 1500.0 in p


@pytest.fixture
def rc_file(tmp_path):
    path = tmp_path / "rc.py"
    path.write_text(textwrap.dedent('''
        from bgmodelica import Component
        from library.electrical import Capacitor, ConstantVoltage, Ground, Resistor


        class RC(Component):
            src = ConstantVoltage(V=1.0)
            R = Resistor(R=1000.0)
            C = Capacitor(C=1e-3, v=0.0)
            gnd = Ground()

            def equations(self):
                from bgmodelica import connect
                yield connect(self.src.p, self.R.p)
                yield connect(self.R.n, self.C.p)
                yield connect(self.C.n, self.src.n)
                yield connect(self.src.n, self.gnd.p)
    '''))
    return f"{path}:RC"


def test_cli_set_with_units(rc_file, tmp_path, capsys):
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    assert main(["simulate", rc_file, "--stop-time", "1", "--set", "R.R=2 kOhm", "-o",
                 str(a)]) == 0
    assert main(["simulate", rc_file, "--stop-time", "1", "--set", "R.R=2000", "-o",
                 str(b)]) == 0
    assert a.read_text() == b.read_text()
    capsys.readouterr()
    assert main(["simulate", rc_file, "--stop-time", "1", "--set", "R.R=2 kg", "-o",
                 str(a)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "UnitError: R.R is declared in Ohm" in err and "kg" in err


# -- FMU unit definitions ---------------------------------------------------------------------


def test_every_library_unit_has_si_exponents():
    from bgmodelica.fmi.units import derivative_unit, parse_unit

    units = set()
    for param in _library_classes():
        flat = flatten(param.values[0]())
        for v in flat.variables + flat.parameters + flat.inputs:
            units.add(v.decl.unit)
            units.add(derivative_unit(v.decl.unit))
    units.discard("")
    assert {"V/(rad.s)", "N.m.s/rad", "kg.m2"} <= units
    missing = sorted(u for u in units if parse_unit(u).exponents is None)
    assert missing == []
    assert parse_unit("V/(rad.s)").exponents == {"kg": 1, "m": 2, "s": -4, "A": -1, "rad": -1}
    assert parse_unit("rpm").exponents == {"s": -1, "rad": 1}


@pytest.mark.parametrize("version", [2, 3])
def test_dc_motor_fmu_declares_si_units(version, tmp_path):
    import shutil
    import xml.etree.ElementTree as ET
    import zipfile

    if shutil.which("cc") is None and shutil.which("gcc") is None:
        pytest.skip("no C compiler")
    from fmpy.validation import validate_fmu

    from bgmodelica.fmi.from_model import export_model
    from library.examples.motors import DCMotor

    path = export_model(DCMotor(), tmp_path, fmi_version=version, fmu_type="me")
    assert validate_fmu(str(path)) == []
    root = ET.fromstring(zipfile.ZipFile(path).read("modelDescription.xml"))
    defined = {}
    for unit in root.iter("Unit"):
        base = unit.find("BaseUnit")
        assert base is not None, unit.get("name")
        defined[unit.get("name")] = base.attrib
    used = {e.get("unit") for e in root.iter() if e.get("unit")}
    assert used <= set(defined)
    assert defined["V"] == {"kg": "1", "m": "2", "s": "-3", "A": "-1"}
    assert defined["rad/s"] == {"s": "-1", "rad": "1"}
