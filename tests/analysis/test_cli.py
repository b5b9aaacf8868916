"""``bgmodelica linearize``, ``simulate --init steady-state`` and ``check`` of a bond graph
(structural and numeric ranks side by side)."""

from __future__ import annotations

import json

import numpy as np

from bgmodelica.cli import main

MOTOR = "library.examples.control:DCMotorIO"


def test_linearize_json_keys(capsys):
    code = main(["linearize", MOTOR, "--set", "V=2", "--set", "R=2", "--json"])
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("states", "inputs", "outputs", "A", "B", "C", "D", "operating_point",
                "eigenvalues", "controllability_rank", "observability_rank"):
        assert key in out, key
    assert out["inputs"] == ["V"] and out["outputs"] == ["w"]
    assert out["controllability_rank"] == 3 and out["observability_rank"] == 2
    assert np.asarray(out["A"]).shape == (3, 3)
    op = out["operating_point"]
    assert op["kind"] == "start values" and op["inputs"] == {"V": 2.0}
    assert "rotor.w" in op["variables"] and "resistor.R" in op["variables"]


def test_linearize_steady_state_with_figures(tmp_path, capsys):
    files = {k: tmp_path / f"{k}.png" for k in ("bode", "step", "pzmap")}
    code = main(["linearize", MOTOR, "--set", "V=1", "--steady-state",
                 "--exclude", "rotor.phi", "--outputs", "w", "inductor.i",
                 "--bode", str(files["bode"]), "--step", str(files["step"]),
                 "--pzmap", str(files["pzmap"])])
    assert code == 0
    text = capsys.readouterr().out
    assert "linearized at the steady state" in text
    assert "numeric controllability rank: 3/3" in text
    assert "numeric observability rank: 2/3" in text and "unobservable modes" in text
    for f in files.values():
        assert f.stat().st_size > 5000


def test_linearize_errors_are_one_line(capsys):
    assert main(["linearize", MOTOR, "--steady-state", "--at-time", "1"]) == 2
    assert "exclude each other" in capsys.readouterr().err
    assert main(["linearize", MOTOR, "--set", "V=1", "--steady-state"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no steady state" in err and "rotor.phi" in err


def test_simulate_init_steady_state(tmp_path, capsys):
    out = tmp_path / "pend.csv"
    code = main(["simulate", "library.examples.constrained:Pendulum", "--stop-time", "0.5",
                 "--set", "x=0.2", "--set", "y=-0.8", "--init", "steady-state", "-o",
                 str(out)])
    assert code == 0
    rows = np.genfromtxt(out, delimiter=",", names=True)
    assert np.max(np.abs(rows["x"])) < 1e-9 and np.max(np.abs(rows["y"] + 1.0)) < 1e-9


def test_check_bond_graph_structural_beside_numeric(capsys):
    code = main(["check", "library.bondgraph.paper:DCMotorDrive"])
    assert code == 0
    text = capsys.readouterr().out
    assert "Structural vs numeric controllability/observability" in text
    assert "BGD rank [A B] 2/2" in text and "rank 3/3" in text
    code = main(["check", "library.bondgraph.paper:DCMotorDrive", "--json"])
    data = json.loads(capsys.readouterr().out)
    cmp = data["bond_graph"]["structural_vs_numeric"]
    assert cmp["controllability"]["structural"]["rank"] == 2
    assert cmp["controllability"]["numeric"]["rank"] == 3
