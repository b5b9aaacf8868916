"""Bad co-simulation set-ups and options: each refused before an FMU runs, with one typed
error naming the element, connector or parameter; and the same through the command line
(exit status 2, one line on stderr, no traceback, nothing written)."""

from __future__ import annotations

import copy
import math
import tempfile
import zipfile
from pathlib import Path

import pytest

from bgmodelica import Component, Input, Output, Parameter, Variable, cli, der
from bgmodelica.cosim.checks import check_parameter_value
from bgmodelica.cosim.cli import register
from bgmodelica.cosim.errors import (
    ConnectorMismatchError,
    CosimStepError,
    DuplicateElementError,
    InvalidExperimentError,
    InvalidParameterError,
    SetupError,
    SspFormatError,
    UnknownConnectorError,
)
from bgmodelica.cosim.fmu import FmuInfo, FmuVariable
from bgmodelica.cosim.master import Master, count_steps
from bgmodelica.cosim.ssp import (
    SspConnection,
    SspConnector,
    system_from_fmus,
    write_ssp,
)
from bgmodelica.cosim.ssp_read import read_ssp
from bgmodelica.errors import ModelError, ParameterError


class Tank(Component):
    """A der(h) = u - k h; outputs the level h and the outflow q = k h."""

    A = Parameter(2.0, unit="m2", description="Cross section", min=0.5, max=10.0)
    k = Parameter(0.3, unit="m2/s", description="Outflow coefficient", min=0.0)
    u = Input(unit="m3/s", description="Inflow", min=-5.0, max=5.0)
    h = Variable(start=1.0, fixed=True, unit="m", min=0.0)
    level = Output(unit="m", description="Level")
    q = Output(unit="m3/s", description="Outflow")

    def equations(self):
        yield self.A * der(self.h) == self.u - self.k * self.h
        yield self.level == self.h
        yield self.q == self.k * self.h


LOOP = [("tank1", "q", "tank2", "u"), ("tank2", "q", "tank1", "u")]


@pytest.fixture(scope="module")
def tank_fmu(tmp_path_factory):
    from bgmodelica.fmi.from_model import export_model

    return export_model(Tank(name="Tank"), tmp_path_factory.mktemp("tank"), fmi_version=2,
                        fmu_type="both")


@pytest.fixture
def tanks(tank_fmu):
    """Two tanks draining into each other (no algebraic loop: q depends on the state)."""
    return system_from_fmus("tanks", {"tank1": tank_fmu, "tank2": tank_fmu}, LOOP,
                            parameters={"tank1": {"A": 3.0}}, stop_time=1.0,
                            master={"step_size": 0.01})


def ssp_with(system, tmp_path: Path, edit=lambda t: t, name: str = "s.ssp") -> Path:
    """The SSP of ``system`` with its SSD text passed through ``edit``."""
    path = write_ssp(copy.deepcopy(system), tmp_path / name)
    with zipfile.ZipFile(path) as zf:
        members = {n: zf.read(n) for n in zf.namelist()}
    members["SystemStructure.ssd"] = edit(members["SystemStructure.ssd"].decode()).encode()
    with zipfile.ZipFile(path, "w") as zf:
        for n, data in members.items():
            zf.writestr(n, data)
    return path


def test_good_setup_runs(tanks, tmp_path):
    res = Master(read_ssp(write_ssp(tanks, tmp_path / "t.ssp"))).simulate(0.1, 0.01)
    assert len(res.time) == 11 and res.parameters["tank1.A"] == 3.0
    assert all(math.isfinite(x) for x in res["tank1.level"])


def test_duplicate_names(tanks, tmp_path):
    def twice(t: str) -> str:
        return t.replace('name="tank2"', 'name="tank1"', 1)
    with pytest.raises(DuplicateElementError, match="two components are named 'tank1'"):
        read_ssp(ssp_with(tanks, tmp_path, twice))
    dup = copy.deepcopy(tanks)
    dup.elements[1].name = "tank1"
    with pytest.raises(DuplicateElementError, match=r"element name\(s\) used twice: tank1"):
        Master(dup)
    with pytest.raises(DuplicateElementError, match="tank1"):
        write_ssp(dup, tmp_path / "dup.ssp")
    assert not (tmp_path / "dup.ssp").exists() and not (tmp_path / "dup.ssp.part").exists()

    def connector_twice(t: str) -> str:
        i = t.index('<ssd:Connector name="u"')
        j = t.index("</ssd:Connector>", i) + len("</ssd:Connector>")
        return t[:j] + t[i:j] + t[j:]
    with pytest.raises(DuplicateElementError, match="component 'tank1' declares the "
                                                    "connector 'u' twice"):
        read_ssp(ssp_with(tanks, tmp_path, connector_twice))
    twin = copy.deepcopy(tanks)
    twin.elements[0].connectors.append(twin.elements[0].connectors[0])
    with pytest.raises(DuplicateElementError, match=r"element 'tank1' declares the "
                                                    r"connector\(s\) u twice"):
        Master(twin)

    def parameter_twice(t: str) -> str:
        i = t.index('<ssv:Parameter name="A"')
        j = t.index("</ssv:Parameter>", i) + len("</ssv:Parameter>")
        return t[:j] + t[i:j].replace("3.0", "4.0") + t[j:]
    with pytest.raises(DuplicateElementError, match="component 'tank1'.*parameter 'A' is "
                                                    "given twice"):
        read_ssp(ssp_with(tanks, tmp_path, parameter_twice))


def test_unit_mismatches(tanks, tmp_path):
    bad = copy.deepcopy(tanks)
    bad.connections[0] = SspConnection("tank1", "level", "tank2", "u")
    with pytest.raises(ConnectorMismatchError, match=r"tank1\.level -> tank2\.u: unit "
                                                     r"mismatch, tank1\.level is in 'm' and "
                                                     r"tank2\.u in 'm3/s'"):
        Master(bad)
    bad = copy.deepcopy(tanks)
    bad.elements[0].connectors = [SspConnector(c.name, c.kind, c.type,
                                               "mm" if c.name == "level" else c.unit)
                                  for c in bad.elements[0].connectors]
    with pytest.raises(ConnectorMismatchError, match=r"tank1\.level has unit 'mm' in the "
                                                     r"SSD but 'm'"):
        Master(bad)
    # a parameter value given in another unit than the FMU's
    path = ssp_with(tanks, tmp_path, lambda t: t.replace('value="3.0" unit="m2"',
                                                         'value="3.0" unit="cm2"'))
    system = read_ssp(path)
    assert system.element("tank1").parameter_units == {"A": "cm2"}
    with pytest.raises(ConnectorMismatchError, match=r"parameter binding tank1\.A is given "
                                                     r"in 'cm2' but A is in 'm2'"):
        Master(system)
    # the unit survives a write/read round trip
    again = read_ssp(write_ssp(system, tmp_path / "again.ssp"))
    assert again.element("tank1").parameter_units == {"A": "cm2"}


def test_connection_into_a_parameter(tanks):
    bad = copy.deepcopy(tanks)
    bad.connections.append(SspConnection("tank1", "level", "tank2", "A"))
    with pytest.raises(ConnectorMismatchError, match=r"tank2\.A is a parameter, not an input "
                                                     r"\(a connection cannot drive a "
                                                     r"parameter"):
        Master(bad)
    bad = copy.deepcopy(tanks)
    bad.connections.append(SspConnection("tank1", "A", "tank2", "u"))
    with pytest.raises(ConnectorMismatchError, match=r"tank1\.A is a parameter, not an "
                                                     r"output"):
        Master(bad)


@pytest.mark.parametrize("name, value, message", [
    ("A", 50.0, r"tank1\.A = 50 is outside the range \[0\.5, 10\] declared in Tank\.fmu"),
    ("A", 0.1, r"tank1\.A = 0\.1 is outside the range \[0\.5, 10\]"),
    ("k", -1.0, r"tank1\.k = -1 is outside the range \[0, inf\]"),
    ("u", 9.0, r"tank1\.u = 9 is outside the range \[-5, 5\]"),
    ("A", math.nan, r"tank1\.A: the value nan is not finite"),
    ("A", math.inf, r"tank1\.A: the value inf is not finite"),
    ("A", "abc", r"tank1\.A: 'abc' is not a number"),
    ("level", 1.0, r"tank1\.level: it is a continuous output Real of Tank\.fmu, not a "
                   "parameter that can be set"),
    ("h", 1.0, r"tank1\.h: it is a continuous local Real"),
    ("time", 1.0, r"tank1\.time: it is a continuous independent Real"),
])
def test_bad_parameter_values(tanks, name, value, message):
    binding = copy.deepcopy(tanks)
    binding.elements[0].parameters[name] = value
    with pytest.raises(InvalidParameterError, match="parameter binding " + message):
        Master(binding)
    master = Master(tanks)
    with pytest.raises(InvalidParameterError, match="parameter override " + message):
        master.simulate(0.1, 0.01, parameters={"tank1": {name: value}})


def test_boundaries_and_inputs_are_accepted(tanks):
    master = Master(tanks)
    res = master.simulate(0.02, 0.01, parameters={"tank1": {"A": 10.0, "k": 0.0},
                                                  "tank2": {"A": 0.5}})
    assert res.parameters["tank1.A"] == 10.0 and res.parameters["tank2.A"] == 0.5


def test_constant_and_calculated_parameters_are_not_settable(tmp_path):
    def var(causality, variability):
        return FmuVariable("p", 1, causality, variability, "Real", "", 1.0, "", 0.0, 2.0)
    for causality, variability in (("parameter", "constant"), ("calculatedParameter", "fixed"),
                                   ("structuralParameter", "tunable")):
        info = FmuInfo(tmp_path / "X.fmu", "X", 2, "", {"p": var(causality, variability)}, {})
        with pytest.raises(InvalidParameterError, match=f"it is a {variability} {causality}"):
            check_parameter_value("x", info, "p", 1.0)
    info = FmuInfo(tmp_path / "X.fmu", "X", 2, "", {"p": var("parameter", "fixed")}, {})
    assert check_parameter_value("x", info, "p", "1.5") == 1.5
    info.variables["p"].type = "Integer"          # typed parameters are set as such
    assert check_parameter_value("x", info, "p", 1) == 1.0
    with pytest.raises(InvalidParameterError, match="1.5 is not an integer"):
        check_parameter_value("x", info, "p", 1.5)
    info.variables["p"].type = info.variables["p"].fmi_type = "UInt8"
    with pytest.raises(InvalidParameterError, match=r"outside the UInt8 range \[0, 255\]"):
        check_parameter_value("x", info, "p", -1)


@pytest.mark.parametrize("kw, message", [
    (dict(stop_time=math.nan), "stop time nan is not finite"),
    (dict(stop_time=math.inf), "stop time inf is not finite"),
    (dict(stop_time=-1.0), "stop time -1 must be after the start time 0"),
    (dict(stop_time=1e300), r"the horizon 1e\+300 s at macro step 0.01 s needs 1e\+302 macro "
                            r"steps, more than the limit of 1e\+08"),
    (dict(step=1e-300), r"needs 1e\+300 macro steps"),
    (dict(step=5e-320), r"needs inf macro steps"),
    (dict(step=math.nan), "macro step nan is not finite"),
    (dict(step=0.0), "macro step must be > 0, got 0"),
    (dict(step=-0.01), "macro step must be > 0, got -0.01"),
    (dict(step=0.3), "not a multiple of the macro step"),
    (dict(step="x"), "macro step 'x' is not a number"),
    (dict(start_time=math.inf), "start time inf is not finite"),
    (dict(tolerance=math.nan), "tolerance nan is not finite"),
    (dict(tolerance=-1.0), "tolerance must be > 0"),
    (dict(max_abs=math.nan), "max_abs must be > 0"),
    (dict(record_every=0), "record_every must be a positive integer"),
    (dict(record_every=1.5), "record_every must be a positive integer"),
    (dict(max_steps=10), r"needs 100 macro steps, more than the limit of 10"),
])
def test_bad_times_and_steps(tanks, kw, message):
    kw = {"stop_time": 1.0, "step": 0.01, **kw}
    with pytest.raises(InvalidExperimentError, match=message) as err:
        Master(tanks).simulate(**kw)
    assert "\n" not in str(err.value)


def test_count_steps_and_recording_limit(tanks, monkeypatch):
    assert count_steps(0.0, 10.0, 1e-3) == 10_000
    assert count_steps(0.0, 0.3, 0.1) == 3
    import bgmodelica.cosim.master as master_mod

    monkeypatch.setattr(master_mod, "MAX_RECORD_BYTES", 10_000)
    with pytest.raises(InvalidExperimentError,
                       match=r"recording 1001 communication points of 6 variables needs "
                             r"54\.7 KiB, more than 9\.8 KiB: record fewer points "
                             r"\(record_every\)"):
        Master(tanks).simulate(1.0, 1e-3)
    res = Master(tanks).simulate(1.0, 1e-3, record_every=250)
    assert list(res.time) == pytest.approx([0.0, 0.25, 0.5, 0.75, 1.0])
    res = Master(tanks).simulate(0.05, 0.01, record_every=3)
    assert list(res.time) == pytest.approx([0.0, 0.03, 0.05])


def test_bad_experiment_in_the_ssd(tanks, tmp_path):
    for old, new, message in (
            ('stopTime="1.0"', 'stopTime="INF"', "stopTime: 'INF' is not finite"),
            ('stopTime="1.0"', 'stopTime="NaN"', "stopTime: 'NaN' is not finite"),
            ('stopTime="1.0"', 'stopTime="-2.0"', "stopTime -2.0 is not after startTime"),
            ('startTime="0.0"', 'startTime="1e400"', "startTime: '1e400' is not finite"),
            ('stepSize="0.01"', 'stepSize="fast"', "stepSize: 'fast' is not a number"),
            ('value="3.0"', 'value="nan"', "parameter A: 'nan' is not finite"),
    ):
        with pytest.raises(SspFormatError, match=message):
            read_ssp(ssp_with(tanks, tmp_path, lambda t, o=old, n=new: t.replace(o, n, 1)))
    # absurd but well-formed: refused by the master with the number of steps
    system = read_ssp(ssp_with(tanks, tmp_path, lambda t: t.replace('stopTime="1.0"',
                                                                    'stopTime="1e15"', 1)))
    with pytest.raises(InvalidExperimentError, match=r"needs 1e\+17 macro steps"):
        Master(system).simulate()


def test_unknown_names(tanks):
    bad = copy.deepcopy(tanks)
    bad.connections.append(SspConnection("tank1", "nope", "tank2", "u"))
    with pytest.raises(UnknownConnectorError, match=r"tank1\.nope does not exist \(Tank\.fmu "
                                                    r"has inputs/outputs u, q, level\)"):
        Master(bad)
    bad = copy.deepcopy(tanks)
    bad.connections.append(SspConnection("tank3", "q", "tank2", "u"))
    with pytest.raises(UnknownConnectorError, match="no element 'tank3'"):
        Master(bad)
    bad = copy.deepcopy(tanks)
    bad.elements[0].connectors.append(SspConnector("volume", "output"))
    with pytest.raises(UnknownConnectorError, match=r"connector tank1\.volume of the SSD does "
                                                    r"not exist in Tank\.fmu"):
        Master(bad)
    bad = copy.deepcopy(tanks)
    bad.elements[0].parameters["area"] = 1.0
    with pytest.raises(UnknownConnectorError, match=r"parameter binding tank1\.area: Tank\.fmu "
                                                    r"has no variable 'area'"):
        Master(bad)
    master = Master(tanks)
    with pytest.raises(UnknownConnectorError, match="unknown element 'tank9'"):
        master.simulate(0.1, 0.01, parameters={"tank9": {"A": 1.0}})
    with pytest.raises(UnknownConnectorError, match="has no variable 'area'"):
        master.simulate(0.1, 0.01, parameters={"tank1": {"area": 1.0}})
    with pytest.raises(UnknownConnectorError, match="has no variable 'volume'"):
        master.simulate(0.1, 0.01, record=["tank1.volume"])
    with pytest.raises(UnknownConnectorError, match="'tank1' is not <element>.<variable>"):
        master.simulate(0.1, 0.01, record=["tank1"])
    with pytest.raises(UnknownConnectorError, match=r"unknown element\(s\) tank7"):
        Master(tanks, interface={"tank7": "me"})
    with pytest.raises(SetupError, match="sequence"):
        master.simulate(0.1, 0.01, order="gauss-seidel", sequence=["tank1", "tank1"])
    with pytest.raises(SetupError, match="order must be"):
        master.simulate(0.1, 0.01, order=3)
    empty = copy.deepcopy(tanks)
    empty.elements, empty.connections = [], []
    with pytest.raises(SetupError, match="has no elements"):
        Master(empty)


def test_fmu_error_message_reaches_the_exception(tanks):
    """tank2 drains 6 m3/s into tank1, whose input accepts [-5, 5]: the FMU refuses the
    value and its own message (naming the input and range) ends up in the error."""
    master = Master(tanks)
    with pytest.raises(CosimStepError) as err:
        master.simulate(0.1, 0.01, parameters={"tank2": {"k": 6.0}})
    msg = str(err.value)
    assert "element 'tank1' (Tank.fmu)" in msg and "fmi2SetReal" in msg
    assert "value 6 for u is outside its range [-5, 5]" in msg and "\n" not in msg


# -- the command line ---------------------------------------------------------------------

@pytest.fixture
def main(monkeypatch, tmp_path):
    monkeypatch.setattr(cli, "_EXTENSIONS", [register])
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    return cli.main


def one_error_line(capsys, kind: str) -> str:
    cap = capsys.readouterr()
    lines = cap.err.strip().splitlines()
    assert len(lines) == 1, cap.err
    assert lines[0].startswith(f"error: {kind}: "), lines[0]
    assert "Traceback" not in cap.err + cap.out
    return lines[0]


#: an absolute member name: must never be written
ABS_TARGET = Path(tempfile.gettempdir()) / "bgm_evil_abs.txt"


def test_cli_malicious_ssp(main, tmp_path, capsys):
    evil = tmp_path / "evil.ssp"
    with zipfile.ZipFile(evil, "w") as zf:
        zf.writestr("SystemStructure.ssd", "<x/>")
        zf.writestr("../../evil.txt", "pwned")
        zf.writestr(str(ABS_TARGET), "pwned")
    before = {p for p in tmp_path.parent.rglob("*")}
    assert main(["cosim", str(evil), "-o", str(tmp_path / "out.csv")]) == 2
    line = one_error_line(capsys, "UnsafeArchiveError")
    assert "'../../evil.txt'" in line and str(evil) in line
    assert {p for p in tmp_path.parent.rglob("*")} == before
    assert not ABS_TARGET.exists()


def test_cli_malicious_nested_fmu_and_sources(main, tanks, tmp_path, capsys):
    evil_fmu = tmp_path / "Evil.fmu"
    with zipfile.ZipFile(evil_fmu, "w") as zf:
        zf.writestr("modelDescription.xml", "<fmiModelDescription/>")
        zf.writestr("../evil.txt", "pwned")
    nested = copy.deepcopy(tanks)
    nested.elements[1].fmu_path = evil_fmu
    path = write_ssp(nested, tmp_path / "nested.ssp")
    assert main(["cosim", str(path), "--stop-time", "0.1"]) == 2
    assert "Evil.fmu: member '../evil.txt' has a '..' component" in one_error_line(
        capsys, "UnsafeArchiveError")
    src = ssp_with(tanks, tmp_path, lambda t: t.replace('source="resources/Tank.fmu"',
                                                        'source="../Tank.fmu"', 1))
    assert main(["cosim", str(src)]) == 2
    assert "refers to '../Tank.fmu'" in one_error_line(capsys, "UnsafeArchiveError")
    assert not (tmp_path / "evil.txt").exists() and not list((tmp_path / "work").iterdir())


def test_cli_broken_archives(main, tanks, tmp_path, capsys):
    good = write_ssp(tanks, tmp_path / "good.ssp")
    cut = tmp_path / "cut.ssp"
    cut.write_bytes(good.read_bytes()[:1000])
    assert main(["cosim", str(cut)]) == 2
    assert "truncated or corrupt" in one_error_line(capsys, "SspFormatError")
    plain = tmp_path / "plain.ssp"
    with zipfile.ZipFile(plain, "w") as zf:
        zf.writestr("notes.txt", "hello")
    assert main(["cosim", str(plain)]) == 2
    assert "no SystemStructure.ssd" in one_error_line(capsys, "SspFormatError")


@pytest.mark.parametrize("args, kind, message", [
    (["--stop-time", "nan"], "InvalidExperimentError", "--stop-time must be a finite number"),
    (["--stop-time", "inf"], "InvalidExperimentError", "--stop-time must be a finite number"),
    (["--step", "-1"], "InvalidExperimentError", "--step must be a finite number > 0"),
    (["--stop-time", "1e300"], "InvalidExperimentError", "needs 1e+302 macro steps"),
    (["--set", "tank1.A=50"], "InvalidParameterError", "tank1.A = 50 is outside the range"),
    (["--set", "tank1.A=nan"], "ParameterError", "'nan' is not finite"),
    (["--set", "tank1.level=1"], "InvalidParameterError", "not a parameter that can be set"),
    (["--set", "tank3.A=1"], "UnknownConnectorError", "unknown element 'tank3'"),
    (["--record", "tank1.nope"], "UnknownConnectorError", "no variable 'nope'"),
    (["-o", "missing/dir/out.csv"], "CosimError", "the folder missing/dir does not exist"),
    (["--plot", "missing/p.png"], "CosimError", "the folder missing does not exist"),
    (["--plot-vars", "tank1.nope", "--plot", "p.png"], "CosimError", "tank1.nope"),
])
def test_cli_bad_options(main, tanks, tmp_path, capsys, args, kind, message):
    path = write_ssp(tanks, tmp_path / "t.ssp")
    assert main(["cosim", str(path), "-o", "out.csv", "--step", "0.01", *args]) == 2
    assert message in one_error_line(capsys, kind)
    assert not list((tmp_path / "work").iterdir())           # no (partial) output


def test_cli_output_name_from_the_ssd_stays_here(main, tanks, tmp_path, capsys):
    """A system named ``../../x`` does not steer the default output file elsewhere."""
    bad_name = copy.deepcopy(tanks)
    bad_name.name = "../../escape"
    path = write_ssp(bad_name, tmp_path / "n.ssp")
    assert main(["cosim", str(path), "--stop-time", "0.05", "--step", "0.01"]) == 0
    assert [p.name for p in (tmp_path / "work").iterdir()] == ["_.._escape_cosim.csv"]
    assert not (tmp_path.parent / "escape_cosim.csv").exists()
    capsys.readouterr()


@pytest.mark.parametrize("args, kind, message", [
    (["--steps", "nan"], "ParameterError", "finite positive macro steps required"),
    (["--step", "1e-3,-1"], "ParameterError", "finite positive macro steps required"),
    (["--stop-time", "inf"], "InvalidExperimentError", "stop time inf is not finite"),
    (["--stop-time", "1e12", "--steps", "1e-3"], "InvalidExperimentError",
     "needs 1e+15 macro steps"),
    (["--stop-time", "1", "--steps", "3e-3"], "InvalidExperimentError", "not a multiple"),
    (["--tolerance", "nan"], "ParameterError", "--tolerance must be a finite number"),
])
def test_cli_verify_bad_options(main, tanks, monkeypatch, tmp_path, capsys, args, kind,
                                message):
    """``verify MODEL SSP``: refused before anything is compiled or simulated."""
    import bgmodelica

    def no_compile(*a, **k):
        raise AssertionError("nothing must be compiled for bad options")
    monkeypatch.setattr(bgmodelica, "compile", no_compile)
    path = write_ssp(tanks, tmp_path / "t.ssp")
    assert main(["verify", "library.examples.hybrid:PWMMotor", str(path), "--quiet",
                 *args]) == 2
    assert message in one_error_line(capsys, kind)


def test_error_types():
    for cls in (DuplicateElementError, InvalidParameterError, InvalidExperimentError):
        assert issubclass(cls, SetupError) and issubclass(cls, ModelError)
    assert issubclass(ParameterError, ModelError)
