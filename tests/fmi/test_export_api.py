"""``bgmodelica.export_fmu``: one call from a model (or a MODEL reference) to an FMU that fmpy
validates and simulates like the native simulator."""

from __future__ import annotations

import re
from datetime import datetime, timezone

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

import bgmodelica as bg
from bgmodelica.errors import OptionError
from library.examples import RC


@pytest.mark.parametrize(("model", "version", "kind"), [
    ("library.examples:RC", "2.0", "ME"),
    (RC(), "3.0", "CS"),
])
def test_export_fmu_loads_and_simulates_in_fmpy(tmp_path, model, version, kind):
    path = bg.export_fmu(model, tmp_path / "out", fmi_version=version, fmi_type=kind,
                         stop_time=2.0)
    assert path.name == "RC.fmu" and path.is_file()
    assert validate_fmu(str(path)) == []
    fmu = simulate_fmu(str(path), stop_time=2.0, output_interval=0.01,
                       output=["capacitor.v"], relative_tolerance=1e-8)
    ref = bg.simulate(RC(), stop_time=2.0, interval=0.01, rtol=1e-8, atol=1e-10)
    assert np.allclose(fmu["capacitor.v"][-1], ref["capacitor.v"][-1], rtol=1e-4, atol=1e-6)


@pytest.mark.parametrize(("options", "culprit"), [
    ({"fmi_version": "1.0"}, "fmi_version='1.0'"),
    ({"fmi_type": "XX"}, "fmi_type='XX'"),
])
def test_export_fmu_refuses_bad_options(tmp_path, options, culprit):
    with pytest.raises(OptionError, match=culprit):
        bg.export_fmu(RC(), tmp_path, **options)


@pytest.mark.parametrize("version", ["2.0", "3.0"])
def test_fmu_carries_its_date_and_the_model_docstring(tmp_path, version):
    before = datetime.now(timezone.utc).replace(microsecond=0)
    path = bg.export_fmu(RC(), tmp_path, fmi_version=version)
    md = read_model_description(str(path))
    assert md.fmiVersion == version
    assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", md.generationDateAndTime)
    made = datetime.strptime(md.generationDateAndTime, "%Y-%m-%dT%H:%M:%SZ")
    assert made.replace(tzinfo=timezone.utc) >= before
    summary = " ".join(RC.__doc__.split("\n\n")[0].split())
    assert md.description == summary
    assert validate_fmu(str(path)) == []


def test_reproducible_date(tmp_path, monkeypatch):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1795872000")
    path = bg.export_fmu(RC(), tmp_path)
    assert read_model_description(str(path)).generationDateAndTime == "2026-11-28T13:20:00Z"
