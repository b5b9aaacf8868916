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
            "Electrical.Analog.Examples.HeatingPNP_NORGate",
            # the springs' relative speeds are states (prefer): the stops' reinit keeps them
            "Mechanics.Translational.Examples.HeatLosses"]


@pytest.mark.parametrize("name", EXAMPLES)
def test_example_matches_its_reference(msl, name, tmp_path):
    full = f"Modelica.{name}"
    model = load_class(full)
    _check_reference(bg.simulate(model, **experiment_of(model)), full, tmp_path)


def _check_reference(result, full: str, tmp_path) -> None:
    """``result`` inside the tube of the reference of ``full`` (``check_msl.py``)."""
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


def test_tables_and_radio_buttons_of_interaction1(msl):
    """Blocks.Examples.Interaction1: TimeTable's coefficients come from a function with a
    while loop over time, run at its events; the radio buttons reset each other."""
    r = bg.simulate(load_class("Modelica.Blocks.Examples.Interaction1"), stop_time=10,
                    interval=0.01)

    def at(name: str, t: float) -> float:
        return float(r[name][abs(r.time - t).argmin()])

    # table [0, 0; 1, 2.1; 2, 4.2; 3, 6.3; 4, 4.2; 6, 2.1; 6, 2.1], linear
    for t, y in ((0.5, 1.05), (2.5, 5.25), (3.5, 5.25), (5.0, 3.15), (8.0, 2.1)):
        assert abs(at("timeTable.y", t) - y) < 1e-9
    # integer table held: 2 on [1, 2), 6 on [3, 4), 2 after 6
    assert (at("integerTable.y", 1.5), at("integerTable.y", 3.5), at("integerTable.y", 8.5)) \
        == (2, 6, 2)
    # start pressed at 1 and 3, stop at 2 and 4; each resets the other
    on = [(at("start.on", t), at("stop.on", t)) for t in (0.5, 1.5, 2.5, 3.5, 4.5)]
    assert on == [(0, 0), (1, 0), (0, 1), (1, 0), (0, 1)]


def test_fft_of_a_sampled_current_at_the_end(msl, tmp_path, monkeypatch):
    """Blocks.Examples.Rectifier6pulseFFT: a buffer sampled in a when-clause, its FFT at
    terminal() and the result file written; the signals match their reference."""
    monkeypatch.chdir(tmp_path)
    full = "Modelica.Blocks.Examples.Rectifier6pulseFFT"
    model = load_class(full)
    result = bg.simulate(model, **experiment_of(model))
    from scipy.io import loadmat

    fft = loadmat(tmp_path / "rectifier6pulseFFTresult.mat")["FFT"][1::3]
    top = sorted(fft[np.argsort(-fft[:, 1])[:7], 0])
    # the fundamental (50 Hz) and the harmonics 5, 7, 11, 13, 17, 19 of a 6-pulse bridge
    assert top == [50, 250, 350, 550, 650, 850, 950]
    _check_reference(result, full, tmp_path)


def test_transformers_with_parameters_bound_out_of_order(msl):
    """Electrical.Analog.Examples.CompareTransformers: ``L1 = L1sigma + M*n`` is declared
    before ``M = Lm1/n``; the bindings resolve. A 0.1 V DC offset plus 0.1 V peak at 10 Hz,
    n = 2: after 50 s the basic transformer's magnetizing inductance carries the DC current
    Vdc/R1 = 10 A (less the secondary's share) and passes only the AC part, +-0.05 V on the
    load, while the ideal transformer passes DC and AC, 0 to 0.1 V."""
    model = load_class("Modelica.Electrical.Analog.Examples.CompareTransformers")
    r = bg.simulate(model, **experiment_of(model))
    last = r["time"] > 49.0
    assert 9.0 < np.mean(r["i1B"][last]) < 10.0
    np.testing.assert_allclose([r["load1.v"][last].max(), -r["load1.v"][last].min()],
                               0.05, rtol=0.1)
    np.testing.assert_allclose([r["load2.v"][last].max(), r["load2.v"][last].min()],
                               [0.1, 0.0], atol=0.005)
