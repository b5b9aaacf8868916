"""``bgmodelica.export_fmu``: one call from a model (or a MODEL reference) to an FMU that fmpy
validates and simulates like the native simulator."""

from __future__ import annotations

import numpy as np
import pytest
from fmpy import simulate_fmu
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
