"""An exported FMU computes its initial state from its parameters as native simulation does:
a fixed start value on a variable that is not a state (here the motor speed, with the load
speed as state) is a condition through the model's equations (load.w = rotor.w / ratio)."""

from __future__ import annotations

import pytest
from fmpy import simulate_fmu

import bgmodelica as bg
from bgmodelica.fmi.from_model import export_model
from library.examples.constrained import MotorGearLoad


@pytest.mark.parametrize("kind", ["me", "cs"])
@pytest.mark.parametrize("version", [2, 3])
def test_initial_state_follows_parameters(tmp_path, kind, version):
    compiled = bg.compile(MotorGearLoad(**{"rotor.w": 10.0}))
    fmu = export_model(compiled, tmp_path, fmu_type=kind, fmi_version=version, stop_time=0.1)
    for ratio in (50.0, 25.0):
        res = simulate_fmu(str(fmu), stop_time=0.1, start_values={"gear.ratio": ratio},
                           output=["load.w"], output_interval=0.01)
        native = bg.simulate(compiled, stop_time=0.1, interval=0.01,
                             params={"gear.ratio": ratio}, rtol=1e-10, atol=1e-12)
        assert res["load.w"][0] == pytest.approx(10.0 / ratio, rel=1e-12)
        assert res["load.w"][-1] == pytest.approx(native["load.w"][-1], rel=1e-6)
