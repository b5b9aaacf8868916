"""Sweeps and Monte Carlo: a real Dask cluster of separate processes, failures recorded,
reproducible sampling, outputs (netCDF, Zarr, Parquet, band plot), FMUs, model shipping."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica.cli import main
from bgmodelica.errors import ModelError, OptionError, ParameterError
from bgmodelica.studies import sweep
from bgmodelica.studies.design import parse_distribution, parse_grid
from bgmodelica.studies.payload import _CACHE, STATS, payload_for

xr = pytest.importorskip("xarray")

RC_GRID = np.linspace(100.0, 1000.0, 20)


def test_sweep_through_scheduler_and_two_worker_processes(dask_cluster, rc, tmp_path):
    """Acceptance: a 20-point RC sweep via `--scheduler tcp://...` and two `dask worker`
    processes equals 20 single simulate runs to 1e-12."""
    nc, pq, zr = tmp_path / "rc.nc", tmp_path / "rc.parquet", tmp_path / "rc.zarr"
    code = main(["sweep", "library.examples.circuits:RC", "--grid", "resistor.R=100:1000:20",
                 "--stop-time", "5", "--interval", "0.01", "--outputs", "capacitor.v",
                 "resistor.i", "--scheduler", dask_cluster, "--workers", "2",
                 "--batch-size", "1", "-o", str(nc), "-o", str(pq), "-o", str(zr),
                 "--no-progress"])
    assert code == 0
    ds = xr.open_dataset(nc)
    assert ds.sizes == {"run": 20, "time": 501}
    np.testing.assert_array_equal(ds["resistor.R"].values, RC_GRID)
    assert ds["capacitor.v"].attrs["units"] == "V" and ds["time"].attrs["units"] == "s"
    assert ds["resistor.R"].attrs["units"] == "Ohm"
    assert list(ds["status"].values) == ["ok"] * 20
    assert ds.attrs["scheduler"] == dask_cluster and ds.attrs["workers"] == 2
    assert len(set(ds["worker"].values)) == 2          # both worker processes ran some
    worst = 0.0
    for k, R in enumerate(RC_GRID):
        single = bg.simulate(rc, stop_time=5.0, interval=0.01, params={"resistor.R": R},
                             outputs=["capacitor.v", "resistor.i"])
        np.testing.assert_array_equal(single.time, ds["time"].values)
        for name in ("capacitor.v", "resistor.i"):
            worst = max(worst, float(np.max(np.abs(single[name] - ds[name].values[k]))))
    assert worst <= 1e-12
    import pandas as pd

    summary = pd.read_parquet(pq)
    assert len(summary) == 20 and "capacitor.v:final" in summary.columns
    np.testing.assert_allclose(summary["capacitor.v:final"], ds["capacitor.v"].values[:, -1])
    z = xr.open_zarr(zr)
    np.testing.assert_array_equal(z["capacitor.v"].values, ds["capacitor.v"].values)
    ds.close()


def test_failed_runs_are_recorded_not_lost(rc):
    res = sweep(rc, grid={"resistor.R": [1000.0, -1e-3, 500.0]}, outputs=["capacitor.v"],
                stop_time=5.0, interval=0.01, scheduler="serial", progress=False,
                max_steps=2000)
    status = list(res["status"].values)
    assert status[0] == "ok" and status[2] == "ok" and status[1] == "failed"
    fail = res.failures()
    assert len(fail) == 1 and fail[0]["run"] == 1
    assert fail[0]["parameters"] == {"resistor.R": -1e-3}
    assert fail[0]["error"]                     # the solver's complaint, on one line
    assert np.isfinite(res["capacitor.v"].values[[0, 2]]).all()
    assert res.meta["n_failed"] == 1
    ok = bg.simulate(rc, 5.0, 0.01, params={"resistor.R": 500.0}, outputs=["capacitor.v"])
    np.testing.assert_array_equal(res["capacitor.v"].values[2], ok["capacitor.v"])


def test_monte_carlo_reproducible_bands_and_summary(robot, tmp_path):
    kw = dict(samples=6, distributions={"m1": "+-5%", "motor1.R": "normal(1, 0.02)"},
              seed=7, outputs=["arm.joint1.q", "e1"], stop_time=1.0, interval=0.01,
              scheduler="serial", progress=False, solver="cvodes")
    a, b = sweep(robot, **kw), sweep(robot, **kw)
    np.testing.assert_array_equal(a["m1"].values, b["m1"].values)
    np.testing.assert_array_equal(a["arm.joint1.q"].values, b["arm.joint1.q"].values)
    m1 = a["m1"].values
    assert np.all((m1 >= 3.0 * 0.95) & (m1 <= 3.0 * 1.05)) and len(set(m1)) == 6
    c = sweep(robot, **{**kw, "seed": 8})
    assert not np.array_equal(a["m1"].values, c["m1"].values)
    lhs = sweep(robot, **{**kw, "sampling": "lhs"})
    bins = np.floor((lhs["m1"].values - 2.85) / 0.3 * 6).astype(int)
    assert sorted(bins) == list(range(6))                   # one draw per stratum
    assert a["arm.joint1.q"].attrs["units"] == "rad"
    s = a.summary()
    assert list(s.columns[:3]) == ["run", "m1", "motor1.R"]
    np.testing.assert_allclose(s["e1:max"], np.nanmax(a["e1"].values, axis=1))
    png = tmp_path / "band.png"
    a.plot_band("arm.joint1.q", png)
    assert png.stat().st_size > 5000
    a.save(tmp_path / "mc.csv")
    assert (tmp_path / "mc.csv").read_text().startswith("run,m1,motor1.R,status")


def test_grid_product_and_fixed_params(rc):
    res = sweep(rc, grid={"resistor.R": "500,1000", "capacitor.C": "1e-3:4e-3:2"},
                params={"source.V": 5.0}, outputs=["capacitor.v"], stop_time=1.0,
                interval=0.5, scheduler="serial", progress=False)
    assert res.dataset.sizes["run"] == 4
    np.testing.assert_array_equal(res["resistor.R"].values, [500, 500, 1000, 1000])
    np.testing.assert_array_equal(res["capacitor.C"].values, [1e-3, 4e-3, 1e-3, 4e-3])
    tau = res["resistor.R"].values * res["capacitor.C"].values
    np.testing.assert_allclose(res["capacitor.v"].values[:, -1], 5.0 * (1 - np.exp(-1 / tau)),
                               rtol=1e-5)


def test_bad_sweeps_refused_before_running(rc):
    kw = dict(stop_time=1.0, scheduler="serial", progress=False)
    with pytest.raises(ParameterError, match="did you mean resistor.R"):
        sweep(rc, grid={"R": [1, 2]}, **kw)
    with pytest.raises(ParameterError, match="unknown output"):
        sweep(rc, grid={"resistor.R": [1, 2]}, outputs=["nope"], **kw)
    with pytest.raises(OptionError, match="nothing to sweep"):
        sweep(rc, **kw)
    with pytest.raises(OptionError, match="number of samples"):
        sweep(rc, distributions={"resistor.R": "+-5%"}, **kw)
    with pytest.raises(OptionError, match="scheduler"):
        sweep(rc, grid={"resistor.R": [1, 2]}, stop_time=1.0, scheduler="nowhere")
    with pytest.raises(OptionError):
        parse_grid("x", "1:2")
    with pytest.raises(OptionError, match="positive ends"):
        parse_grid("x", "0:10:3:log")
    np.testing.assert_allclose(parse_grid("x", "1:100:3:log"), [1, 10, 100])
    with pytest.raises(OptionError, match="unknown distribution"):
        parse_distribution("x", "gauss(1,2)", lambda: 1.0)
    with pytest.raises(OptionError, match="low <= high"):
        parse_distribution("x", "uniform(2,1)", lambda: 1.0)
    d = parse_distribution("x", "+-10%", lambda: 2.0)
    assert d.ppf(0.0) == pytest.approx(1.8) and d.ppf(1.0) == pytest.approx(2.2)
    assert main(["sweep", "library.examples.circuits:RC", "--n", "3"]) == 2


def test_model_travels_pickled_or_as_reference(rc, monkeypatch):
    """The compiled model is pickled once (CasADi graphs included) and unpickled once per
    worker; with ship='reference' a worker compiles the model once and caches it."""
    pay = payload_for(rc)
    assert pay.kind == "compiled" and pay.size < 100_000
    remote = pickle.loads(pickle.dumps(pay))      # what a worker receives
    assert remote._local is None
    _CACHE.pop(pay.token, None)
    model, _lock = remote.get()
    assert STATS[pay.token]["how"] == "unpickled"
    assert remote.get()[0] is model                 # cached: unpickled once
    r1 = bg.simulate(model, 2.0, 0.1, params={"resistor.R": 300.0})
    r2 = bg.simulate(rc, 2.0, 0.1, params={"resistor.R": 300.0})
    np.testing.assert_array_equal(r1.values, r2.values)
    ref = payload_for(rc, ref="library.examples.circuits:RC", mode="reference")
    assert ref.kind == "reference" and ref.blob is None
    remote = pickle.loads(pickle.dumps(ref))
    _CACHE.pop(ref.token, None)
    model, _lock = remote.get()
    assert STATS[ref.token]["how"] == "compiled on the worker"
    assert remote.get()[0] is model

    def refuse(_compiled):
        raise TypeError("cannot serialize this CasADi object")

    monkeypatch.setattr("bgmodelica.studies.payload.pickle_compiled", refuse)
    with pytest.raises(ModelError, match="cannot be pickled"):
        payload_for(rc)
    fallback = payload_for(rc, ref="library.examples.circuits:RC")     # auto: the reference
    assert fallback.kind == "reference"


def test_sweep_of_an_exported_fmu(rc, tmp_path):
    pytest.importorskip("fmpy")
    from bgmodelica.fmi import FmuExportError
    from bgmodelica.fmi.from_model import export_model

    try:
        fmu = export_model(rc, tmp_path, fmi_version=2, fmu_type="cs", stop_time=5.0)
    except FmuExportError as err:                   # no C compiler here
        pytest.skip(str(err))
    res = sweep(str(fmu), grid={"resistor.R": [500.0, 2000.0]}, outputs=["capacitor.v"],
                stop_time=5.0, interval=0.05, scheduler="serial", progress=False)
    assert res.dataset.attrs["kind"] == "fmu" and list(res["status"].values) == ["ok"] * 2
    assert res["capacitor.v"].attrs["units"] == "V"
    for k, R in enumerate([500.0, 2000.0]):
        ref = bg.simulate(rc, 5.0, 0.05, params={"resistor.R": R}, outputs=["capacitor.v"])
        np.testing.assert_allclose(res["capacitor.v"].values[k], ref["capacitor.v"],
                                   atol=1e-4)
    with pytest.raises(ParameterError, match="not a variable of the FMU"):
        sweep(str(fmu), grid={"nope": [1.0]}, stop_time=1.0, scheduler="serial",
              progress=False)


def test_sweep_of_a_model_with_events_samples_the_grid():
    """Event rows (left and right limits) are not on the common time axis: each run is
    sampled at the output times, the right limit at an event on the grid."""
    from library.examples.hybrid import BouncingBall

    ball = bg.compile(BouncingBall())
    res = sweep(ball, grid={"e": [0.5, 0.8]}, outputs=["h", "v"], stop_time=2.0,
                interval=0.01, scheduler="serial", progress=False)
    assert list(res["status"].values) == ["ok", "ok"]
    for k, e in enumerate((0.5, 0.8)):
        single = bg.simulate(ball, 2.0, 0.01, params={"e": e}, outputs=["h", "v"])
        assert len(single.time) > len(res["time"])           # event rows in the single run
        last = np.searchsorted(single.time, res["time"].values, side="right") - 1
        np.testing.assert_array_equal(res["h"].values[k], single["h"][last])
