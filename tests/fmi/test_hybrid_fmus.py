"""FMUs of models with events (issue 12, item 1): the hybrid examples export as FMI 2.0 and 3.0,
Model Exchange and Co-Simulation, pass fmpy's validation and ``fmutool -check``, and fmpy's
results (ME with CVode, CS with the embedded solver, FMI 3.0 CS also with Event Mode and early
return) match the native simulation (``rtol=1e-10, atol=1e-12``) to 1e-6 of each signal's
range, event times included.

Each test builds its FMU once (cached per worker) and runs every check on it, so that xdist
spreads the builds. Comparisons use the output grid; grid points closer than 1e-6 s to a state
event that the two simulations locate ~1e-8 s apart are left out (event times are compared
on their own), time events at grid points compare with the left or right limit.
"""

from __future__ import annotations

import functools
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

import bgmodelica as bg
from bgmodelica import (
    Component,
    Discrete,
    Input,
    Integer,
    Output,
    Parameter,
    Variable,
    der,
    if_else,
    pre,
    terminal,
    time_table,
    when,
)
from bgmodelica.fmi.from_model import export_model

HERE = Path(__file__).resolve().parent
TIGHT = {"rtol": 1e-10, "atol": 1e-12}


class EventMix(Component):
    """Tables (periodic linear with a jump, hold), a state event counting with pre() into an
    Integer, a relation on an input only, terminal(), and an initial state that follows the
    parameter k (through the fixed start of x2)."""

    k = Parameter(2.0, unit="1/s")
    sp = Input(start=1.0)
    x = Variable(start=0.0)
    x2 = Variable(start=0.2, fixed=True, unit="1/s")
    u = Variable()
    w = Variable()
    y = Output()
    count = Integer(start=0)
    boost = bg.Boolean(start=False)
    final = Discrete(start=0.0)

    def equations(self):
        yield self.u == time_table([0, 0.3, 0.3, 0.7, 1.0], [0, 1, -1, 0.5, 0],
                                   extrapolation="periodic")
        yield self.w == time_table([0.1, 0.25, 0.5], [1, 2, 3], interpolation="hold")
        yield self.boost == (self.sp > 2.0)
        yield self.x2 == self.k * self.x
        yield der(self.x) == self.k * (self.u + 0.2 * self.w
                                       + if_else(self.boost, 0.5, 0.0) - self.x)
        yield when(self.x > 0.3, self.count == pre(self.count) + 1)
        yield when(terminal(), self.final == self.x)
        yield self.y == self.x


def _examples():
    from library.examples.hybrid import BouncingBall, HalfWaveRectifier, PWMMotor
    from library.robots import RobotDigitalPID

    return {
        # model class, stop time, output interval, compared signals
        "BouncingBall": (BouncingBall, 3.0, 0.01, ["h", "v", "flying"]),
        "HalfWaveRectifier": (HalfWaveRectifier, 0.05, 1e-4, ["v_out", "diode.off"]),
        "PWMMotor": (PWMMotor, 5e-3, 1e-5, ["i", "w", "U", "period_start"]),
        "RobotDigitalPID": (RobotDigitalPID, 0.2, 0.01,
                            ["arm.joint1.q", "arm.joint2.q", "motor1.inductor.i",
                             "motor2.inductor.i", "pid1.u", "pid2.I", "pid1.first"]),
    }


EXAMPLES = ("BouncingBall", "HalfWaveRectifier", "PWMMotor", "RobotDigitalPID")
CASES = [(m, v, t) for m in EXAMPLES for v in (2, 3) for t in ("me", "cs")]


@functools.cache
def _build(model: str, version: int, fmu_type: str, out: str) -> Path:
    cls = EventMix if model == "EventMix" else _examples()[model][0]
    return export_model(cls(), Path(out) / f"{model}_{version}_{fmu_type}",
                        fmi_version=version, fmu_type=fmu_type)


@pytest.fixture(scope="module")
def build(tmp_path_factory):
    base = str(tmp_path_factory.mktemp("hybrid_fmus"))
    return lambda model, version, fmu_type: _build(model, version, fmu_type, base)


@functools.cache
def _native(model: str, rtol: float = 1e-10, atol: float = 1e-12):
    cls, stop, dt, _ = _examples()[model]
    return bg.simulate(cls(), stop_time=stop, interval=dt, rtol=rtol, atol=atol)


def _errors(nat, res, names, dt, window=1e-6):
    """Largest deviation from the native result relative to each signal's range, over the
    output grid rows of ``res`` (see the module docstring); also the number compared."""
    ev = np.asarray(nat.meta["event_times"], dtype=float)
    tn = nat.time
    out, compared = {}, 0
    rows = []
    for k, t in enumerate(res["time"]):
        if abs(t - round(t / dt) * dt) > 1e-9 * dt:
            continue                                    # event row between grid points
        gap = np.abs(ev - t)
        if np.any((gap > 1e-12 * max(1.0, t)) & (gap <= window)):
            continue                                    # a state event within 1e-6 s
        match = np.nonzero(np.abs(tn - t) <= 1e-9 * dt)[0]
        assert match.size, f"no native row at t={t}"
        rows.append((k, match))
    compared = len(rows)
    for n in names:
        yn = np.asarray(nat[n], dtype=float)
        yf = np.asarray(res[n], dtype=float)
        rng = np.ptp(yn) or 1.0
        out[n] = max(float(np.min(np.abs(yn[m] - yf[k]))) / rng for k, m in rows)
    return out, compared


def _event_times(res) -> np.ndarray:
    t = np.asarray(res["time"])
    return t[1:][np.diff(t) == 0]


def _check_events(nat, res, tol=1e-6):
    native = np.asarray(nat.meta["event_times"], dtype=float)
    fmu = _event_times(res)
    assert len(fmu) == len(native), (len(fmu), len(native))
    worst = float(np.max(np.abs(fmu - native))) if len(native) else 0.0
    assert worst <= tol, f"event times differ by {worst:.3g} s"
    return worst


def _fmutool() -> str | None:
    exe = Path(sys.executable).with_name("fmutool")
    return str(exe) if exe.exists() else shutil.which("fmutool")


def _check_fmu_files(fmu: Path, version: int) -> None:
    assert validate_fmu(str(fmu)) == []
    exe = _fmutool()
    if exe is not None:
        proc = subprocess.run([exe, "-input", str(fmu), "-check"], capture_output=True,
                              text=True, timeout=120)
        out = proc.stdout + proc.stderr
        assert proc.returncode == 0, out
        assert f"compliant with FMI-{version}.0" in out, out
        if "Semantic Checks" in out:
            assert f"No semantic error against the FMI-{version} standard" in out, out
        assert "ERROR" not in out, out


@pytest.mark.parametrize("model,version,fmu_type", CASES)
def test_hybrid_example(build, model, version, fmu_type):
    fmu = build(model, version, fmu_type)
    _check_fmu_files(fmu, version)
    _, stop, dt, names = _examples()[model]
    nat = _native(model)
    common = dict(stop_time=stop, output_interval=dt, output=names, relative_tolerance=1e-10)
    runs = []
    if fmu_type == "me":
        res = simulate_fmu(str(fmu), fmi_type="ModelExchange", **common)
        runs.append(("ME", res))
        _check_events(nat, res)
    else:
        runs.append(("CS", simulate_fmu(str(fmu), fmi_type="CoSimulation", **common)))
        if version == 3 and model != "RobotDigitalPID":
            res = simulate_fmu(str(fmu), fmi_type="CoSimulation", use_event_mode=True,
                               early_return_allowed=True, **common)
            runs.append(("CS event mode + early return", res))
            _check_events(nat, res)
            runs.append(("CS early return", simulate_fmu(
                str(fmu), fmi_type="CoSimulation", early_return_allowed=True, **common)))
    n_grid = int(round(stop / dt)) + 1
    for what, res in runs:
        errors, compared = _errors(nat, res, names, dt)
        assert compared >= 0.9 * n_grid, (what, compared, n_grid)
        bad = {n: e for n, e in errors.items() if not e <= 1e-6}
        assert not bad, f"{model} FMI {version} {what}: {bad}"


def test_bouncing_ball_impact_times(build):
    """Impacts located by CVODE on the FMU's event indicator (ME) and by the embedded solver
    (CS, FMI 3.0 early return) match the native ones (themselves analytic to 1e-9 s)."""
    nat = _native("BouncingBall")
    native = np.asarray(nat.meta["event_times"])
    g, h0, e = 9.81, 1.0, 0.7
    t1 = np.sqrt(2 * h0 / g)
    assert native[0] == pytest.approx(t1, abs=1e-9)
    assert native[1] == pytest.approx(t1 + 2 * e * g * t1 / g, abs=1e-9)
    me = simulate_fmu(str(build("BouncingBall", 3, "me")), stop_time=3.0, output_interval=0.01,
                      relative_tolerance=1e-10, output=["h", "v"])
    assert np.max(np.abs(_event_times(me) - native)) < 1e-7


def test_rectifier_current_at_tight_tolerance(build):
    """The diode current i = (v_source - v_out)/Ron (Ron = 1e-5 Ohm) amplifies the state's
    integration error 1e5 times: native runs at rtol 1e-10 and 1e-12 differ by 6e-5 of its
    range. Compared at rtol 1e-12 on both sides it agrees to the 1e-6 noise floor."""
    nat = _native("HalfWaveRectifier", 1e-12, 1e-14)
    common = dict(stop_time=0.05, output_interval=1e-4, output=["v_out", "i_d"],
                  relative_tolerance=1e-12)
    me = simulate_fmu(str(build("HalfWaveRectifier", 2, "me")), **common)
    errors, _ = _errors(nat, me, ["v_out", "i_d"], 1e-4)
    assert errors["v_out"] < 1e-9 and errors["i_d"] < 1e-6, errors
    cs = simulate_fmu(str(build("HalfWaveRectifier", 3, "cs")), **common)
    errors, _ = _errors(nat, cs, ["v_out", "i_d"], 1e-4)
    # the embedded BDF solver stops at its 1e-12 tolerance floor
    assert errors["v_out"] < 1e-9 and errors["i_d"] < 3e-6, errors


def test_model_description_of_discrete_variables(build):
    md3 = read_model_description(str(build("BouncingBall", 3, "me")))
    by_name = {v.name: v for v in md3.modelVariables}
    flying = by_name["flying"]
    assert (flying.type, flying.variability, flying.causality, flying.initial) == \
        ("Boolean", "discrete", "local", "exact")
    assert flying.start in (True, "true")
    assert md3.numberOfEventIndicators == 1
    assert [u.variable.name for u in md3.eventIndicators] == ["_event_indicator_1"]
    md2 = read_model_description(str(build("PWMMotor", 2, "me")))
    ps = next(v for v in md2.modelVariables if v.name == "period_start")
    assert (ps.type, ps.variability, ps.unit) == ("Real", "discrete", "s")
    assert md2.numberOfEventIndicators == 0          # time events only
    md = read_model_description(str(build("HalfWaveRectifier", 2, "cs")))
    off = next(v for v in md.modelVariables if v.name == "diode.off")
    assert (off.type, off.variability, off.initial) == ("Boolean", "discrete", "calculated")


def test_tables_counter_input_relation_and_terminal(build):
    """EventMix: periodic and hold tables, an Integer counter with pre(), a relation on an
    input alone (an input event in the FMU), terminal(), a parameter-dependent initial state;
    FMI 3.0 ME and CS in one FMU."""
    from fmpy import extract, instantiate_fmu

    fmu = build("EventMix", 3, "both")
    _check_fmu_files(fmu, 3)
    sig = np.array([(0.0, 1.0), (1.2, 1.0), (1.2, 3.0), (2.5, 3.0)],
                   dtype=[("time", float), ("sp", float)])
    nat = bg.simulate(EventMix(k=3.0), stop_time=2.5, interval=0.01,
                      inputs={"sp": (sig["time"], sig["sp"])}, **TIGHT)
    assert nat["x"][0] == pytest.approx(0.2 / 3.0)
    names = ["x", "u", "w", "count", "boost"]
    for fmi_type in ("ModelExchange", "CoSimulation"):
        res = simulate_fmu(str(fmu), fmi_type=fmi_type, stop_time=2.5, output_interval=0.01,
                           input=sig, output=names, relative_tolerance=1e-10,
                           start_values={"k": 3.0})
        errors, compared = _errors(nat, res, names, 0.01)
        assert compared > 200 and max(errors.values()) <= 1e-6, (fmi_type, errors)
        assert res["count"][-1] == nat["count"][-1] >= 2
    # terminal(): the when-clause runs at fmi3Terminate
    md = read_model_description(str(fmu))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    unzipped = extract(str(fmu))
    inst = instantiate_fmu(unzipped, md, fmi_type="CoSimulation")
    inst.enterInitializationMode()
    inst.exitInitializationMode()
    for k in range(100):
        inst.doStep(currentCommunicationPoint=0.01 * k, communicationStepSize=0.01)
    x_end = inst.getFloat64([vr["x"]])[0]
    assert inst.getFloat64([vr["final"]])[0] == 0.0
    inst.terminate()
    assert inst.getFloat64([vr["final"]])[0] == pytest.approx(x_end, abs=1e-15)
    inst.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)


@pytest.mark.slow
@pytest.mark.parametrize("fmu_type", ["me", "cs"])
@pytest.mark.parametrize("version", [2, 3])
def test_valgrind_bouncing_ball(build, tmp_path, version, fmu_type):
    """No leaks and no invalid reads in the event runtime (the drivers of test_valgrind.py:
    valgrind_driver.c for CS, valgrind_driver_me.c for the ME event loop)."""
    if shutil.which("valgrind") is None:
        pytest.skip("valgrind is not installed")
    fmu = build("BouncingBall", version, fmu_type)
    with zipfile.ZipFile(fmu) as zf:
        zf.extractall(tmp_path / "fmu")
    md = read_model_description(str(fmu))
    plat = "linux64" if version == 2 else "x86_64-linux"
    lib = tmp_path / "fmu" / "binaries" / plat / "BouncingBall.so"
    vrs = {v.name: v.valueReference for v in md.modelVariables}
    exe = tmp_path / "driver"
    driver = HERE / ("valgrind_driver_me.c" if fmu_type == "me" else "valgrind_driver.c")
    subprocess.run(["cc", "-g", "-O0", f"-DFMI_VERSION={version}",
                    f"-I{tmp_path / 'fmu' / 'sources'}", str(driver), "-o", str(exe), "-ldl",
                    "-lm"], check=True, capture_output=True, text=True)
    if fmu_type == "me":   # h0 = 1.5, 2.5 s of the FMI event loop with forward Euler
        args = [str(lib), md.guid, str(vrs["h0"]), str(vrs["h"]), str(vrs["flying"])]
    else:                  # h0 = 1.5, 30 steps of 0.05 s: two impacts inside DoStep
        args = [str(lib), md.guid, str(vrs["h0"]), str(vrs["der(v)"]), "0.05"]
    plain = subprocess.run([str(exe), *args], capture_output=True, text=True, timeout=60)
    assert plain.returncode == 0, plain.stdout + plain.stderr
    if fmu_type == "me":
        assert "events=4 " in plain.stdout, plain.stdout
    proc = subprocess.run(
        ["valgrind", "--tool=memcheck", "--error-exitcode=1", "--leak-check=full",
         "--errors-for-leak-kinds=definite", "--show-leak-kinds=definite", str(exe), *args],
        capture_output=True, text=True, timeout=300)
    report = proc.stderr
    assert proc.returncode == 0, report[-4000:]
    assert re.search(r"ERROR SUMMARY: 0 errors", report), report[-4000:]
    assert "definitely lost" not in report or re.search(r"definitely lost: 0 bytes", report)
    assert "Invalid read" not in report and "Invalid write" not in report
    assert "driver done rc=0" in proc.stdout


@pytest.mark.parametrize("model", EXAMPLES)
@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("interface", ["me", "cs"])
def test_hybrid_example_in_our_master(build, model, version, interface):
    """The same FMUs run by bgmodelica's own master (``bgmodelica simulate-fmu``): Model
    Exchange with its integrator and event location, Co-Simulation through doStep."""
    from bgmodelica.cosim import simulate_fmu as master_simulate

    fmu = build(model, version, interface)
    _, stop, dt, names = _examples()[model]
    nat = _native(model)
    res = master_simulate(fmu, stop_time=stop, interval=dt, interface=interface, record=names,
                          rtol=1e-10, atol=1e-12)
    errors, compared = _errors(nat, res, names, dt)
    assert compared >= 0.9 * (int(round(stop / dt)) + 1)
    bad = {n: e for n, e in errors.items() if not e <= 1e-6}
    assert not bad, f"{model} FMI {version} {interface}: {bad}"
    if interface == "me":
        native = np.asarray(nat.meta["event_times"], dtype=float)
        ours = np.unique(np.round(np.asarray(res.meta["events"]), 12))
        assert len(ours) == len(np.unique(np.round(native, 12)))
        assert np.max(np.abs(ours - np.unique(np.round(native, 12)))) <= 1e-6
