"""Pure-Python parts of the exporter: spec validation, units, build errors."""

from __future__ import annotations

import dataclasses
import math

import casadi as ca
import pytest
from fmi_models import algebraic_loop, oscillator

from bgmodelica.fmi import FmuBuildError, FmuSpecError, ScalarVariable, export_fmu
from bgmodelica.fmi.build import find_compiler
from bgmodelica.fmi.model_description import instantiation_token
from bgmodelica.fmi.units import derivative_unit, parse_unit


@pytest.mark.parametrize("unit,exps", [
    ("V", {"kg": 1, "m": 2, "s": -3, "A": -1}),
    ("A", {"A": 1}),
    ("Ohm", {"kg": 1, "m": 2, "s": -3, "A": -2}),
    ("F", {"kg": -1, "m": -2, "s": 4, "A": 2}),
    ("H", {"kg": 1, "m": 2, "s": -2, "A": -2}),
    ("s", {"s": 1}),
    ("rad", {"rad": 1}),
    ("rad/s", {"rad": 1, "s": -1}),
    ("rad/s2", {"rad": 1, "s": -2}),
    ("N", {"kg": 1, "m": 1, "s": -2}),
    ("N.m", {"kg": 1, "m": 2, "s": -2}),
    ("kg", {"kg": 1}),
    ("kg.m2", {"kg": 1, "m": 2}),
    ("m", {"m": 1}),
    ("m/s", {"m": 1, "s": -1}),
    ("m/s2", {"m": 1, "s": -2}),
    ("W", {"kg": 1, "m": 2, "s": -3}),
    ("J", {"kg": 1, "m": 2, "s": -2}),
    ("1", {}),
    ("1/s", {"s": -1}),
    ("N.m.s/rad", {"kg": 1, "m": 2, "s": -1, "rad": -1}),
    ("N.m/A", {"kg": 1, "m": 2, "s": -2, "A": -1}),
])
def test_unit_exponents(unit, exps):
    d = parse_unit(unit)
    assert d.exponents == exps and d.factor == 1.0 and d.offset == 0.0


def test_unit_factors_offsets_and_unknown():
    assert parse_unit("mA").factor == pytest.approx(1e-3)
    assert parse_unit("km/h").factor == pytest.approx(1000 / 3600)
    assert parse_unit("deg").factor == pytest.approx(math.pi / 180)
    assert parse_unit("degC").offset == pytest.approx(273.15)
    assert parse_unit("furlong").exponents == {"m": 1}          # through pint
    assert parse_unit("blorf").exponents is None
    assert parse_unit("m//s").exponents is None
    assert derivative_unit("rad/s") == "rad/s2"
    assert derivative_unit("m") == "m/s"
    assert derivative_unit("1") == "1/s"
    assert derivative_unit("") == ""


def test_spec_validation_errors():
    good = oscillator()
    good.validate()
    with pytest.raises(FmuSpecError, match="identifier"):
        dataclasses.replace(good, model_name="bad name").validate()
    with pytest.raises(FmuSpecError, match="used twice"):
        dataclasses.replace(good, locals=[ScalarVariable("pos", 0.0)]).validate()
    with pytest.raises(FmuSpecError, match="reserved"):
        dataclasses.replace(good, locals=[ScalarVariable("time", 0.0)]).validate()
    with pytest.raises(FmuSpecError, match="elements"):
        dataclasses.replace(good, outputs=good.outputs[:1]).validate()
    with pytest.raises(FmuSpecError, match="not finite"):
        dataclasses.replace(good, inputs=[ScalarVariable("force", math.nan)]).validate()
    with pytest.raises(FmuSpecError, match="outside"):
        dataclasses.replace(good, parameters=[ScalarVariable("mass.m", -1.0, min=0.0)]
                            + good.parameters[1:]).validate()
    bad_init = ca.Function("i", [ca.SX.sym("t"), ca.SX.sym("u"), ca.SX.sym("p", 3)],
                           [ca.SX.zeros(3)])
    with pytest.raises(FmuSpecError, match="init"):
        dataclasses.replace(good, init=bad_init).validate()
    with pytest.raises(FmuSpecError, match="fmu_type"):
        export_fmu(good, "/nonexistent", 2, "xx")
    with pytest.raises(FmuSpecError, match="fmi_version"):
        export_fmu(good, "/nonexistent", 1, "me")


def test_missing_compiler_is_a_typed_error(monkeypatch, tmp_path):
    monkeypatch.setenv("PATH", str(tmp_path))
    monkeypatch.delenv("CC", raising=False)
    with pytest.raises(FmuBuildError, match="no C compiler found"):
        find_compiler()
    with pytest.raises(FmuBuildError, match="no C compiler found"):
        export_fmu(algebraic_loop(), tmp_path, 2, "cs")
    monkeypatch.setenv("CC", "definitely-not-a-compiler")
    with pytest.raises(FmuBuildError, match="definitely-not-a-compiler"):
        find_compiler()


def test_compiler_errors_are_shown(tmp_path, monkeypatch):
    fake = tmp_path / "fakecc"
    fake.write_text("#!/bin/sh\necho 'fatal: something broke' >&2\nexit 1\n")
    fake.chmod(0o755)
    monkeypatch.setenv("CC", str(fake))
    with pytest.raises(FmuBuildError, match="something broke"):
        export_fmu(oscillator(), tmp_path / "out", 3, "me")


def test_token_is_deterministic():
    assert instantiation_token("a", "b") == instantiation_token("a", "b")
    assert instantiation_token("a", "b") != instantiation_token("a", "c")
    assert len(instantiation_token("x")) == 38
