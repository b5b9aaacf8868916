"""The Python entry points take the command line's MODEL string as well as a component."""

from __future__ import annotations

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica.errors import ModelLoadError
from library.examples import RC

REF = "library.examples:RC"


def test_compile_and_simulate_a_reference():
    assert bg.compile(REF).name == "RC"
    got = bg.simulate(REF, stop_time=1.0)
    want = bg.simulate(RC(), stop_time=1.0)
    assert np.allclose(got["capacitor.v"], want["capacitor.v"])


def test_reference_to_a_file(tmp_path):
    path = tmp_path / "decay.py"
    path.write_text("from bgmodelica import Component, Variable, der\n\n"
                    "class Decay(Component):\n"
                    "    x = Variable(start=1.0, fixed=True)\n\n"
                    "    def equations(self):\n"
                    "        yield der(self.x) == -self.x\n")
    res = bg.simulate(f"{path}:Decay", stop_time=1.0)
    assert res["x"][-1] == pytest.approx(np.exp(-1.0), rel=1e-5)


def test_analyses_take_a_reference():
    point = bg.steady_state(REF)
    assert point.dae is not None
    sys = bg.linearize("library.examples:DCMotor")
    assert sys.nstates == 3
    assert bg.load_model(REF).__class__.__name__ == "RC"


def test_sweep_takes_a_reference():
    sweep = bg.sweep(REF, grid={"resistor.R": [1.0, 2.0]}, outputs=["capacitor.v"],
                     stop_time=0.5, scheduler="serial")
    assert list(sweep.ok) == [True, True]
    assert repr(sweep) == ("SweepResult(RC: 2 runs, 0 failed; outputs capacitor.v; "
                           "parameters resistor.R)")


def test_a_misspelt_reference_is_one_line():
    with pytest.raises(ModelLoadError, match="did you mean RC"):
        bg.simulate("library.examples:Rc")
