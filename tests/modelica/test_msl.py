"""The Modelica Standard Library from its source tree: examples against the Modelica
Association's regression references (inside the tube of their ``check_msl.py``), MSL parts
composed from Python against an analytic solution, the command line.

The MSL is looked for in ``$BGMODELICA_MSL``, then next to the repository
(``../shared/msl``); its references in ``$BGMODELICA_MSL_REFERENCE`` or
``../shared/msl-reference``. Tests skip with the reason when they are absent.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica.cli import main
from bgmodelica.modelica import ModelicaError, experiment_of, load_class
from bgmodelica.modelica import library_path as LP

ROOT = Path(__file__).resolve().parents[2]
MSL = Path(os.environ.get("BGMODELICA_MSL", ROOT.parent / "shared" / "msl"))
REFS = Path(os.environ.get("BGMODELICA_MSL_REFERENCE", ROOT.parent / "shared" / "msl-reference"))

pytestmark = pytest.mark.skipif(not (MSL / "Modelica" / "package.mo").is_file(),
                                reason=f"no Modelica Standard Library at {MSL} "
                                       "(set BGMODELICA_MSL)")


@pytest.fixture
def msl(monkeypatch):
    monkeypatch.setenv("MODELICAPATH", str(MSL))
    LP.clear()
    yield MSL
    LP.clear()


EXAMPLES = ["Mechanics.Rotational.Examples.First",
            "Mechanics.Rotational.Examples.CoupledClutches",
            "Mechanics.Rotational.Examples.LossyGearDemo1",
            "Electrical.Analog.Examples.CauerLowPassAnalog",
            "Blocks.Examples.PID_Controller",
            "Blocks.Examples.LogicalNetwork1",
            "Mechanics.Translational.Examples.Damper",
            "Thermal.HeatTransfer.Examples.TwoMasses",
            "Blocks.Examples.RealNetwork1",
            "Blocks.Examples.IntegerNetwork1",
            "Blocks.Examples.BooleanNetwork1",
            "Electrical.Analog.Examples.AD_DA_conversion",
            "Electrical.Analog.Examples.InvertingAmp",
            "Electrical.Analog.Examples.GenerationOfFMUs",
            "Thermal.HeatTransfer.Examples.GenerationOfFMUs",
            # transistors whose junction currents are exponential: the algebraic loop is
            # re-solved at each source kink from the values just before it
            "Electrical.Analog.Examples.HeatingNPN_NORGate",
            "Electrical.Analog.Examples.HeatingPNP_NORGate"]


@pytest.mark.parametrize("name", EXAMPLES)
def test_example_matches_its_reference(msl, name, tmp_path):
    full = f"Modelica.{name}"
    model = load_class(full)
    result = bg.simulate(model, **experiment_of(model))
    ref = REFS / full
    if not (ref / "ref.csv.gz").is_file():
        pytest.skip(f"no reference for {full} in {REFS}")
    csv = tmp_path / "result.csv"
    result.to_csv(csv)
    done = subprocess.run([sys.executable, str(REFS / "check_msl.py"), str(csv), str(ref)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr


def test_friction_elements_in_series_settle_at_events(msl):
    """Rotational.HeatLosses: a one-way clutch between stuck neighbours starts to slide with
    zero relative acceleration (consistent only once pre(startForward) has caught up), then
    stays within the relation tolerance instead of chattering."""
    result = bg.simulate(load_class("Modelica.Mechanics.Rotational.Examples.HeatLosses"),
                         stop_time=0.01, interval=1e-4)
    assert result["oneWayClutch.w_rel"].min() >= -1e-6


def test_rc_of_msl_parts_composed_in_python(msl):
    from bgmodelica import Component, connect
    from library.electrical import ConstantVoltage, Ground

    class RC(Component):
        def __init__(self, **kw):
            super().__init__(**kw)
            self.R = bg.load_modelica("Modelica.Electrical.Analog.Basic.Resistor", R=1e3)
            self.C = bg.load_modelica("Modelica.Electrical.Analog.Basic.Capacitor", C=1e-3)
            self.src = ConstantVoltage(V=10.0)
            self.gnd = Ground()

        def equations(self):
            yield connect(self.src.p, self.R.p)
            yield connect(self.R.n, self.C.p)
            yield connect(self.C.n, self.src.n)
            yield connect(self.src.n, self.gnd.p)

    r = bg.simulate(RC(), stop_time=3.0, rtol=1e-10, atol=1e-12)
    charge = 1e-3 * r["C.v"]
    exact = 1e-3 * 10.0 * (1.0 - np.exp(-r.time / (1e3 * 1e-3)))      # q = C V (1 - e^-t/RC)
    np.testing.assert_allclose(charge, exact, atol=1e-6 * 1e-2)


def test_cli_takes_an_msl_class(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("MODELICAPATH", "")        # restored after the test: main() sets it
    monkeypatch.setattr(LP, "_extra", [])
    LP.clear()
    out = tmp_path / "first.csv"
    code = main(["simulate", "Modelica.Mechanics.Rotational.Examples.First", "--modelica-path",
                 str(MSL), "-o", str(out)])
    assert code == 0, capsys.readouterr().err
    rows = out.read_text().splitlines()
    assert float(rows[-1].split(",")[0]) == pytest.approx(1.0)      # experiment StopTime
    assert "inertia1.w" in rows[0].split(",")


def test_a_misspelt_class_is_named_with_suggestions(msl):
    with pytest.raises(ModelicaError, match="did you mean Modelica.Mechanics.Rotational."
                                            "Examples.First"):
        load_class("Modelica.Mechanics.Rotational.Examples.Frist")


def test_a_file_of_the_package_folder_with_its_experiment(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("MODELICAPATH", "")
    monkeypatch.setattr(LP, "_extra", [])
    LP.clear()
    out = tmp_path / "first.csv"
    ref = f"{MSL / 'Modelica' / 'package.mo'}:Modelica.Mechanics.Rotational.Examples.First"
    assert main(["simulate", ref, "-o", str(out)]) == 0, capsys.readouterr().err
    rows = out.read_text().splitlines()[1:]
    assert float(rows[-1].split(",")[0]) == pytest.approx(1.0)
    assert len(rows) >= 1001             # the experiment's Interval = 1 ms (default: 501 rows)
