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


def test_export_with_dynamic_state_selection(tmp_path):
    # the FMU carries the state sets (tests/fmi/test_state_set_fmus.py checks the numbers);
    # on request, the compiled states only (valid while the pendulum stays below horizontal)
    from bgmodelica.fmi.from_model import fmu_spec

    assert any(v.name.startswith("_stateSet.x") for v in fmu_spec(Pendulum()).states)
    fmu = export_model(Pendulum(), tmp_path, static_states=True, stop_time=0.4)
    assert fmu.exists()


def test_sparse_jacobian_is_generated_as_its_nonzeros(tmp_path):
    """A ladder's Jacobian is tridiagonal: the generated code holds its 3n - 2 nonzeros (not
    n*n entries), the embedded solver scatters them, and the CS FMU agrees with native."""
    from bgmodelica.fmi.codegen import build_functions, symbol_prefix
    from bgmodelica.fmi.from_model import fmu_spec
    from library.examples.circuits import RCLadder

    n = 60
    compiled = bg.compile(RCLadder(n))
    spec = fmu_spec(compiled, stop_time=0.2)
    jac = build_functions(spec, symbol_prefix("RCLadder")).jacx.sparsity_out(0)
    assert jac.shape == (n, n) and jac.nnz() == 3 * n - 2
    names = ["C1.v", f"C{n}.v"]
    ref = bg.simulate(compiled, stop_time=0.2, interval=0.001, rtol=1e-10, atol=1e-10,
                      outputs=names)
    fmu = export_model(compiled, tmp_path, fmi_version=2, fmu_type="cs", stop_time=0.2)
    messages: list[str] = []

    def logger(*args):
        text = args[-1]
        messages.append(text.decode() if isinstance(text, bytes) else str(text))

    res = simulate_fmu(str(fmu), stop_time=0.2, output_interval=0.001, output=names,
                       debug_logging=True, logger=logger)
    assert _deviation(ref, res, names) < 1e-3
    # a wrong Jacobian still converges here, but through 1e5 Newton failures: with the right
    # one this linear model needs none (172 steps, one Jacobian when measured)
    stats = next(m for m in messages if "solver statistics" in m).split("statistics: ")[1]
    steps, failures = int(stats.split()[0]), int(stats.split(", ")[2].split()[0])
    assert steps < 1000 and failures < 5, stats
