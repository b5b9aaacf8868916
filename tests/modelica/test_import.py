"""Modelica text of the library's acceptance models, loaded and compared with the Python
library models: same parameters, rtol = 1e-12 in both simulations, results to 1e-10."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica.modelica import experiment_of, load_modelica

MODELS = Path(__file__).parent / "models"
TOL = dict(rtol=1e-12, atol=1e-12)


def _compare(a, b, pairs, scale_floor=1.0):
    assert len(a.time) == len(b.time)
    np.testing.assert_allclose(a.time, b.time, rtol=0, atol=1e-12)
    for mo_name, py_name in pairs:
        x, y = np.asarray(a[mo_name]), np.asarray(b[py_name])
        scale = max(scale_floor, float(np.max(np.abs(y))))
        err = float(np.max(np.abs(x - y)))
        assert err <= 1e-10 * scale, f"{mo_name} vs {py_name}: {err:.3g}"


def test_rc_circuit():
    from library.examples import RC

    model = load_modelica(MODELS / "circuits.mo", "Circuits.RC")
    assert model.experiment == {"StopTime": 5.0, "Interval": 0.01, "Tolerance": 1e-6}
    kw = dict(stop_time=5.0, interval=0.01, **TOL)
    a, b = bg.simulate(model, **kw), bg.simulate(RC(), **kw)
    names = ["capacitor.v", "resistor.i", "source.i", "capacitor.p.v"]
    _compare(a, b, [(n, n) for n in names])
    t = np.asarray(a.time)
    np.testing.assert_allclose(a["capacitor.v"], 10 * (1 - np.exp(-t)), atol=1e-9)


@pytest.mark.parametrize("name", ["Motors.DCMotor", "Motors.DCMotorMSL"])
def test_dc_motor(name):
    """Own MSL-style components (``der(flange_b.phi - flange_a.phi)`` in the damper) and the
    same drive from ``Modelica.*`` classes mapped onto ``library``."""
    from library.examples import DCMotor

    model = load_modelica(MODELS / "motors.mo", name)
    kw = dict(stop_time=2.0, interval=0.01, **TOL)
    a, b = bg.simulate(model, **kw), bg.simulate(DCMotor(), **kw)
    names = ["rotor.w", "rotor.phi", "inductor.i", "load.phi", "emf.v", "damper.tau"]
    _compare(a, b, [(n, n) for n in names])


def test_cartesian_pendulum():
    from library.examples.constrained import Pendulum

    model = load_modelica(MODELS / "mechanics.mo", "Mechanics.Pendulum")
    kw = dict(stop_time=2.0, interval=0.01, **TOL)
    a, b = bg.simulate(model, **kw), bg.simulate(Pendulum(), **kw)
    _compare(a, b, [(n, n) for n in ("x", "y", "vx", "vy", "T")])
    assert bg.compile(model).summary()["structural_index"] == 3


def test_bouncing_ball():
    from library.examples.hybrid import BouncingBall

    model = load_modelica(MODELS / "mechanics.mo", "Mechanics.BouncingBall")
    kw = dict(stop_time=3.0, interval=0.01, **TOL)
    a, b = bg.simulate(model, **kw), bg.simulate(BouncingBall(), **kw)
    _compare(a, b, [(n, n) for n in ("h", "v", "flying")])
    np.testing.assert_allclose(a.meta["event_times"], b.meta["event_times"], rtol=0, atol=1e-12)
    assert a.meta["event_times"][0] == pytest.approx(np.sqrt(2 / 9.81), abs=1e-9)


def test_rc_ladder_array_form():
    """n = 1000 sections as component arrays ``R[n]``, ``C[n]`` with for-loops of connects,
    against the Python RCLadder(1000) (names R1/C1 there, R[1]/C[1] here)."""
    from library.examples import RCLadder

    model = load_modelica(MODELS / "circuits.mo", "Circuits.RCLadder")
    assert len(model.children()) == 2002
    assert model.children()["R[7]"].R.sym.decl.value == pytest.approx(1 / 7)
    ks = (1, 2, 500, 999, 1000)
    kw = dict(stop_time=1.0, interval=0.01, **TOL)
    a = bg.simulate(model, outputs=[f"C[{k}].v" for k in ks] + ["R[1].i"], **kw)
    b = bg.simulate(RCLadder(1000), outputs=[f"C{k}.v" for k in ks] + ["R1.i"], **kw)
    _compare(a, b, [(f"C[{k}].v", f"C{k}.v") for k in ks] + [("R[1].i", "R1.i")])


def test_ladder_size_is_a_modifier():
    model = load_modelica(MODELS / "circuits.mo", "Circuits.RCLadder", n=4)
    assert sorted(n for n in model.children() if n.startswith("C[")) == [
        "C[1]", "C[2]", "C[3]", "C[4]"]
    res = bg.simulate(model, **experiment_of(model) | {"stop_time": 0.1})
    assert res["C[4].v"][0] == pytest.approx(4.0)


def test_import_does_not_need_library_until_msl_is_used():
    import subprocess
    import sys

    code = ("import sys, bgmodelica as bg\n"
            f"m = bg.load_modelica(r'{MODELS / 'circuits.mo'}', 'Circuits.RC')\n"
            "assert 'library' not in sys.modules\n"
            f"m = bg.load_modelica(r'{MODELS / 'motors.mo'}', 'Motors.DCMotorMSL')\n"
            "assert 'library.electrical' in sys.modules\n")
    subprocess.run([sys.executable, "-c", code], check=True, cwd=str(MODELS.parents[2]))
