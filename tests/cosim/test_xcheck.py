"""A second, independent master on the same FMUs: fmucontainer's container FMU (its C runtime
steps the embedded FMUs), run by fmpy. Same step, same order: same result to 1e-9."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from cosim_helpers import HORIZON, tight

from bgmodelica.cosim.master import Master
from bgmodelica.cosim.xcheck import build_container, cross_check, run_container

pytest.importorskip("fmu_manipulation_toolbox")


@pytest.mark.parametrize("order", ["jacobi", "gauss-seidel"])
def test_same_result_as_fmucontainer(robot_ssp, tmp_path, order):
    cc = cross_check(robot_ssp, stop_time=HORIZON, step=1e-3, order=order,
                     parameters=tight(robot_ssp), work_dir=tmp_path)
    assert cc.points == 1001
    assert {"arm.q1", "arm.q2", "motor1.i", "motor2.tau", "controller.u1"} <= set(
        cc.max_abs_diff)
    name, worst = cc.worst
    assert worst < 1e-9, (name, worst)
    assert cc.to_dict()["worst_abs_diff"] == worst


def test_cross_check_is_sensitive(robot_ssp, tmp_path):
    """The comparison would see a different scheme: our Gauss-Seidel vs their Jacobi."""
    fmu = build_container(robot_ssp, tmp_path, step_size=1e-3, order="jacobi",
                          parameters=tight(robot_ssp))
    theirs = run_container(fmu, 0.2, 1e-3)
    ours = Master(robot_ssp).simulate(0.2, 1e-3, order="gauss-seidel", propagate=False,
                                      parameters=tight(robot_ssp))
    assert np.max(np.abs(theirs["arm.q2"] - ours["arm.q2"])) > 1e-6


def test_fmucontainer_reads_our_ssp(robot_setup, robot_ssp, tmp_path):
    """fmucontainer's own SSP reader on robot.ssp (it ignores parameter bindings; ours equal
    the FMU defaults), Jacobi: same result as our master."""
    from fmu_manipulation_toolbox.assembly import Assembly

    shutil.copyfile(robot_setup["ssp"], tmp_path / "robot.ssp")
    assembly = Assembly("robot.ssp", fmu_directory=tmp_path, default_step_size=1e-3)
    assembly.make_fmu()
    theirs = run_container(tmp_path / "robot.fmu", 0.3, 1e-3)
    ours = Master(robot_ssp).simulate(0.3, 1e-3, order="jacobi", propagate=False)
    # it names the instances after the FMU files: Motor.fmu -> motor, motor-1
    for mine, its in (("arm.q1", "arm.q1"), ("arm.w2", "arm.w2"), ("motor1.tau", "motor.tau"),
                      ("motor2.tau", "motor-1.tau"), ("controller.u2", "controller.u2")):
        assert np.max(np.abs(theirs[its] - ours[mine])) < 1e-9, mine


def test_container_json_with_the_cli(robot_setup, robot_ssp, tmp_path):
    """robot_container.json (written by export_robot_setup, Gauss-Seidel, 1 ms) through the
    fmucontainer command line."""
    js = Path(robot_setup["container_json"])
    data = json.loads(js.read_text())
    assert data["sequential"] and data["step_size"] == 1e-3
    assert data["fmu"] == ["arm.fmu", "controller.fmu", "motor1.fmu", "motor2.fmu"]
    work = tmp_path / "json"
    shutil.copytree(js.parent, work)
    exe = Path(sys.executable).with_name("fmucontainer")
    proc = subprocess.run([str(exe), "-container", js.name, "-fmu-directory", str(work)],
                          capture_output=True, text=True, cwd=work, timeout=120)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    theirs = run_container(work / "robot_container.fmu", 0.3, 1e-3)
    ours = Master(robot_ssp).simulate(0.3, 1e-3, order="gauss-seidel", propagate=False)
    assert np.max(np.abs(theirs["arm.q1"] - ours["arm.q1"])) < 1e-9
