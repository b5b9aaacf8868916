"""Memcheck of the Co-Simulation binaries with a small C driver (no Python noise)."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import zipfile
from pathlib import Path

import pytest
from fmi_models import VERSIONS
from fmpy import read_model_description

DRIVER = Path(__file__).with_name("valgrind_driver.c")


@pytest.mark.slow
@pytest.mark.parametrize("model,param,output", [("loop", "cap.v0", "res.i"),
                                                ("motor", "motor.R", "speed")])
@pytest.mark.parametrize("version", VERSIONS)
def test_valgrind_cs(build_fmu, tmp_path, version, model, param, output):
    if shutil.which("valgrind") is None:
        pytest.skip("valgrind is not installed")
    fmu = build_fmu(model, version, "cs")
    with zipfile.ZipFile(fmu) as zf:
        zf.extractall(tmp_path / "fmu")
    md = read_model_description(str(fmu))
    plat = "linux64" if version == 2 else "x86_64-linux"
    lib = tmp_path / "fmu" / "binaries" / plat / f"{md.coSimulation.modelIdentifier}.so"
    vrs = {v.name: v.valueReference for v in md.modelVariables}
    exe = tmp_path / "driver"
    subprocess.run(["cc", "-g", "-O0", f"-DFMI_VERSION={version}",
                    f"-I{tmp_path / 'fmu' / 'sources'}", str(DRIVER), "-o", str(exe), "-ldl",
                    "-lm"], check=True, capture_output=True, text=True)
    # the driver alone must work
    # the motor's terminal voltage changes before the last steps (the one-step solver path)
    env = dict(os.environ, BGM_DRIVER_INPUT_VR=str(vrs["U"])) if model == "motor" else None
    plain = subprocess.run([str(exe), str(lib), md.guid, str(vrs[param]), str(vrs[output])],
                           capture_output=True, text=True, timeout=60, env=env)
    assert plain.returncode == 0, plain.stdout + plain.stderr
    proc = subprocess.run(
        ["valgrind", "--tool=memcheck", "--error-exitcode=1", "--leak-check=full",
         "--errors-for-leak-kinds=definite", "--show-leak-kinds=definite",
         str(exe), str(lib), md.guid, str(vrs[param]), str(vrs[output])],
        capture_output=True, text=True, timeout=300, env=env)
    report = proc.stderr
    assert proc.returncode == 0, report[-4000:]
    assert re.search(r"ERROR SUMMARY: 0 errors", report), report[-4000:]
    assert "definitely lost" not in report or re.search(r"definitely lost: 0 bytes", report)
    assert "Invalid read" not in report and "Invalid write" not in report
    assert "driver done rc=0" in proc.stdout
