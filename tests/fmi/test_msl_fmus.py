"""Examples of the Modelica Standard Library as FMUs: built as FMI 2.0 Model Exchange and
FMI 3.0 Co-Simulation, checked by fmpy's ``validate_fmu`` and simulated under fmpy with the
example's experiment settings against the Modelica Association's regression references
(inside the tube of their ``check_msl.py``).

The MSL is looked for in ``$BGMODELICA_MSL``, then next to the repository (``../shared/msl``);
its references in ``$BGMODELICA_MSL_REFERENCE`` or ``../shared/msl-reference``. Tests skip
with the reason when they are absent.
"""

from __future__ import annotations

import csv
import os
import subprocess
import sys
from pathlib import Path

import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

from bgmodelica.compiler import compile
from bgmodelica.fmi.from_model import export_model
from bgmodelica.modelica import library_path as LP
from bgmodelica.modelica import load_class

ROOT = Path(__file__).resolve().parents[2]
MSL = Path(os.environ.get("BGMODELICA_MSL", ROOT.parent / "shared" / "msl"))
REFS = Path(os.environ.get("BGMODELICA_MSL_REFERENCE", ROOT.parent / "shared" / "msl-reference"))

pytestmark = [
    pytest.mark.skipif(not (MSL / "Modelica" / "package.mo").is_file(),
                       reason=f"no Modelica Standard Library at {MSL} (set BGMODELICA_MSL)"),
    pytest.mark.skipif(not (REFS / "check_msl.py").is_file(),
                       reason=f"no MSL references at {REFS} (set BGMODELICA_MSL_REFERENCE)"),
]

CAUER = "Modelica.Electrical.Analog.Examples.CauerLowPassAnalog"
CLUTCHES = "Modelica.Mechanics.Rotational.Examples.CoupledClutches"
PID = "Modelica.Blocks.Examples.PID_Controller"
#: (example, its experiment annotation's stop time)
EXAMPLES = [pytest.param(CAUER, 60.0, id="CauerLowPassAnalog"),
            pytest.param(CLUTCHES, 1.5, id="CoupledClutches", marks=pytest.mark.slow),
            pytest.param(PID, 4.0, id="PID_Controller", marks=pytest.mark.slow)]
KINDS = [pytest.param((2, "me"), id="fmi2-me"), pytest.param((3, "cs"), id="fmi3-cs")]


@pytest.fixture(scope="module")
def compiled():
    """Example name -> its compiled model, built once per module with the MSL on the path."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("MODELICAPATH", str(MSL))
        LP.clear()
        cache: dict[str, object] = {}

        def get(name: str):
            if name not in cache:
                cache[name] = compile(load_class(name))
            return cache[name]

        yield get
    LP.clear()


def _creation(ref: Path) -> dict[str, float]:
    out = {}
    for line in (ref / "creation.txt").read_text().splitlines():
        key, _, value = line.partition("=")
        try:
            out[key.strip()] = float(value.split("//")[0])
        except ValueError:
            continue
    return out


def _write_csv(result, signals: list[str], path: Path) -> None:
    with open(path, "w", newline="") as fh:
        out = csv.writer(fh)
        out.writerow(["time", *signals])
        for row in result:
            out.writerow([float(row["time"]), *(float(row[s]) for s in signals)])


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("name, stop", EXAMPLES)
def test_msl_example_fmu_validates_and_matches_its_reference(compiled, name, stop, kind,
                                                             tmp_path):
    ref = REFS / name
    if not (ref / "ref.csv.gz").is_file():
        pytest.skip(f"no reference for {name} in {REFS}")
    version, fmu_type = kind
    fmu = export_model(compiled(name), tmp_path, fmi_version=version, fmu_type=fmu_type)
    assert validate_fmu(str(fmu)) == []
    md = read_model_description(str(fmu))
    assert float(md.defaultExperiment.stopTime) == pytest.approx(stop)  # the annotation
    signals = [s for s in (ref / "signals.txt").read_text().split() if s != "time"]
    types = {v.name: v.type for v in md.modelVariables}
    assert not set(signals) - set(types)
    if name == CLUTCHES:       # friction modes keep their FMI types
        assert types["clutch1.mode"] == ("Integer" if version == 2 else "Int32")
        assert types["clutch1.startForward"] == "Boolean"
    exp = _creation(ref)
    result = simulate_fmu(str(fmu), start_time=exp["StartTime"], stop_time=exp["StopTime"],
                          output_interval=exp["Interval"], record_events=True, output=signals,
                          relative_tolerance=exp["Tolerance"] if fmu_type == "me" else None)
    _write_csv(result, signals, tmp_path / "result.csv")
    done = subprocess.run([sys.executable, str(REFS / "check_msl.py"),
                           str(tmp_path / "result.csv"), str(ref)], capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr

