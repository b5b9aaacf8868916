"""The C test FMUs: valid for fmpy and fmutool, correct under fmpy (ME and CS), and run by
our master with the same results - every FMI 3.0 type, arrays, a resource file, time events
and a terminate request."""

from __future__ import annotations

import csv
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import simulate_fmu as fmpy_simulate
from fmpy.validation import validate_fmu
from scipy.linalg import expm

from bgmodelica.cosim.errors import ConnectorMismatchError, CosimStepError
from bgmodelica.cosim.fmu import read_fmu_info
from bgmodelica.cosim.master import Master
from bgmodelica.cosim.single import simulate_fmu
from bgmodelica.cosim.ssp import system_from_fmus
from bgmodelica.result import Result

A = np.array([0, 1, 0, -2, -0.5, 0, 0, 0, -3.0]).reshape(3, 3)
X0 = np.array([1.0, 0.0, 0.5])
INTERFACES = {"me": "ModelExchange", "cs": "CoSimulation"}


def _fmutool() -> str | None:
    exe = Path(sys.executable).with_name("fmutool")
    return str(exe) if exe.exists() else shutil.which("fmutool")


@pytest.mark.parametrize("name", ["Feedthrough", "StateSpace", "Resource", "Countdown",
                                  "Feedthrough2"])
def test_valid_for_fmpy_and_fmutool(c_fmus, name):
    assert validate_fmu(str(c_fmus[name])) == []
    tool = _fmutool()
    if tool is None:
        pytest.skip("fmutool (fmu-manipulation-toolbox) not installed")
    run = subprocess.run([tool, "-input", str(c_fmus[name]), "-check"], capture_output=True,
                         text=True, check=False)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "No semantic error" in run.stdout + run.stderr


def test_arrays_are_listed_as_elements(c_fmus):
    info = read_fmu_info(c_fmus["StateSpace"])
    assert info.n_states == 3
    assert [n for n in info.variables if n.startswith("A[")][:4] == ["A[1,1]", "A[1,2]",
                                                                      "A[1,3]", "A[2,1]"]
    a12 = info.variables["A[1,2]"]
    assert (a12.array_size, a12.element, a12.start) == (9, 1, 1.0)
    assert info.variables["u[3]"].causality == "input"
    assert info.variables["m"].fmi_type == "UInt64"


@pytest.mark.parametrize("interface", ["me", "cs"])
def test_state_space_against_the_matrix_exponential(c_fmus, interface):
    path = c_fmus["StateSpace"]
    ours = simulate_fmu(path, stop_time=2.0, interval=0.05, interface=interface, rtol=1e-10,
                        atol=1e-12)
    exact = np.array([expm(A * t) @ X0 for t in ours.time])
    ref = fmpy_simulate(str(path), fmi_type=INTERFACES[interface], stop_time=2.0,
                        output_interval=0.05, relative_tolerance=1e-10)
    for i in range(3):
        span = np.ptp(exact[:, i])
        assert np.max(np.abs(ours[f"y[{i + 1}]"] - exact[:, i])) < 1e-6 * span
        assert np.max(np.abs(ours[f"y[{i + 1}]"] - ref["y"][:, i])) < 1e-6 * span


def test_state_space_array_input_from_a_table(c_fmus):
    """u = (1, 0, 0) from t = 0: x(t) = e^{At} x0 + A^-1 (e^{At} - I) B u (B = I)."""
    u = np.array([1.0, 0.0, 0.0])
    res = simulate_fmu(c_fmus["StateSpace"], stop_time=1.0, interval=0.05, interface="me",
                       inputs={"u[1]": ([0.0, 1.0], [1.0, 1.0])}, rtol=1e-10, atol=1e-12)
    for k, t in enumerate(res.time):
        e = expm(A * t)
        x = e @ X0 + np.linalg.solve(A, (e - np.eye(3)) @ u)
        assert np.allclose([res[f"x[{i}]"][k] for i in (1, 2, 3)], x, atol=1e-8)
    assert np.all(res["u[1]"] == 1.0) and np.all(res["u[2]"] == 0.0)


@pytest.mark.parametrize("interface", ["me", "cs"])
def test_every_type_is_fed_through(c_fmus, interface):
    values = {"Float32_continuous_input": 0.1, "Float64_continuous_input": -2.5,
              "Float64_discrete_input": 7.25, "Int8_input": -128, "UInt8_input": 255,
              "Int16_input": -32768, "UInt16_input": 65535, "Int32_input": -2**31,
              "UInt32_input": 2**32 - 1, "Int64_input": -2**53, "UInt64_input": 2**53,
              "Boolean_input": True, "Enumeration_input": 2,
              "String_input": "héllo", "Binary_input": b"\x00\xffab",
              "Float64_tunable_parameter": 5.0}
    res = simulate_fmu(c_fmus["Feedthrough"], stop_time=0.2, interval=0.1,
                       interface=interface, parameters=values)
    for name, v in values.items():
        if name.endswith("_input") and not name.startswith(("String", "Binary")):
            out = name.replace("_input", "_output")
            expect = float(np.float32(v)) if name.startswith("Float32") else float(v)
            assert res[out][-1] == expect, out
    assert res["Float64_parameter_sum"][-1] == 6.0
    with pytest.raises(Exception, match=r"Int8_input: 200 is outside the Int8 range"):
        simulate_fmu(c_fmus["Feedthrough"], parameters={"Int8_input": 200})


def test_typed_connections_between_fmus(c_fmus):
    """Two Feedthrough FMUs in a chain: every numeric and Boolean output drives the other's
    input with its own type; a String cannot drive a Binary."""
    path = c_fmus["Feedthrough"]
    kinds = ["Float32_continuous", "Float64_continuous", "Float64_discrete", "Int8", "UInt8",
             "Int16", "UInt16", "Int32", "UInt32", "Int64", "UInt64", "Boolean", "Enumeration"]
    conns = [("a", f"{k}_output", "b", f"{k}_input") for k in kinds]
    system = system_from_fmus("chain", {"a": path, "b": path}, conns)
    given = {"Int8_input": -7, "UInt16_input": 40000, "Boolean_input": 1, "Enumeration_input": 2,
             "Int64_input": 2**40, "Float32_continuous_input": 1.5}
    for interface in ("cs", "me"):
        res = Master(system, interface=interface, allow_unconnected=True).simulate(
            0.3, 0.1, parameters={"a": given})
        for name, v in given.items():
            assert res[f"b.{name.replace('_input', '_output')}"][-1] == v
    bad = system_from_fmus("bad", {"a": path, "b": path},
                           [("a", "String_output", "b", "Binary_input")])
    with pytest.raises(ConnectorMismatchError, match="type mismatch, a.String_output is "
                                                     "String and b.Binary_input is Binary"):
        Master(bad, allow_unconnected=True)


@pytest.mark.parametrize("interface", ["me", "cs"])
def test_resource_file_is_read(c_fmus, interface, tmp_path):
    res = simulate_fmu(c_fmus["Resource"], interface=interface)
    assert np.all(res["y"] == ord("A"))
    assert fmpy_simulate(str(c_fmus["Resource"]), fmi_type=INTERFACES[interface])["y"][-1] == 65
    # the same FMU without its resource file: a clear error with the FMU's own message
    broken = tmp_path / "Resource.fmu"
    with zipfile.ZipFile(c_fmus["Resource"]) as src, zipfile.ZipFile(broken, "w") as dst:
        for item in src.infolist():
            if not item.filename.startswith("resources/"):
                dst.writestr(item, src.read(item))
    with pytest.raises(CosimStepError, match=r"cannot open the resource file .*y\.txt"):
        simulate_fmu(broken, interface=interface)


@pytest.mark.parametrize("interface", ["me", "cs"])
def test_terminate_request_ends_the_run(c_fmus, interface):
    res = simulate_fmu(c_fmus["Countdown"], stop_time=5.0, interval=0.25, interface=interface)
    assert res.time[-1] == pytest.approx(3.0)
    assert res.meta["terminated"]["time"] == pytest.approx(3.0)
    assert "terminate" in res.meta["terminated"]["reason"]
    steps = res.time < 3.0 - 1e-9
    assert np.array_equal(res["counter"][steps], 3 - np.floor(res.time[steps] + 1e-9))
    assert res["counter"][-1] == 0
    assert np.allclose(res["x"], res.time, atol=1e-9)


@pytest.mark.parametrize("interface", ["me", "cs"])
def test_fmi2_types_through_a_chain(c_fmus, interface):
    """FMI 2.0: a.Int32_input steps from 3 to 5 at t = 1 s (a discrete input: set in event
    mode under Model Exchange) and reaches b through Integer, Boolean, Enumeration and Real
    connections; String set by name."""
    path = c_fmus["Feedthrough2"]
    kinds = ["Float64_continuous", "Float64_discrete", "Int32", "Boolean", "Enumeration"]
    system = system_from_fmus("chain2", {"a": path, "b": path},
                              [("a", f"{k}_output", "b", f"{k}_input") for k in kinds])
    master = Master(system, interface=interface, allow_unconnected=True)
    assert master.infos["a"].variables["Int32_input"].fmi_type == "Integer"
    res = master.simulate(2.0, 0.1, parameters={"a": {"Boolean_input": True,
                                                       "Enumeration_input": 2,
                                                       "String_input": "hello"}},
                          inputs={"a.Int32_input": ([0, 1, 1, 2], [3, 3, 5, 5]),
                                  "a.Float64_continuous_input": ([0, 2], [0, 4])})
    t = res.time
    assert np.array_equal(res["b.Int32_output"], np.where(t < 1 - 1e-9, 3.0, 5.0))
    assert np.all(res["b.Boolean_output"] == 1.0) and np.all(res["b.Enumeration_output"] == 2)
    assert np.allclose(res["b.Float64_continuous_output"], 2 * t)
    assert res["a.Float64_parameter_sum"][-1] == 3.0
    # the declared dependencies make the outputs direct feedthrough: evaluated in order
    assert master.plan.feedthrough["a"]["Int32_output"] == ["Int32_input"]


def test_typed_values_in_an_ssp(c_fmus, tmp_path):
    """SSP round trip: Integer, Boolean and String bindings keep their types; typed
    connections run from the file."""
    from bgmodelica.cosim.ssp import write_ssp
    from bgmodelica.cosim.ssp_read import read_ssp

    path = c_fmus["Feedthrough"]
    system = system_from_fmus(
        "chain", {"a": path, "b": path},
        [("a", f"{k}_output", "b", f"{k}_input") for k in ("Int8", "Boolean", "UInt64")],
        parameters={"a": {"Int8_input": -3, "Boolean_input": 1, "String_input": "hey",
                          "UInt64_input": 2**40}})
    back = read_ssp(write_ssp(system, tmp_path / "chain.ssp"))
    bound = back.element("a").parameters
    assert bound == {"Int8_input": -3.0, "Boolean_input": 1.0, "String_input": "hey",
                     "UInt64_input": float(2**40)}
    res = Master(back, allow_unconnected=True).simulate(0.2, 0.1)
    assert res["b.Int8_output"][-1] == -3 and res["b.Boolean_output"][-1] == 1
    assert res["b.UInt64_output"][-1] == 2**40


@pytest.mark.parametrize("interface", ["me", "cs"])
def test_strings_and_binaries_through_a_chain(c_fmus, interface, tmp_path):
    """FMI 3.0: Countdown's String and Binary outputs change at its time events (t = 1, 2 s);
    the master records them and passes them to a Feedthrough, whose outputs follow at the same
    communication point; the CSV holds the text and the hex."""
    system = system_from_fmus("text", {"c": c_fmus["Countdown"], "f": c_fmus["Feedthrough"]},
                              [("c", "label", "f", "String_input"),
                               ("c", "code", "f", "Binary_input")])
    master = Master(system, interface=interface, allow_unconnected=True)
    assert master.plan.text_sources == {("f", "String_input"): ("c", "label"),
                                        ("f", "Binary_input"): ("c", "code")}
    res = master.simulate(2.5, 0.25)
    left = (3 - np.floor(res.time + 1e-9)).astype(int)
    assert list(left[[0, 4, 8, -1]]) == [3, 2, 1, 1]
    assert list(res["c.label"]) == [f"left {k}" for k in left]
    assert list(res["f.String_input"]) == list(res["c.label"])
    assert list(res["f.String_output"]) == [f"left {k}" for k in left]
    assert list(res["f.Binary_output"]) == [bytes([k, 0xA5]) for k in left]
    assert res["f.Int8_output"][-1] == 0                    # the numeric signals still run
    res.to_csv(tmp_path / "text.csv")
    with (tmp_path / "text.csv").open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert (rows[0]["f.String_output"], rows[0]["f.Binary_output"]) == ("left 3", "03a5")
    assert (rows[-1]["f.String_output"], rows[-1]["f.Binary_output"]) == ("left 1", "01a5")
    back = Result.read_csv(tmp_path / "text.csv")
    assert back["f.String_output"][5] == "left 2" and back["f.Binary_input"][0] == "03a5"
    assert np.array_equal(back["f.Int8_output"], res["f.Int8_output"])


@pytest.mark.parametrize("interface", ["me", "cs"])
def test_fmi2_strings_through_a_chain(c_fmus, interface):
    """FMI 2.0: a.Int32_input steps from 3 to 5 at t = 1 s; its decimal text (a String
    output) drives b.String_input (under Model Exchange set in event mode), which b feeds
    through; a String set by name reaches a.String_output."""
    path = c_fmus["Feedthrough2"]
    system = system_from_fmus("text2", {"a": path, "b": path},
                              [("a", "Int32_text", "b", "String_input")])
    res = Master(system, interface=interface, allow_unconnected=True).simulate(
        2.0, 0.25, parameters={"a": {"String_input": "héllo"}},
        inputs={"a.Int32_input": ([0, 1, 1, 2], [3, 3, 5, 5])},
        record=["b.Int32_text"])
    expect = ["3" if t < 1 - 1e-9 else "5" for t in res.time]
    assert list(res["a.Int32_text"]) == expect
    assert list(res["b.String_output"]) == expect
    assert set(res["a.String_output"]) == {"héllo"} and set(res["b.Int32_text"]) == {"0"}
    assert set(res["b.String_input"]) == {"3", "5"}


def test_single_fmu_through_the_cosim_command(c_fmus, tmp_path, capsys):
    """``bgmodelica cosim MODEL.fmu``: one FMU through the master, String and Binary
    variables set by name, recorded and written (text, hex)."""
    from bgmodelica.cli import main

    out = tmp_path / "feed.csv"
    assert main(["cosim", str(c_fmus["Feedthrough"]), "--step", "0.5", "--stop-time", "1",
                 "--set", "String_input=a, b", "--set", "Binary_input=00ff",
                 "--set", "Int8_input=-5", "--record", "Float64_parameter_sum",
                 "-o", str(out)]) == 0
    assert "Feedthrough: Co-Simulation, 3 points" in capsys.readouterr().out
    with out.open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["time"] for r in rows] == ["0", "0.5", "1"]
    assert {(r["String_output"], r["Binary_output"], r["Int8_output"]) for r in rows} == {
        ("a, b", "00ff", "-5")}
    assert rows[-1]["Float64_parameter_sum"] == "3"
    res = simulate_fmu(c_fmus["Countdown"], stop_time=1.5, interval=0.5, interface="me",
                       record=["label", "x"])
    assert list(res["label"]) == ["left 3", "left 3", "left 2", "left 2"]
    assert list(res["code"]) == [b"\x03\xa5", b"\x03\xa5", b"\x02\xa5", b"\x02\xa5"]


def test_model_exchange_with_forward_euler(c_fmus, tmp_path, capsys):
    """``euler_step``: Model Exchange by forward Euler at a fixed step, x_{k+1} = (I + hA) x_k
    exactly; the time events of Countdown still fall on their instants."""
    h = 0.01
    res = simulate_fmu(c_fmus["StateSpace"], stop_time=1.0, interval=0.1, interface="me",
                       euler_step=h)
    x, step = X0.copy(), np.eye(3) + h * A
    for k in range(len(res.time)):
        assert np.allclose([res[f"y[{i}]"][k] for i in (1, 2, 3)], x, rtol=1e-12, atol=1e-14)
        x = np.linalg.matrix_power(step, 10) @ x
    assert np.max(np.abs(res["y[3]"][-1] - (expm(A) @ X0)[2])) > 1e-3   # not the exact one
    down = simulate_fmu(c_fmus["Countdown"], stop_time=2.5, interval=0.5, interface="me",
                        euler_step=0.1)
    assert list(down["counter"]) == [3, 3, 2, 2, 1, 1]
    assert list(down["label"]) == ["left 3", "left 3", "left 2", "left 2", "left 1", "left 1"]
    from bgmodelica.cli import main

    assert main(["cosim", str(c_fmus["StateSpace"]), "--interface", "me", "--euler-step",
                 "0", "-o", str(tmp_path / "x.csv")]) == 2
    assert "me_euler_step must be > 0" in capsys.readouterr().err
