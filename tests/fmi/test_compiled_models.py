"""Compiled library models exported as FMUs: both checkers pass, and native IDAS, FMU-ME under
fmpy (CVode and Euler) and FMU-CS under fmpy agree (DC motor, an index-2 motor-gear-load, the
robot); a model that needs dynamic state selection (the Cartesian pendulum) is refused."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.validation import validate_fmu
from test_checkers import _fmutool

import bgmodelica as bg
from bgmodelica.fmi.from_model import export_model
from library.examples import DCMotor
from library.examples.constrained import MotorGearLoad, Pendulum
from library.robots.robot import RobotPID

#: model, stop time [s], compared variables, CS deviation bound (relative to the range)
MODELS = {
    "dcmotor": (DCMotor, 1.0, ["inductor.i", "load.w"], 1e-4),
    "gearload": (MotorGearLoad, 1.0, ["L.i", "load.w"], 1e-4),
    "robot": (RobotPID, 2.0, ["arm.q1", "arm.q2", "motor1.i", "motor2.i"], 1e-3),
}


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    cache: dict = {}

    def get(name: str, version: int, kind: str):
        key = (name, version, kind)
        if key not in cache:
            cls, stop, names, _ = MODELS[name]
            if name not in cache:
                compiled = bg.compile(cls())
                ref = bg.simulate(compiled, stop_time=stop, interval=stop / 200, rtol=1e-10,
                                  atol=1e-10, dynamic=False)
                cache[name] = (compiled, ref)
            out = tmp_path_factory.mktemp(f"{name}{version}{kind}")
            cache[key] = export_model(cache[name][0], out, fmi_version=version,
                                      fmu_type=kind, stop_time=stop)
        return cache[key], cache[name][1]

    return get


def _deviation(ref, res, names) -> float:
    worst = 0.0
    for n in names:
        span = max(np.ptp(ref[n]), 1e-12)
        worst = max(worst, np.max(np.abs(np.interp(ref.time, res["time"], res[n]) - ref[n]))
                    / span)
    return worst


@pytest.mark.parametrize("name", list(MODELS))
@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("kind", ["me", "cs"])
def test_checkers_accept(built, name, version, kind):
    fmu, _ = built(name, version, kind)
    assert validate_fmu(str(fmu)) == []
    exe = _fmutool()
    if exe is None:
        pytest.skip("fmutool not installed")
    proc = subprocess.run([exe, "-input", str(fmu), "-check"], capture_output=True, text=True,
                          timeout=120)
    out = proc.stdout + proc.stderr
    assert proc.returncode == 0 and f"compliant with FMI-{version}.0" in out, out
    assert "ERROR" not in out, out


@pytest.mark.parametrize("name", list(MODELS))
@pytest.mark.parametrize("version", [2, 3])
def test_native_me_cs_agree(built, name, version):
    _, stop, names, cs_bound = MODELS[name]
    me, ref = built(name, version, "me")
    cs, _ = built(name, version, "cs")
    grid = dict(stop_time=stop, output_interval=stop / 200, output=names)
    res_me = simulate_fmu(str(me), solver="CVode", relative_tolerance=1e-10, **grid)
    assert _deviation(ref, res_me, names) < 1e-6
    res_cs = simulate_fmu(str(cs), **grid)
    assert _deviation(ref, res_cs, names) < cs_bound


def test_me_euler_converges(built):
    me, ref = built("dcmotor", 2, "me")
    names = MODELS["dcmotor"][2]
    errs = [_deviation(ref, simulate_fmu(str(me), solver="Euler", step_size=h, stop_time=1.0,
                                         output_interval=h, output=names), names)
            for h in (1e-4, 5e-5)]
    assert errs[1] < errs[0] < 5e-2          # first order: halving the step halves the error
    assert 1.5 < errs[0] / errs[1] < 2.5


def test_parameters_are_tunable(built):
    me, _ = built("dcmotor", 2, "me")
    base = simulate_fmu(str(me), stop_time=1.0, output=["load.w"], solver="CVode")
    changed = simulate_fmu(str(me), stop_time=1.0, output=["load.w"], solver="CVode",
                           start_values={"source.V": 6.0})
    assert abs(changed["load.w"][-1] / base["load.w"][-1] - 0.5) < 1e-6


def test_export_refuses_dynamic_state_selection(tmp_path):
    from bgmodelica.fmi.spec import FmuSpecError

    with pytest.raises(FmuSpecError, match="needs dynamic state selection"):
        export_model(Pendulum(), tmp_path)
    # on request, with the compiled states (valid while the pendulum stays below horizontal)
    fmu = export_model(Pendulum(), tmp_path, static_states=True, stop_time=0.4)
    assert fmu.exists()
