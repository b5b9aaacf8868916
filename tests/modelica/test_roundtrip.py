"""Export -> import round trip of every library example class: the Modelica text loads back
to the same variables and equations and reproduces the results (bit-identical in practice)."""

from __future__ import annotations

import importlib
import inspect
import pkgutil

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica import Component
from bgmodelica.modelica import export_modelica, load_modelica, load_modelica_text

#: stop times short enough for the suite, long enough to pass events and transients
STOP = {"PWMMotor": 0.002, "PWMDriver": 0.002, "StickSlip": 3.0, "HalfWaveRectifier": 0.05,
        "Pendulum": 0.5, "PendulumPreferXY": 0.5, "PendulumWall": 0.6, "DoublePendulum": 0.1,
        "PIDSpeedControl": 1.5}


def _examples():
    """Every Component class defined in a module of ``library.examples``."""
    import library.examples as examples

    out = []
    for info in sorted(pkgutil.iter_modules(examples.__path__), key=lambda m: m.name):
        mod = importlib.import_module(f"library.examples.{info.name}")
        for name, cls in vars(mod).items():
            if inspect.isclass(cls) and issubclass(cls, Component) \
                    and cls.__module__ == mod.__name__:
                out.append(pytest.param(cls, id=name))
    return out


EXAMPLES = _examples()


def test_every_example_is_covered():
    names = {p.id for p in EXAMPLES}
    assert {"RC", "RCLadder", "DCMotor", "PIDSpeedControl", "Pendulum", "BouncingBall",
            "PWMMotor", "StickSlip", "HalfWaveRectifier", "DoublePendulum"} <= names
    assert len(names) >= 18


@pytest.mark.parametrize("cls", EXAMPLES)
def test_round_trip(cls, tmp_path):
    from bgmodelica.core.component import Connector

    model = cls()
    name = cls.__name__
    if any(isinstance(c, Connector) for c in model._children.values()):
        pytest.skip(f"{name} is a part with connectors, not a standalone model")
    stop = STOP.get(name, 1.0)
    path = tmp_path / f"{name}.mo"
    text = export_modelica(model, path, experiment={"StopTime": stop})
    assert path.read_text() == text
    assert f"model {name}" in text and f"end {name};" in text
    assert f"experiment(StopTime = {stop:g})" in text
    back = load_modelica(path, name)
    assert back.experiment == {"StopTime": stop}
    fa, fb = bg.compile(model).flat, bg.compile(back).flat
    assert [v.name for v in fa.variables] == [v.name for v in fb.variables]
    assert [p.name for p in fa.parameters] == [p.name for p in fb.parameters]
    assert len(fa.equations) == len(fb.equations)
    kw = dict(stop_time=stop, interval=stop / 50, rtol=1e-8, atol=1e-10)
    a, b = bg.simulate(model, **kw), bg.simulate(back, **kw)
    assert list(a.names) == list(b.names)
    assert len(a.time) == len(b.time)
    for n in a.names:
        x, y = np.asarray(a[n], dtype=float), np.asarray(b[n], dtype=float)
        scale = max(1.0, float(np.max(np.abs(x)))) if x.size else 1.0
        assert float(np.max(np.abs(x - y), initial=0.0)) <= 1e-12 * scale, n


def test_reexport_is_stable():
    """Export of an exported model gives the same text (modulo the model name)."""
    from library.examples import PIDSpeedControl

    first = export_modelica(PIDSpeedControl())
    second = export_modelica(load_modelica_text(first, "PIDSpeedControl"))
    assert second == first


def test_imported_array_model_round_trips(tmp_path):
    """Component arrays of an imported model export as quoted identifiers 'R[1]'."""
    from pathlib import Path

    src = Path(__file__).parent / "models" / "circuits.mo"
    model = load_modelica(src, "Circuits.RCLadder", n=5)
    text = export_modelica(model)
    assert "Resistor 'R[2]'(R = 0.5);" in text
    assert "connect('R[1]'.n, 'R[2]'.p);" in text
    back = load_modelica_text(text, "RCLadder")
    kw = dict(stop_time=0.2, interval=0.01)
    a, b = bg.simulate(model, **kw), bg.simulate(back, **kw)
    assert list(a.names) == list(b.names)
    for n in a.names:
        np.testing.assert_array_equal(a[n], b[n])
