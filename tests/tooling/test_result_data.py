"""Results in the ecosystem: pandas, xarray, CSV with units (round trips), plots, reprs."""

from __future__ import annotations

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica import Result
from library.examples import DCMotor
from library.examples.hybrid import BouncingBall


@pytest.fixture(scope="module")
def motor() -> Result:
    return bg.simulate(DCMotor(), stop_time=0.5, interval=0.01)


@pytest.fixture(scope="module")
def ball() -> Result:
    return bg.simulate(BouncingBall(), stop_time=1.5, interval=0.05)


def test_to_pandas_round_trip_with_units(motor):
    pd = pytest.importorskip("pandas")
    df = motor.to_pandas()
    assert isinstance(df, pd.DataFrame)
    assert df.index.name == "time" and len(df) == len(motor.time)
    assert list(df.columns) == motor.all_names()
    assert df.attrs["units"]["inductor.i"] == "A"
    assert df.attrs["units"]["rotor.w"] == "rad/s"
    assert df.attrs["units"]["time"] == "s"
    assert df.attrs["parameters"]["source.V"] == 12.0
    assert df.attrs["parameter_units"]["source.V"] == "V"
    np.testing.assert_array_equal(df["inductor.i"].to_numpy(), motor["inductor.i"])
    back = Result.from_pandas(df)
    np.testing.assert_array_equal(back.time, motor.time)
    for name in ("inductor.i", "rotor.w", "resistor.v"):
        np.testing.assert_array_equal(back[name], motor[name])
        assert back.unit(name) == motor.unit(name)
    assert back.parameters["resistor.R"] == 1.0 and back.unit("resistor.R") == "Ohm"


def test_to_xarray_round_trip_with_units(motor):
    xr = pytest.importorskip("xarray")
    ds = motor.to_xarray()
    assert isinstance(ds, xr.Dataset)
    assert ds["time"].attrs["units"] == "s"
    assert ds["inductor.i"].attrs["units"] == "A"
    assert ds["source.V"].ndim == 0 and ds["source.V"].attrs["kind"] == "parameter"
    assert ds["source.V"].attrs["units"] == "V"
    back = Result.from_xarray(ds)
    np.testing.assert_array_equal(back["rotor.w"], motor["rotor.w"])
    assert back.unit("rotor.w") == "rad/s"
    assert back.parameters["source.V"] == 12.0
    sub = motor.to_xarray(["rotor.w"], parameters=False)
    assert list(sub.data_vars) == ["rotor.w"]


def test_events_keep_both_rows(ball):
    events = ball.meta["event_times"]
    assert len(events) >= 2
    df = ball.to_pandas(["h", "v"])
    assert not df.index.is_unique                   # left and right limit at each event
    at = df.loc[events[0]]
    assert len(at) == 2 and at["v"].iloc[0] < 0 < at["v"].iloc[1]
    assert df.attrs["event_times"] == pytest.approx(events)
    ds = ball.to_xarray(["h", "v"])
    assert ds.sizes["time"] == len(ball.time)
    assert ds.attrs["event_times"] == pytest.approx(events)
    back = Result.from_pandas(df)
    assert back.meta["event_times"] == pytest.approx(events)
    np.testing.assert_array_equal(back["v"], ball["v"])


def test_csv_with_units_row_round_trip(motor, ball, tmp_path):
    path = motor.to_csv(tmp_path / "m.csv", ["inductor.i", "rotor.w", "emf.k"], units=True)
    lines = path.read_text().splitlines()
    assert lines[0] == "time,inductor.i,rotor.w,emf.k"
    assert lines[1] == "s,A,rad/s,N.m/A"
    back = Result.read_csv(path)
    np.testing.assert_allclose(back["rotor.w"], motor["rotor.w"], rtol=1e-11)
    assert back.unit("rotor.w") == "rad/s" and back.unit("emf.k") == "N.m/A"
    plain = Result.read_csv(motor.to_csv(tmp_path / "p.csv", ["rotor.w"]))
    assert plain.unit("rotor.w") == "" and len(plain.time) == len(motor.time)
    hybrid = Result.read_csv(ball.to_csv(tmp_path / "b.csv", ["v"], units=True))
    np.testing.assert_allclose(hybrid["v"], ball["v"], rtol=1e-11, atol=1e-14)
    assert len(hybrid.time) == len(ball.time)          # event rows kept


def test_plot_groups_by_unit(motor, tmp_path):
    fig = motor.plot(["source.v", "resistor.v", "inductor.i", "rotor.phi"],
                     tmp_path / "mixed.png", title="DC motor")
    assert (tmp_path / "mixed.png").stat().st_size > 0
    axes = fig.axes
    assert len(axes) == 3                            # V, A, rad
    labels = [ax.get_ylabel() for ax in axes]
    assert labels == ["[V]", "inductor.i [A]", "rotor.phi [rad]"]
    assert axes[-1].get_xlabel() == "time [s]"
    assert len(axes[0].get_lines()) == 2
    assert axes[0].get_shared_x_axes().joined(axes[0], axes[2])


def test_plot_marks_events(ball, tmp_path):
    fig = ball.plot(["h", "v"], tmp_path / "ball.svg")
    assert len(fig.axes) == 2
    marks = [c for c in fig.axes[0].collections if c.get_label() == "event"]
    assert marks and len(marks[0].get_segments()) == len(ball.meta["event_times"])
    fig = ball.plot(["h"], tmp_path / "no_events.png", events=False, style=None)
    assert not fig.axes[0].collections


def test_notebook_views(motor, ball):
    html = motor._repr_html_()
    assert "<img" in html and "inductor.i" in html and "rad/s" in html
    assert "events" in ball._repr_html_()
    model = DCMotor()
    view = model._repr_html_()
    assert "resistor.R" in view and "Ohm" in view and "balanced" in view
    compiled = bg.compile(model)
    view = compiled._repr_html_()
    assert "structural index" in view and "inductor.i" in view


def test_bond_graph_view_has_the_drawing():
    from library.bondgraph.paper import DCMotor as BondGraphMotor

    view = BondGraphMotor()._repr_html_()
    assert "<svg" in view and "Bond graph" in view
