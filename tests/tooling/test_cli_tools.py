"""Command line: --version, info, list, simulate --solver/--max-step."""

from __future__ import annotations

import json

import bgmodelica
from bgmodelica.cli import main


def test_version(capsys):
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"bgmodelica {bgmodelica.__version__}"


def test_info_lists_parameters_states_and_interface(capsys):
    assert main(["info", "library.examples.thermal:ThermalDCMotor"]) == 0
    out = capsys.readouterr().out
    assert "Model Info" in out and "ThermalDCMotor" in out
    assert "winding.alpha" in out and "1/K" in out and "Temperature coefficient" in out
    assert "capacity.T" in out and "293.15 (fixed)" in out
    assert main(["info", "library.robots:RobotOpenLoop", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert [u["name"] for u in info["inputs"]] == ["U1", "U2"]
    assert info["inputs"][0]["unit"] == "V"
    assert [y["name"] for y in info["outputs"]] == ["q1", "q2"]
    assert info["balanced"] and len(info["states"]) == 6
    assert main(["info", "library.examples:DCMotor", "--no-compile", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert "states" not in info and info["parameters"][0]["name"] == "source.V"
    # a parameter bound to another shows the binding (and, compiled, its value)
    assert main(["info", "library.bondgraph.paper:DCMotorDrive"]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if "motor.res.R" in x)
    assert "1 (= motor.R)" in line


def test_list_domains_and_components(capsys):
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    for domain in ("electrical", "rotational", "thermal", "examples.hybrid"):
        assert domain in out
    assert main(["list", "thermal"]) == 0
    out = capsys.readouterr().out
    assert "library.thermal:" in out
    for name in ("HeatPort", "HeatCapacitor", "ThermalConductor", "Convection",
                 "FixedTemperature", "PrescribedHeatFlow", "TemperatureSensor"):
        assert f"\n  {name} " in out
    assert main(["list", "examples", "--json"]) == 0
    refs = [c["ref"] for c in json.loads(capsys.readouterr().out)["components"]]
    assert "library.examples.thermal:ThermalDCMotor" in refs
    assert "library.examples.hybrid:BouncingBall" in refs
    assert main(["list", "nonsense"]) == 2
    assert "no library domain" in capsys.readouterr().err


def test_simulate_solver_and_max_step(tmp_path, capsys):
    out = tmp_path / "m.csv"
    for solver in ("auto", "cvodes", "idas"):
        assert main(["simulate", "library.examples:DCMotor", "--stop-time", "0.2",
                     "--solver", solver, "--max-step", "1e-3", "-o", str(out)]) == 0
        assert out.stat().st_size > 0
    capsys.readouterr()
    assert main(["simulate", "library.examples:DCMotor", "--solver", "rk4"]) == 2
    assert main(["simulate", "library.examples:DCMotor", "--max-step", "-1",
                 "-o", str(out)]) == 2
