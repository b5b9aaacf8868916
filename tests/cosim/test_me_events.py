"""The master runs hybrid FMUs: Model Exchange with state events (bouncing ball), time events
(Stair), typed (Integer, Boolean) outputs, and Co-Simulation FMUs with events inside doStep;
checked against the analytic solutions and against fmpy on the same FMUs."""

from __future__ import annotations

import functools
import math
from pathlib import Path

import numpy as np
import pytest
from fmpy import simulate_fmu

from bgmodelica.cosim.errors import SetupError
from bgmodelica.cosim.fmu import read_fmu_info
from bgmodelica.cosim.master import Master
from bgmodelica.cosim.ssp import system_from_fmus
from bgmodelica.fmi.from_model import export_model

G, H0, E, V_MIN = 9.81, 1.0, 0.7, 0.1


def _impacts(n: int) -> list[float]:
    """Analytic impact times of the bouncing ball (dropped from H0, restitution E)."""
    t = math.sqrt(2 * H0 / G)
    out, v = [t], G * t
    while len(out) < n:
        v *= E
        if v < V_MIN:
            break
        t += 2 * v / G
        out.append(t)
    return out


@functools.cache
def _fmu(model: str, version: int, base: str) -> Path:
    from library.examples.hybrid import BouncingBall
    from library.examples.reference import Dahlquist, Stair, VanDerPol

    cls = {"BouncingBall": BouncingBall, "Stair": Stair, "Dahlquist": Dahlquist,
           "VanDerPol": VanDerPol}[model]
    return export_model(cls(), Path(base) / f"{model}{version}", fmi_version=version,
                        fmu_type="both")


@pytest.fixture(scope="module")
def fmu(tmp_path_factory):
    base = str(tmp_path_factory.mktemp("me_events"))
    return lambda model, version: _fmu(model, version, base)


def _run(path: Path, interface: str, stop: float, step: float, record: list[str]):
    """Model Exchange with CVODES at 1e-10; Co-Simulation with the FMU's solver at 1e-10."""
    system = system_from_fmus("one", {"m": path}, [])
    tight = {"m": {"solver.tolerance": 1e-10}} if interface == "cs" else None
    return Master(system, interface=interface, me_rtol=1e-10, me_atol=1e-12).simulate(
        stop, step, record=[f"m.{r}" for r in record], parameters=tight)


@pytest.mark.parametrize("version", [2, 3])
def test_bouncing_ball_events_in_model_exchange(fmu, version):
    res = _run(fmu("BouncingBall", version), "me", 3.0, 0.01, ["h", "v", "flying"])
    events = np.array(res.meta["events"]["m"])
    exact = np.array(_impacts(30))
    assert len(events) == len(exact) == 11                 # then the ball rests
    assert np.max(np.abs(events - exact)) < 1e-8
    assert np.all(res["m.h"] >= -1e-9)                      # never falls through the floor
    assert res["m.h"][-1] == 0.0 and res["m.v"][-1] == 0.0
    assert res["m.flying"][0] == 1.0 and res["m.flying"][-1] == 0.0
    # same FMU under fmpy (CVode), on the communication grid
    ref = simulate_fmu(str(fmu("BouncingBall", version)), fmi_type="ModelExchange",
                       stop_time=3.0, output_interval=0.01, relative_tolerance=1e-10,
                       output=["h", "v"])
    for name in ("h", "v"):
        span = np.ptp(ref[name])
        assert np.max(np.abs(np.interp(res.time, ref["time"], ref[name]) - res[f"m.{name}"])) \
            < 1e-6 * span


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("interface", ["me", "cs"])
def test_stair_time_events_and_integer_output(fmu, version, interface):
    res = _run(fmu("Stair", version), interface, 3.5, 0.05, ["counter"])
    assert np.array_equal(res["m.counter"], 1 + np.floor(res.time + 1e-9))
    assert np.array_equal(res["m.y"], res["m.counter"])
    if interface == "me":
        assert res.meta["events"]["m"] == pytest.approx([1.0, 2.0, 3.0], abs=1e-12)
    info = read_fmu_info(fmu("Stair", version))
    assert info.variables["counter"].fmi_type == ("Integer" if version == 2 else "Int32")


@pytest.mark.parametrize("model, names, exact", [
    ("Dahlquist", ["x"], lambda t: {"x": np.exp(-t)}),
    ("VanDerPol", ["x0", "x1"], None),
])
@pytest.mark.parametrize("interface", ["me", "cs"])
def test_smooth_models_agree_with_fmpy(fmu, model, names, exact, interface):
    path = fmu(model, 3)
    res = _run(path, interface, 5.0, 0.05, names)
    ref = simulate_fmu(str(path), fmi_type="ModelExchange" if interface == "me" else
                       "CoSimulation", stop_time=5.0, output_interval=0.05,
                       relative_tolerance=1e-10, output=names)
    for name in names:
        span = np.ptp(ref[name])
        got = res[f"m.{name}"]
        assert np.max(np.abs(np.interp(res.time, ref["time"], ref[name]) - got)) < 1e-6 * span
        if exact is not None:
            assert np.max(np.abs(got - exact(res.time)[name])) < 1e-6 * span


def test_typed_parameters_are_set_with_their_type(fmu):
    """A Real parameter given as text, and errors naming the element for bad values."""
    path = fmu("Stair", 3)
    system = system_from_fmus("one", {"m": path}, [])
    res = Master(system, interface="me").simulate(2.0, 0.1, parameters={"m": {"period": 0.5}})
    assert res["m.y"][-1] == 5.0                           # steps at 0.5, 1, 1.5, 2
    with pytest.raises(Exception, match="'x' is not a number"):
        Master(system, interface="me").simulate(1.0, 0.1, parameters={"m": {"period": "x"}})


def test_fmu_with_only_scheduled_execution_is_refused(fmu):
    from dataclasses import replace

    info = read_fmu_info(fmu("Stair", 3))
    system = system_from_fmus("one", {"m": info.path}, [])
    master = Master(system)
    master.infos["m"] = replace(info, cs_identifier=None, me_identifier=None,
                                scheduled_execution=True)
    with pytest.raises(SetupError, match="offers only Scheduled Execution, which this master "
                                         "does not run"):
        master._interface("m", "", "cs")
