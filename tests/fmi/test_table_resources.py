"""Time tables read from files: natively at build time; in an exported FMU from its
resources folder when it is instantiated, so a new file changes the FMU's input."""

from __future__ import annotations

import functools
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.validation import validate_fmu

import bgmodelica as bg
from bgmodelica import Component, Output, der, time_table
from bgmodelica.errors import EquationError
from bgmodelica.fmi.from_model import export_model

PROFILE = "time,u,w\n0,0,1\n1,2,1\n1,-1,2\n2,0,2\n"


class TableLag(Component):
    """der(x) = u(t) - x with u from a CSV file (a ramp to 2, a jump to -1, a ramp to 0)."""

    x = Output(start=0.0, fixed=True)

    def __init__(self, file: str = "profile.csv", **kw):
        self.file = file
        super().__init__(**kw)

    def equations(self):
        yield der(self.x) == time_table(file=self.file, column="u") - self.x


def _exact_u_const(t: np.ndarray, u: float) -> np.ndarray:
    return u * (1 - np.exp(-t))


@functools.cache
def _build(base: str, version: int) -> Path:
    csv = Path(base) / "profile.csv"
    csv.write_text(PROFILE)
    return export_model(TableLag(str(csv)), Path(base) / f"v{version}", fmi_version=version,
                        fmu_type="both")


@pytest.fixture(scope="module")
def fmu(tmp_path_factory):
    base = str(tmp_path_factory.mktemp("tables"))
    return lambda version: _build(base, version)


def _with_resource(fmu: Path, out: Path, text: str | None) -> Path:
    """A copy of ``fmu`` whose table file says ``text`` (None: no file)."""
    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(out, "w") as dst:
        for item in src.infolist():
            if item.filename.startswith("resources/tables/"):
                if text is not None:
                    dst.writestr(item, text)
            else:
                dst.writestr(item, src.read(item))
    return out


@pytest.mark.parametrize("version", [2, 3])
def test_table_file_travels_in_the_resources(fmu, version):
    path = fmu(version)
    assert validate_fmu(str(path)) == []
    assert "resources/tables/0_profile.csv" in zipfile.ZipFile(path).namelist()
    nat = bg.simulate(TableLag(str(path.parent.parent / "profile.csv")), stop_time=2.0,
                      interval=0.1, rtol=1e-10, atol=1e-12)
    grid = np.isclose(nat.time / 0.1, np.round(nat.time / 0.1))
    keep = np.concatenate([[True], np.diff(nat.time) > 0])      # right limits at events
    for fmi_type in ("ModelExchange", "CoSimulation"):
        res = simulate_fmu(str(path), fmi_type=fmi_type, stop_time=2.0, output_interval=0.1,
                           relative_tolerance=1e-10, output=["x"])
        t = res["time"][np.isclose(res["time"] / 0.1, np.round(res["time"] / 0.1))]
        x = res["x"][np.isclose(res["time"] / 0.1, np.round(res["time"] / 0.1))]
        ref = np.interp(t, nat.time[grid & keep], nat["x"][grid & keep])
        assert np.max(np.abs(x - ref)) < 1e-6 * np.ptp(nat["x"]), fmi_type


@pytest.mark.parametrize("version", [2, 3])
def test_a_new_file_in_the_resources_is_used(fmu, version, tmp_path):
    """Two rows instead of four, u = 1: x = 1 - e^-t, without re-exporting."""
    path = _with_resource(fmu(version), tmp_path / "TableLag.fmu", "time,u\n0,1\n5,1\n")
    for fmi_type in ("ModelExchange", "CoSimulation"):
        res = simulate_fmu(str(path), fmi_type=fmi_type, stop_time=2.0, output_interval=0.1,
                           relative_tolerance=1e-10, output=["x"])
        assert np.max(np.abs(res["x"] - _exact_u_const(res["time"], 1.0))) < 1e-6


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("text, message", [
    (None, r"cannot open the resource file .*tables/0_profile\.csv"),
    ("time,v\n0,1\n", r"needs a first column 'time' and a column 'u'"),
    ("time,u\n0,1\n1,x\n", r"row 3: not two numbers"),
    ("time,u\n1,1\n0,1\n", r"row 3: time decreases"),
])
def test_bad_table_files_are_refused_with_the_file_named(fmu, version, text, message,
                                                         tmp_path):
    from bgmodelica.cosim import simulate_fmu as master_simulate
    from bgmodelica.cosim.errors import CosimError

    path = _with_resource(fmu(version), tmp_path / "TableLag.fmu", text)
    with pytest.raises(CosimError, match=message):
        master_simulate(path, stop_time=1.0, interval=0.1, interface="me")


def test_native_errors_name_the_file_and_column(tmp_path):
    csv = tmp_path / "p.csv"
    csv.write_text(PROFILE)
    with pytest.raises(EquationError, match=r"p\.csv has no column 'q' \(columns: u, w\)"):
        time_table(file=csv, column="q")
    with pytest.raises(EquationError, match=r"needs column=<name>"):
        time_table(file=csv)
    with pytest.raises(EquationError, match=r"does not exist"):
        time_table(file=tmp_path / "nope.csv", column="u")
    times, values = [0.0, 1.0], [0.0, 1.0]
    with pytest.raises(EquationError, match="either times and values or file="):
        time_table(times, values, file=csv, column="u")
    res = bg.simulate(TableLag(str(csv)), stop_time=2.0, interval=0.5, rtol=1e-10, atol=1e-12)
    # x(1) with u = 2t on [0, 1]: 2 (t - 1 + e^-t)
    assert res.final("x") != 0.0
    assert np.interp(1.0 - 1e-9, res.time, res["x"]) == pytest.approx(2 * np.exp(-1.0),
                                                                      abs=1e-6)


def test_library_time_table_block_carries_its_file(tmp_path):
    """library.blocks.TimeTable on a CSV whose first column is 'time' exports the file."""
    from bgmodelica import connect
    from library.blocks import FirstOrder, TimeTable

    csv = tmp_path / "profile.csv"
    csv.write_text(PROFILE)

    class Driven(Component):
        tab = TimeTable(str(csv), column="u")
        lag = FirstOrder(T=1.0)

        def equations(self):
            yield connect(self.tab.y, self.lag.u)

    path = export_model(Driven(), tmp_path / "out", fmi_version=3, fmu_type="me")
    assert "resources/tables/0_profile.csv" in zipfile.ZipFile(path).namelist()
    new = _with_resource(path, tmp_path / "Driven.fmu", "time,u\n0,1\n5,1\n")
    res = simulate_fmu(str(new), stop_time=2.0, output_interval=0.1,
                       relative_tolerance=1e-10, output=["lag.y"])
    assert np.max(np.abs(res["lag.y"] - _exact_u_const(res["time"], 1.0))) < 1e-6
