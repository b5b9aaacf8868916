"""Result files by extension: .csv, .parquet and .nc written and read back with units,
parameters and event instants, from the API and from ``bgmodelica simulate -o``."""

from __future__ import annotations

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica import Result
from bgmodelica.cli import main
from library.examples import DCMotor
from library.examples.hybrid import BouncingBall

pytest.importorskip("pyarrow")


@pytest.fixture(scope="module")
def motor() -> Result:
    return bg.simulate(DCMotor(), stop_time=0.5, interval=0.01)


@pytest.fixture(scope="module")
def ball() -> Result:
    return bg.simulate(BouncingBall(), stop_time=1.5, interval=0.05)


@pytest.mark.parametrize("ext", ["parquet", "nc", "csv"])
def test_round_trip_by_extension(tmp_path, motor, ext):
    path = motor.save(tmp_path / f"motor.{ext}", units=True)
    back = Result.read(path)
    rtol = 1e-11 if ext == "csv" else 0.0          # CSV: 12 significant digits; else exact
    np.testing.assert_allclose(back.time, motor.time, rtol=rtol)
    for name in ("inductor.i", "rotor.w", "resistor.v"):
        np.testing.assert_allclose(back[name], motor[name], rtol=rtol, atol=1e-300)
        assert back.unit(name) == motor.unit(name)
    assert back.names == motor.all_names()
    if ext != "csv":                               # CSV holds no parameters or model name
        assert back.parameters == motor.parameters
        assert back.unit("source.V") == "V"
        assert back.meta["model"] == "DCMotor"


@pytest.mark.parametrize("ext", ["parquet", "nc"])
def test_events_survive(tmp_path, ball, ext):
    back = Result.read(ball.save(tmp_path / f"ball.{ext}"))
    assert back.meta["event_times"] == pytest.approx(ball.meta["event_times"])
    np.testing.assert_array_equal(back.time, ball.time)     # two rows at each event


def test_named_methods(tmp_path, motor):
    some = ["rotor.w", "inductor.i"]
    pq = Result.read_parquet(motor.to_parquet(tmp_path / "m.parquet", some))
    nc = Result.read_netcdf(motor.to_netcdf(tmp_path / "m.nc", some))
    for back in (pq, nc):
        assert back.names == some
        np.testing.assert_array_equal(back["rotor.w"], motor["rotor.w"])


def test_progress_reaches_one(tmp_path, motor):
    for ext in ("csv", "parquet", "nc"):
        seen: list[float] = []
        motor.save(tmp_path / f"p.{ext}", progress=seen.append)
        assert seen and seen[-1] == 1.0 and seen == sorted(seen), (ext, seen)


def test_cli_writes_by_extension(tmp_path, capsys):
    out = tmp_path / "rc.parquet"
    assert main(["simulate", "library.examples:RC", "--stop-time", "1", "-o", str(out),
                 "--progress"]) == 0
    err = capsys.readouterr().err
    assert "writing" in err and "100.0%" in err
    back = Result.read(out)
    assert back["capacitor.v"][-1] == pytest.approx(10 * (1 - np.exp(-1)), rel=1e-4)
    out = tmp_path / "rc.nc"
    assert main(["simulate", "library.examples:RC", "-o", str(out), "--no-progress"]) == 0
    assert "writing" not in capsys.readouterr().err
    assert Result.read(out).unit("capacitor.v") == "V"


def test_cli_refuses_a_format_it_does_not_write(tmp_path, capsys):
    out = tmp_path / "rc.mat"
    assert main(["simulate", "library.examples:RC", "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "rc.mat" in err and ".parquet" in err
    assert not out.exists()
