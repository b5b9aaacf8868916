"""Parameter estimation: DC motor from a noisy step response, the robot's motor resistances
from a PID run, non-identifiable sets refused, several experiments, CSV and the CLI."""

from __future__ import annotations

import json

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica.cli import main
from bgmodelica.studies import Experiment, IdentifiabilityError, fit
from bgmodelica.studies.fitting import FitError

TRUTH = {"resistor.R": 1.0, "emf.k": 0.1, "rotor.J": 0.002}
COLS = ["rotor.w", "inductor.i"]


def _noisy_step(compiled, seed=0, noise=0.01, params=None):
    """Speed and current of a simulated step response with `noise` x max|signal| Gaussian
    noise; returns the table and the noise levels."""
    truth = bg.simulate(compiled, 2.0, 0.01, params=params, outputs=COLS, rtol=1e-10,
                        atol=1e-12)
    rng = np.random.default_rng(seed)
    data, sigma = {"time": truth.time}, {}
    for c in COLS:
        sigma[c] = noise * float(np.max(np.abs(truth[c])))
        data[c] = truth[c] + sigma[c] * rng.standard_normal(len(truth.time))
    return data, sigma


def test_dc_motor_R_k_J_recovered_within_their_95_percent_intervals(dcmotor, tmp_path):
    """Acceptance: 1 % noise, known truth; R, k, J (rotor inertia; the load's is known)."""
    data, sigma = _noisy_step(dcmotor)
    res = fit(dcmotor, data, {"resistor.R": 1.5, "emf.k": 0.07, "rotor.J": 0.004},
              weights={c: 1 / s for c, s in sigma.items()})
    assert res.success and res.jacobian.startswith("forward sensitivities")
    assert res.rms == pytest.approx(1.0, abs=0.1)     # residuals at the noise level
    for name, true in TRUTH.items():
        lo, hi = res.ci95[name]
        assert lo < true < hi, (name, res.estimates[name], lo, hi)
        assert res.std_errors[name] < 0.02 * true
    assert res.units["resistor.R"] == "Ohm"
    report = res.to_dict()
    assert set(report["parameters"]) == set(TRUTH)
    assert report["parameters"]["emf.k"]["ci95"] == list(res.ci95["emf.k"])
    png = tmp_path / "residuals.png"
    res.plot_residuals(png)
    assert png.stat().st_size > 10000


def test_non_identifiable_set_refused(dcmotor):
    """rotor.J and load.J turn together: only their sum reaches the data."""
    data, _ = _noisy_step(dcmotor)
    with pytest.raises(IdentifiabilityError, match=r"3 free parameters has rank 2.*"
                                                   r"fix one of (rotor|load).J, (rotor|load).J"
                                                   ) as err:
        fit(dcmotor, data, ["resistor.R", "rotor.J", "load.J"])
    assert set(err.value.direction) == {"rotor.J", "load.J"}
    with pytest.raises(IdentifiabilityError, match="do not depend on fixed.phi0"):
        fit(dcmotor, data, ["resistor.R", "fixed.phi0"])


def test_robot_motor_resistances_from_a_pid_run(robot):
    """Acceptance: motor1.R and motor2.R from 5 s of the PID robot's joint angles, no
    noise, to 1e-3 relative."""
    cols = ["arm.joint1.q", "arm.joint2.q"]
    truth = bg.simulate(robot, 5.0, 0.02, outputs=cols, rtol=1e-10, atol=1e-12,
                        solver="cvodes")
    data = {"time": truth.time, **{c: truth[c] for c in cols}}
    res = fit(robot, data, {"motor1.R": 1.2, "motor2.R": 0.85})
    assert res.success
    for name in ("motor1.R", "motor2.R"):
        assert abs(res.estimates[name] - 1.0) < 1e-3, res.estimates


def test_two_experiments_and_csv_and_cli(dcmotor, tmp_path, capsys):
    """Two supply voltages (an experiment parameter), CSV files with a missing value, the
    ``bgmodelica fit`` command with --json."""
    files = []
    for k, volts in enumerate((12.0, 6.0)):
        data, _ = _noisy_step(dcmotor, seed=k, noise=0.002, params={"source.V": volts})
        data["rotor.w"][5] = np.nan                      # a missing sample
        path = tmp_path / f"step{k}.csv"
        rows = np.column_stack([data["time"], data["rotor.w"], data["inductor.i"]])
        lines = ["time,rotor.w,inductor.i"] + [
            ",".join("" if np.isnan(v) else f"{v:.12g}" for v in row) for row in rows]
        path.write_text("\n".join(lines) + "\n")
        files.append(path)
    exps = [Experiment(files[0], params={"source.V": 12.0}),
            Experiment(files[1], params={"source.V": 6.0})]
    res = fit(dcmotor, exps, {"resistor.R": 1.3, "emf.k": 0.08})
    assert res.n_data == 2 * 2 * 201 - 2
    for name in ("resistor.R", "emf.k"):
        assert abs(res.estimates[name] - TRUTH[name]) < 0.01 * TRUTH[name]
    code = main(["fit", "library.examples.motors:DCMotor", str(files[0]), "--free",
                 "resistor.R=1.3", "--free", "emf.k=0.08:0.01:1", "--json"])
    assert code == 0
    report = json.loads(capsys.readouterr().out)
    assert report["parameters"]["resistor.R"]["estimate"] == pytest.approx(1.0, rel=0.01)
    assert report["jacobian"].startswith("forward")
    assert main(["fit", "library.examples.motors:DCMotor", str(files[0]), "--free",
                 "rotor.J", "--free", "load.J"]) == 2
    assert "not identifiable" in capsys.readouterr().err


def test_bad_data_refused(dcmotor, tmp_path):
    with pytest.raises(FitError, match="not a variable.*did you mean"):
        fit(dcmotor, {"time": [0.0, 0.1, 0.2], "w": [0, 1, 2]}, ["emf.k"])
    with pytest.raises(FitError, match="strictly increasing"):
        fit(dcmotor, {"time": [0.0, 0.2, 0.1], "rotor.w": [0, 1, 2]}, ["emf.k"])
    with pytest.raises(FitError, match="both free and set"):
        fit(dcmotor, {"time": [0.0, 0.1, 0.2], "rotor.w": [0, 1, 2]}, ["emf.k"],
            params={"emf.k": 0.2})
    bad = tmp_path / "bad.csv"
    bad.write_text("t_sec,rotor.w\n0,0\n")
    with pytest.raises(FitError, match="first column must be 'time'"):
        fit(dcmotor, bad, ["emf.k"])


def test_model_with_events_fitted_with_labelled_finite_differences():
    from bgmodelica.studies.sweeps import on_grid
    from library.examples.hybrid import BouncingBall

    ball = bg.compile(BouncingBall())
    run = bg.simulate(ball, 1.5, 0.01, params={"e": 0.7}, outputs=["h"], rtol=1e-10,
                      atol=1e-12)
    grid = np.round(np.arange(151) * 0.01, 12)                     # as read from a CSV
    data = {"time": grid, "h": on_grid(run, ["h"], grid)[:, 0]}
    res = fit(ball, data, {"e": 0.6})
    assert res.jacobian == "central finite differences"
    assert res.estimates["e"] == pytest.approx(0.7, rel=1e-4)
