"""Generic verification: ``bgmodelica verify MODEL SSP`` on a model that is not the robot (the
PWM motor split into a hybrid driver FMU and a motor FMU, :mod:`library.examples.splits`),
the tolerance check and its exit status, and the generic package's independence from
``library``."""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from bgmodelica import cli
from bgmodelica.cosim.cli import register
from bgmodelica.cosim.verify import max_error, reference_at, verify_model

ROOT = Path(__file__).resolve().parents[2]
MODEL = "library.examples.hybrid:PWMMotor"
#: macro steps dividing the PWM on time (30 us) and period (50 us); a short horizon
STEPS = "20e-6,10e-6,5e-6"
STOP = "0.002"


@pytest.fixture
def main(monkeypatch):
    monkeypatch.setattr(cli, "_EXTENSIONS", [register])
    return cli.main


@pytest.fixture(scope="module")
def pwm_ssp(tmp_path_factory):
    from library.examples.splits import export_pwm_setup

    return export_pwm_setup(tmp_path_factory.mktemp("pwm"))["ssp"]


def test_generic_package_does_not_import_library():
    """Importing bgmodelica.cosim (and its verify/cli modules) loads nothing from library/,
    although library is importable from the working folder."""
    code = ("import sys\n"
            "assert not any(m == 'library' or m.startswith('library.') for m in sys.modules)\n"
            "import bgmodelica.cosim, bgmodelica.cosim.verify, bgmodelica.cosim.cli\n"
            "import bgmodelica.cosim.xcheck, bgmodelica.cosim.wrap, bgmodelica.cosim.ssp\n"
            "import importlib.util\n"
            "assert importlib.util.find_spec('library') is not None\n"
            "bad = sorted(m for m in sys.modules if m == 'library' or m.startswith('library.'))\n"
            "print(bad)\n"
            "assert not bad, bad\n")
    run = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                         text=True, timeout=60)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "[]"
    # and no module of the package imports it, even lazily inside a function
    for path in (ROOT / "bgmodelica" / "cosim").glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
                [node.module or ""] if isinstance(node, ast.ImportFrom) and not node.level \
                else []
            assert not any(n == "library" or n.startswith("library.") for n in names), \
                f"{path.name} imports {names}"


def test_reference_at_event_instants():
    """At an event instant the reference has two rows; either value counts."""
    data = {"y": np.array([0.0, 1.0, 5.0, 7.0])}

    class Ref:
        time = np.array([0.0, 1.0, 1.0, 2.0])

        def __getitem__(self, name):
            return data[name]
    before, after = reference_at(Ref(), "y", np.array([0.0, 1.0, 1.5, 2.0]))
    assert before.tolist() == [0.0, 1.0, 6.0, 7.0] and after.tolist() == [0.0, 5.0, 6.0, 7.0]
    assert max_error([0.0, 5.0, 6.0, 7.0], Ref(), "y", np.array([0.0, 1.0, 1.5, 2.0])) == 0
    assert max_error([0.0, 1.0, 6.5, 7.0], Ref(), "y", np.array([0.0, 1.0, 1.5, 2.0])) == 0.5


def test_verify_pwm_motor_passes(main, pwm_ssp, capsys):
    rc = main(["verify", MODEL, str(pwm_ssp), "--stop-time", STOP, "--step", STEPS,
               "--tolerance", "0.5", "--quiet"])
    out = capsys.readouterr().out
    assert rc == 0, out
    assert "monolithic PWMMotor" in out and "driver.i ~ i" in out and "motor.w ~ w" in out
    assert "gauss-seidel + extrapolation" in out
    assert out.strip().splitlines()[-1].startswith("verify PASSED: max |error|")


def test_verify_pwm_motor_convergence(main, pwm_ssp, capsys):
    rc = main(["verify", MODEL, str(pwm_ssp), "--stop-time", STOP, "--step", STEPS,
               "--json", "--quiet"])
    assert rc == 0
    data = json.loads(capsys.readouterr().out)
    assert data["variables"] == {"driver.U": "U", "driver.i": "i", "motor.w": "w"}
    assert len(data["rows"]) == 12

    def orders(order, ex, var):
        return [r["observed_order"][var] for r in data["rows"]
                if r["order"] == order and r["extrapolation"] == ex][1:]
    # zero-order hold: first order; with extrapolation: second order (on the speed)
    assert all(0.9 < p < 1.1 for p in orders("jacobi", False, "motor.w"))
    assert all(1.9 < p < 2.2 for p in orders("jacobi", True, "motor.w"))
    # the PWM voltage is exact at the communication points (events located in the FMU)
    assert all(r["errors"]["driver.U"] < 1e-9 for r in data["rows"])
    finest = [r for r in data["rows"] if r["step"] == 5e-6]
    assert all(r["errors"]["motor.w"] < 0.1 for r in finest)


def test_verify_impossible_tolerance_fails(main, pwm_ssp, capsys):
    rc = main(["verify", MODEL, str(pwm_ssp), "--stop-time", STOP, "--step", "10e-6",
               "--order", "gauss-seidel", "--tolerance", "1e-15", "--quiet"])
    assert rc == 1
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert last.startswith("verify FAILED: max |error|")
    assert "exceeds the tolerance 1e-15" in last and "motor.w vs w" in last
    # with --json: the JSON on stdout, the verdict on stderr
    rc = main(["verify", MODEL, str(pwm_ssp), "--stop-time", STOP, "--step", "10e-6",
               "--order", "jacobi", "--no-extrapolation", "--tolerance", "1e-15", "--quiet",
               "--json"])
    cap = capsys.readouterr()
    assert rc == 1
    assert json.loads(cap.out)["tolerance"]["passed"] is False
    assert cap.err.strip().startswith("verify FAILED") and "1e-15" in cap.err


def test_verify_unknown_variable(main, pwm_ssp, capsys):
    rc = main(["verify", MODEL, str(pwm_ssp), "--stop-time", STOP, "--step", "10e-6",
               "--vars", "motor.nope", "--quiet"])
    assert rc == 2
    err = capsys.readouterr().err
    assert "UnknownConnectorError" in err and "motor.nope" in err


def test_verify_model_api(pwm_ssp):
    from library.examples.hybrid import PWMMotor

    rep = verify_model(PWMMotor(), pwm_ssp, steps=(10e-6, 5e-6), stop_time=5e-4,
                       schemes=(("gauss-seidel", True),), variables=["motor.w"])
    assert rep.variables == {"motor.w": "w"} and len(rep.rows) == 2
    e1 = rep.error(10e-6, "gauss-seidel", True, "motor.w")
    e2 = rep.error(5e-6, "gauss-seidel", True, "motor.w")
    assert 0 < e2 < e1
    assert not rep.failures(1.0) and rep.failures(0.0)
    assert "verify PASSED" in rep.verdict(1.0) and "verify FAILED" in rep.verdict(0.0)
    assert json.loads(json.dumps(rep.to_dict()))["model"] == "PWMMotor"
