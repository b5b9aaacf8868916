"""FMUs of models that need dynamic state selection (issue 37): the Cartesian pendulums export
with every candidate selection and switch at events, and ``reinit`` of a state demoted by
index reduction (PendulumWall) re-initializes consistently.

Simulated under fmpy over 5 s (PendulumWall 3 s) at rtol 1e-10 with 1 ms output: Pendulum
against the exact (elliptic-function) solution to 1e-5 in x and y, the others against a tight
native simulation to 1e-5 (PendulumWall 1e-4) of each variable's range, output points within
1e-6 s of a native event left out (the two locate it ~1e-9 s apart). The full matrix (each
model as FMI 2.0 ME and FMI 3.0 CS) runs here, two of its cases marked slow; each FMU is
built once.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu
from scipy.special import ellipj, ellipk

import bgmodelica as bg
from bgmodelica.fmi.from_model import export_model, fmu_spec
from library.examples import constrained, hybrid

SLOW = pytest.mark.slow
CASES = [("Pendulum", 2, "me"), ("Pendulum", 3, "cs"),
         pytest.param("PendulumPreferXY", 2, "me", marks=SLOW), ("PendulumPreferXY", 3, "cs"),
         ("DoublePendulum", 2, "me"), pytest.param("DoublePendulum", 3, "cs", marks=SLOW),
         ("PendulumWall", 2, "me"), ("PendulumWall", 3, "cs")]
SIGNALS = {"Pendulum": ["x", "y", "vx", "vy", "T"], "PendulumPreferXY": ["x", "y", "vx", "vy"],
           "DoublePendulum": ["x1", "y1", "x2", "y2", "vx1", "vy1", "vx2", "vy2", "T1", "T2"],
           "PendulumWall": ["x", "y", "vx", "vy", "T"]}


def _model(name: str):
    return getattr(hybrid if name == "PendulumWall" else constrained, name)()


def _stop(name: str) -> float:
    return 3.0 if name == "PendulumWall" else 5.0


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    base = tmp_path_factory.mktemp("state_sets")
    return functools.cache(
        lambda name, version, kind: export_model(
            _model(name), base / f"{name}{version}{kind}", fmi_version=version,
            fmu_type=kind, stop_time=_stop(name)))


@functools.cache
def _native(name: str):
    return bg.simulate(_model(name), _stop(name), 1e-3, rtol=1e-11, atol=1e-13)


def _exact_pendulum(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Released at rest from the horizontal (L = 1 m, g = 9.81): sin(theta/2) =
    k sn(K - w t | k^2), k = sin(pi/4), theta from the downward vertical."""
    k = np.sin(np.pi / 4)
    sn, _, _, _ = ellipj(ellipk(k * k) - np.sqrt(9.81) * t, k * k)
    theta = 2 * np.arcsin(k * sn)
    return np.sin(theta), -np.cos(theta)


def _relative_errors(nat, res, names: list[str]) -> dict[str, float]:
    tn = np.asarray(nat["time"])
    keep = np.unique(tn[::-1], return_index=True)[1]
    keep = len(tn) - 1 - keep                       # right limits at event instants
    t = res["time"]
    events = np.asarray(nat.meta.get("event_times", []), dtype=float)
    away = np.ones(len(t), dtype=bool)
    for te in events:
        away &= np.abs(t - te) > 1e-6
    dup = np.r_[np.diff(t) == 0, False] | np.r_[False, np.diff(t) == 0]
    away &= ~dup
    out = {}
    for n in names:
        ref = np.interp(t, tn[keep], np.asarray(nat[n])[keep])
        out[n] = float(np.max(np.abs(res[n] - ref)[away]) / np.ptp(np.asarray(nat[n])))
    return out


@pytest.mark.parametrize("name,version,kind", CASES)
def test_matches(fmus, name, version, kind):
    fmu = fmus(name, version, kind)
    assert validate_fmu(str(fmu)) == []
    res = simulate_fmu(str(fmu), stop_time=_stop(name), relative_tolerance=1e-10,
                       output_interval=1e-3, output=SIGNALS[name],
                       fmi_type="ModelExchange" if kind == "me" else "CoSimulation")
    if name == "Pendulum":
        ex, ey = _exact_pendulum(res["time"])
        assert np.max(np.abs(res["x"] - ex)) < 1e-5
        assert np.max(np.abs(res["y"] - ey)) < 1e-5
        assert np.max(np.abs(res["x"] ** 2 + res["y"] ** 2 - 1.0)) < 1e-8
        return
    tol = 1e-4 if name == "PendulumWall" else 1e-5
    errors = _relative_errors(_native(name), res, SIGNALS[name])
    assert max(errors.values()) < tol, errors


def test_selection_switches_as_events(fmus):
    """The importer sees the state slots, the active selection and its switches."""
    fmu = fmus("Pendulum", 2, "me")
    md = read_model_description(str(fmu))
    states = [d.variable.derivative.name for d in md.derivatives]
    assert states == ["_stateSet.x[1]", "_stateSet.x[2]"]
    assert md.numberOfEventIndicators == 1
    assert md.modelExchange.completedIntegratorStepNotNeeded is False
    res = simulate_fmu(str(fmu), stop_time=5.0, relative_tolerance=1e-10,
                       output_interval=1e-3, output=["_stateSet.selection"])
    sel = res["_stateSet.selection"]
    assert set(np.unique(sel)) == {0, 1}
    assert 6 <= np.count_nonzero(np.diff(sel)) <= 12    # twice per swing, ~2.7 swings


def test_spec_lists_the_selections():
    spec = fmu_spec(constrained.Pendulum())
    assert spec.hybrid is not None and spec.hybrid.track_pre
    assert "y (0)" in spec.states[0].description and "x (1)" in spec.states[0].description
    assert {v.name for v in spec.locals} >= {"x", "y", "vx", "vy", "T"}


def test_reinit_of_demoted_state_is_exported():
    """PendulumWall: reinit(vy) with vy demoted sets the states from a consistent solve."""
    spec = fmu_spec(hybrid.PendulumWall())
    assert [s.name for s in spec.states] == ["x", "vx"]
    assert sorted(s for s, _, _ in spec.hybrid.reinits[0]) == [0, 1]
    assert spec.hybrid.step.numel_out(4) == 4       # the two reinit values, then x and vx


@pytest.mark.slow
@pytest.mark.parametrize("name,version,kind", [("Pendulum", 2, "cs"), ("PendulumWall", 3, "cs"),
                                               ("Pendulum", 3, "me")])
def test_valgrind_state_sets(fmus, tmp_path, name, version, kind):
    """No leaks and no invalid reads in the state-set runtime, with g = 1.5 m/s2 (the
    pendulum switches its state set at 1.24 s, PendulumWall hits its wall at 1.73 s). The C
    drivers of test_valgrind.py: Co-Simulation steps 30 times 0.1 s, three times over,
    serializing the state and asking a directional derivative; Model Exchange runs the FMI
    event loop for 2.5 s twice (the switches are events that change the states' meaning)."""
    import re
    import shutil
    import subprocess
    import zipfile
    from pathlib import Path

    if shutil.which("valgrind") is None:
        pytest.skip("valgrind is not installed")
    fmu = fmus(name, version, kind)
    with zipfile.ZipFile(fmu) as zf:
        zf.extractall(tmp_path / "fmu")
    md = read_model_description(str(fmu))
    plat = "linux64" if version == 2 else "x86_64-linux"
    ident = (md.coSimulation if kind == "cs" else md.modelExchange).modelIdentifier
    lib = tmp_path / "fmu" / "binaries" / plat / f"{ident}.so"
    vrs = {v.name: v.valueReference for v in md.modelVariables}
    exe = tmp_path / "driver"
    driver = Path(__file__).with_name("valgrind_driver.c" if kind == "cs"
                                      else "valgrind_driver_me.c")
    subprocess.run(["cc", "-g", "-O0", f"-DFMI_VERSION={version}",
                    f"-I{tmp_path / 'fmu' / 'sources'}", str(driver), "-o", str(exe), "-ldl",
                    "-lm"], check=True, capture_output=True, text=True)
    if kind == "cs":
        out = md.derivatives[0].variable.valueReference      # an unknown of Step Mode
        args = [str(exe), str(lib), md.guid, str(vrs["g"]), str(out), "0.1"]
    else:
        args = [str(exe), str(lib), md.guid, str(vrs["g"]), str(vrs["x"]), "-"]
    plain = subprocess.run(args, capture_output=True, text=True, timeout=120)
    assert plain.returncode == 0, plain.stdout + plain.stderr
    if kind == "me":
        assert "events=2 " in plain.stdout, plain.stdout
    proc = subprocess.run(
        ["valgrind", "--tool=memcheck", "--error-exitcode=1", "--leak-check=full",
         "--errors-for-leak-kinds=definite", "--show-leak-kinds=definite", *args],
        capture_output=True, text=True, timeout=600)
    report = proc.stderr
    assert proc.returncode == 0, report[-4000:]
    assert re.search(r"ERROR SUMMARY: 0 errors", report), report[-4000:]
    assert "Invalid read" not in report and "Invalid write" not in report
    assert "driver done rc=0" in proc.stdout
