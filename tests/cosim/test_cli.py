"""The ``cosim`` and ``verify`` subcommands (registered through ``bgmodelica.cli``), the
generic ``verify`` on the robot and the robot's ``verify_robot`` study."""

from __future__ import annotations

import csv
import json

import pytest

from bgmodelica import cli
from bgmodelica.cosim.cli import register
from bgmodelica.cosim.ssp import SspConnection, write_ssp
from library.robots.subsystems import robot_connections, robot_system
from library.robots.verification import VerifyReport, verify_robot


@pytest.fixture
def main(monkeypatch):
    monkeypatch.setattr(cli, "_EXTENSIONS", [register])
    return cli.main


def test_cosim_command(main, robot_setup, tmp_path, capsys):
    out = tmp_path / "r.csv"
    rc = main(["cosim", str(robot_setup["ssp"]), "--stop-time", "0.1", "--step", "1e-3",
               "--order", "jacobi", "--extrapolation", "--set", "controller.Kp1=350",
               "--record", "arm.joint1.q", "-o", str(out), "--plot", str(tmp_path / "r.png")])
    assert rc == 0
    text = capsys.readouterr().out
    assert "jacobi + extrapolation" in text and "100 steps" in text
    rows = list(csv.reader(out.open()))
    assert rows[0][:3] == ["time", "arm.tau1", "arm.tau2"] and "arm.joint1.q" in rows[0]
    assert len(rows) == 102 and float(rows[-1][0]) == pytest.approx(0.1)
    assert (tmp_path / "r.png").stat().st_size > 1000
    # the SSP's own settings: Gauss-Seidel, 1 ms
    assert main(["cosim", str(robot_setup["ssp"]), "--stop-time", "0.01", "-o",
                 str(out)]) == 0
    assert "gauss-seidel, step 0.001 s" in capsys.readouterr().out


def test_cosim_command_reports_bad_setups(main, robot_fmus, tmp_path, capsys):
    system = robot_system(robot_fmus)
    system.connections = [SspConnection(*c) for c in robot_connections()
                          if c != ("arm", "w1", "motor1", "w")]
    bad = write_ssp(system, tmp_path / "bad.ssp")
    assert main(["cosim", str(bad), "--stop-time", "0.01"]) == 2
    err = capsys.readouterr().err
    assert "UnconnectedInputError" in err and "motor1.w" in err
    assert main(["cosim", str(tmp_path / "none.ssp")]) == 2
    assert "does not exist" in capsys.readouterr().err


def test_verify_command(main, robot_setup, capsys):
    """The generic ``verify MODEL SSP`` on the robot's set-up (joint angles by name)."""
    rc = main(["verify", "library.robots.robot:RobotPID", str(robot_setup["ssp"]),
               "--step", "2e-3,1e-3", "--stop-time", "0.3", "--vars", "arm.q1,arm.q2",
               "--static-states", "--json", "--quiet"])
    assert rc == 0
    data = json.loads(capsys.readouterr().out)
    assert data["steps"] == [2e-3, 1e-3] and len(data["rows"]) == 8
    assert data["variables"] == {"arm.q1": "arm.q1", "arm.q2": "arm.q2"}
    assert {(r["order"], r["extrapolation"]) for r in data["rows"]} == {
        ("jacobi", False), ("jacobi", True), ("gauss-seidel", False), ("gauss-seidel", True)}
    assert all(e < 1e-3 for r in data["rows"] if r["step"] == 1e-3
               for e in r["errors"].values())
    rc = main(["verify", "library.robots.robot:RobotPID", str(robot_setup["ssp"]),
               "--step", "1e-3", "--stop-time", "0.3", "--vars", "arm.q1", "--vars", "arm.q2",
               "--static-states", "--quiet", "--tolerance", "1e-3"])
    assert rc == 0
    assert "verify PASSED" in capsys.readouterr().out


def test_robot_verification_module(robot_fmus, monkeypatch, tmp_path, capsys):
    """``python -m library.robots.verification``: the robot's study (old ``verify``)."""
    import library.robots.subsystems as sub
    from library.robots.verification import main as robot_main

    monkeypatch.setattr(sub, "build_robot_fmus", lambda *a, **k: dict(robot_fmus))
    assert robot_main(["--steps", "2e-3,1e-3", "--stop-time", "0.3", "--no-me",
                       "--no-cross-check", "--json", "--quiet", "--plot",
                       str(tmp_path / "v.png")]) == 0
    data = json.loads(capsys.readouterr().out)
    assert len(data["rows"]) == 8
    assert all(r["error_q1"] < 1e-3 and r["error_q2"] < 1e-3 for r in data["rows"]
               if r["step"] == 1e-3)
    assert (tmp_path / "v.png").stat().st_size > 1000


def test_verify_robot_api(robot_fmus):
    rep = verify_robot(steps=(2e-3, 1e-3), stop_time=0.2, fmus=robot_fmus,
                       schemes=(("gauss-seidel", False), ("gauss-seidel", True)),
                       me_step=1e-3, me_stop_time=0.05, cross_check_step=1e-3,
                       cross_check_stop_time=0.05)
    assert isinstance(rep, VerifyReport)
    assert max(rep.split_check.values()) < 1e-8
    assert rep.error(1e-3, "gauss-seidel", True, 2) < rep.error(1e-3, "gauss-seidel", False, 2)
    rows = rep.rows_for("gauss-seidel", False)
    assert rows[0].observed_order == [None, None] and rows[1].observed_order[0] > 0.5
    assert [r.interface for r in rep.rows].count("me") == 2
    assert all(cc["worst_abs_diff"] < 1e-9 for cc in rep.cross_checks)
    text = rep.to_text()
    assert "gauss-seidel + extrapolation" in text and "fmucontainer" in text
    assert "Model Exchange" in text and "monolithic RobotPID" in text
    assert json.loads(json.dumps(rep.to_dict()))["coupling"] == "lumped"
