"""``bgmodelica simulate-fmu`` and :func:`bgmodelica.cosim.simulate_fmu`: one FMU with
inputs from a CSV, parameters by name, both interfaces; checked against analytic solutions."""

from __future__ import annotations

import functools
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from bgmodelica.cosim.errors import InvalidParameterError, UnknownConnectorError
from bgmodelica.cosim.single import simulate_fmu
from bgmodelica.dataio import read_csv
from bgmodelica.fmi.from_model import export_model


@functools.cache
def _lag(version: int, base: str) -> Path:
    from library.blocks import FirstOrder

    return export_model(FirstOrder(k=2.0, T=0.5), Path(base) / f"lag{version}",
                        fmi_version=version, fmu_type="both")


@pytest.fixture(scope="module")
def lag(tmp_path_factory):
    base = str(tmp_path_factory.mktemp("single"))
    return lambda version: _lag(version, base)


def _step_response(t: np.ndarray, k: float, T: float, t_step: float, u: float) -> np.ndarray:
    return np.where(t < t_step, 0.0, k * u * (1 - np.exp(-(t - t_step) / T)))


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("interface", ["me", "cs"])
def test_step_input_from_a_table(lag, version, interface):
    """u jumps from 0 to 1 at t = 1 s (on the communication grid): y = k (1 - e^-(t-1)/T)."""
    res = simulate_fmu(lag(version), stop_time=3.0, interval=0.01, interface=interface,
                       inputs={"u": ([0.0, 1.0, 1.0, 3.0], [0.0, 0.0, 1.0, 1.0])},
                       rtol=1e-10, atol=1e-12)
    exact = _step_response(res.time, 2.0, 0.5, 1.0, 1.0)
    tol = 1e-7 if interface == "me" else 2e-3          # CS: the FMU's own fixed-step solver
    assert np.max(np.abs(res["y"] - exact)) < tol
    assert res["u"][0] == 0.0 and res["u"][-1] == 1.0


def test_ramp_input_is_followed_within_a_step(lag):
    """u = t (a ramp), coarse communication step 0.5 s: the Model Exchange integrator sees
    the ramp inside each step, so y(t) = k (t - T + T e^(-t/T)) exactly."""
    res = simulate_fmu(lag(3), stop_time=2.0, interval=0.5, interface="me",
                       inputs={"u": ([0.0, 2.0], [0.0, 2.0])}, rtol=1e-10, atol=1e-12)
    t = res.time
    assert np.max(np.abs(res["y"] - 2.0 * (t - 0.5 + 0.5 * np.exp(-t / 0.5)))) < 1e-8


def test_cli_with_csv_input_and_set(lag, tmp_path):
    data = tmp_path / "in.csv"
    data.write_text("time,u\n0,0\n0.5,0\n0.5,2\n2,2\n")
    out = tmp_path / "out.csv"
    run = subprocess.run([sys.executable, "-m", "bgmodelica.cli", "simulate-fmu", str(lag(2)),
                          "--input", str(data), "--set", "T=0.25", "--stop-time", "2",
                          "--interval", "0.01", "--interface", "me", "--rtol", "1e-10",
                          "-o", str(out)], capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stderr
    assert "Model Exchange, 201 points to t = 2 s" in run.stdout
    res = read_csv(out)
    exact = _step_response(res.time, 2.0, 0.25, 0.5, 2.0)
    assert np.max(np.abs(res["y"] - exact)) < 1e-7


def test_defaults_come_from_the_fmu(lag):
    res = simulate_fmu(lag(3))                    # DefaultExperiment of the exported FMU
    assert res.time[0] == 0.0 and math.isclose(res.time[-1], 1.0)
    assert res.meta["model"] == "FirstOrder"


def test_bad_inputs_name_the_fmu_and_variable(lag, tmp_path):
    with pytest.raises(UnknownConnectorError, match=r"input data for 'w': lag\.fmu|"
                                                    r"'w': FirstOrder\.fmu has no such input "
                                                    r"\(inputs: u\)"):
        simulate_fmu(lag(2), inputs={"w": ([0, 1], [0, 1])})
    with pytest.raises(InvalidParameterError, match="'abc' is not a number"):
        simulate_fmu(lag(2), parameters={"T": "abc"})
    with pytest.raises(UnknownConnectorError, match="no variable 'nope'"):
        simulate_fmu(lag(2), record=["nope"])
