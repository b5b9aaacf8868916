"""Every exported FMU (FMI 2.0/3.0 x ME/CS) passes fmpy's validation and ``fmutool -check``."""

from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from fmi_models import TYPES, VERSIONS
from fmpy import read_model_description
from fmpy.validation import validate_fmu

MODELS = ("osc", "motor", "loop")
CASES = [(m, v, t) for m in MODELS for v in VERSIONS for t in TYPES]


def _fmutool() -> str | None:
    exe = Path(sys.executable).with_name("fmutool")
    return str(exe) if exe.exists() else shutil.which("fmutool")


@pytest.mark.parametrize("model,version,fmu_type", CASES)
def test_fmpy_validation(build_fmu, model, version, fmu_type):
    fmu = build_fmu(model, version, fmu_type)
    assert validate_fmu(str(fmu)) == []


@pytest.mark.parametrize("model,version,fmu_type", CASES)
def test_fmutool_check(build_fmu, model, version, fmu_type):
    exe = _fmutool()
    if exe is None:
        pytest.skip("fmu-manipulation-toolbox (fmutool) is not installed")
    fmu = build_fmu(model, version, fmu_type)
    proc = subprocess.run([exe, "-input", str(fmu), "-check"], capture_output=True, text=True,
                          timeout=120)
    out = proc.stdout + proc.stderr
    assert proc.returncode == 0, out
    assert f"compliant with FMI-{version}.0" in out, out
    if "Semantic Checks" in out:  # fmu-manipulation-toolbox >= 2.0
        assert f"No semantic error against the FMI-{version} standard" in out, out
    assert "ERROR" not in out, out


@pytest.mark.parametrize("version", VERSIONS)
def test_both_interfaces_in_one_fmu(build_fmu, version):
    fmu = build_fmu("osc", version, "both")
    assert validate_fmu(str(fmu)) == []
    md = read_model_description(str(fmu))
    assert md.modelExchange is not None and md.coSimulation is not None


@pytest.mark.parametrize("version", VERSIONS)
def test_fmu_layout_and_sources(build_fmu, version):
    fmu = build_fmu("loop", version, "cs")
    names = zipfile.ZipFile(fmu).namelist()
    plat = "linux64" if version == 2 else "x86_64-linux"
    assert f"binaries/{plat}/NonlinearRC.so" in names
    assert "sources/NonlinearRC_model.c" in names
    assert f"sources/fmi{version}Functions.h" in names
    assert ("sources/buildDescription.xml" in names) == (version == 3)


def test_only_fmi_symbols_exported(build_fmu, tmp_path):
    if shutil.which("nm") is None:
        pytest.skip("nm not available")
    fmu = build_fmu("loop", 3, "me")
    with zipfile.ZipFile(fmu) as zf:
        zf.extract("binaries/x86_64-linux/NonlinearRC.so", tmp_path)
    out = subprocess.run(["nm", "-D", "--defined-only",
                          str(tmp_path / "binaries/x86_64-linux/NonlinearRC.so")],
                         capture_output=True, text=True, check=True).stdout
    symbols = [line.split()[-1] for line in out.splitlines() if line.strip()]
    assert symbols and all(s.startswith("fmi3") for s in symbols), symbols


@pytest.mark.parametrize("version", VERSIONS)
def test_model_structure(build_fmu, version):
    """Dependencies follow the sparsity; dotted and der() names survive."""
    md = read_model_description(str(build_fmu("osc", version, "me")))
    by_name = {v.name: v for v in md.modelVariables}
    assert md.variableNamingConvention == "structured"
    assert by_name["der(mass.v)"].derivative is by_name["mass.v"]
    deps = {u.variable.name: sorted(d.name for d in u.dependencies) for u in md.derivatives}
    assert deps == {"der(mass.s)": ["mass.v"], "der(mass.v)": ["force", "mass.s", "mass.v"]}
    outs = {u.variable.name: sorted(d.name for d in u.dependencies) for u in md.outputs}
    assert outs == {"pos": ["mass.s"], "spring.f": ["mass.s"]}
    init = {u.variable.name: sorted(d.name for d in u.dependencies) for u in md.initialUnknowns}
    assert init["spring.f"] == ["mass.s", "spring.c"]
    assert by_name["mass.s"].unit == "m" and by_name["der(mass.v)"].unit == "m/s2"
    units = {u.name: u.baseUnit for u in md.unitDefinitions}
    assert units["N"].kg == 1 and units["N"].m == 1 and units["N"].s == -2


def test_calculated_states_with_init(build_fmu):
    md = read_model_description(str(build_fmu("loop", 2, "me")))
    state = next(v for v in md.modelVariables if v.name == "cap.v")
    assert state.initial == "calculated" and state.start is None
    init = {u.variable.name: sorted(d.name for d in u.dependencies) for u in md.initialUnknowns}
    assert init["cap.v"] == ["cap.v0"]
    assert init["res.i"] == ["cap.v0", "res.R", "res.a", "source.U"]


def _degenerate_specs():
    import casadi as ca

    from bgmodelica.fmi import FmuSpec, ScalarVariable

    t = ca.SX.sym("t")
    p = ca.SX.sym("p", 1)
    no_states = FmuSpec("_odd__Name_", "no states, no inputs", [], [],
                        [ScalarVariable("amp", 2.0)], [ScalarVariable("y", 0.0)],
                        ode=ca.Function("f", [t, ca.SX.sym("x", 0), ca.SX.sym("u", 0), p],
                                        [ca.SX(0, 1), p[0] * ca.sin(t)]))
    x = ca.SX.sym("x", 1)
    no_outputs = FmuSpec("Decay", "no parameters, inputs or outputs",
                         [ScalarVariable("x", 1.0)], [], [], [],
                         ode=ca.Function("g", [t, x, ca.SX.sym("u", 0), ca.SX.sym("p", 0)],
                                         [-x, ca.SX(0, 1)]))
    return no_states, no_outputs


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("fmu_type", TYPES)
def test_degenerate_models(tmp_path, version, fmu_type):
    import numpy as np
    from fmpy import simulate_fmu

    from bgmodelica.fmi import export_fmu

    no_states, no_outputs = _degenerate_specs()
    kind = "ModelExchange" if fmu_type == "me" else "CoSimulation"
    fmu = export_fmu(no_states, tmp_path / "a", version, fmu_type)
    assert validate_fmu(str(fmu)) == []
    r = simulate_fmu(str(fmu), fmi_type=kind, output=["y"], stop_time=1.0)
    assert np.allclose(r["y"], 2.0 * np.sin(r["time"]), atol=1e-12)
    fmu = export_fmu(no_outputs, tmp_path / "b", version, fmu_type)
    assert validate_fmu(str(fmu)) == []
    r = simulate_fmu(str(fmu), fmi_type=kind, output=["x"], relative_tolerance=1e-9)
    assert np.allclose(r["x"], np.exp(-r["time"]), rtol=1e-6)
