"""SSP 1.0 set-ups: writing, reading, schema validity, and readable errors."""

from __future__ import annotations

import zipfile

import pytest

from bgmodelica.cosim.errors import SspFormatError
from bgmodelica.cosim.ssp import SspConnection, ssd_xml, write_ssp
from bgmodelica.cosim.ssp_read import parse_ssd, read_ssp
from library.robots.subsystems import robot_connections, robot_parameters


def test_robot_ssp_contents(robot_setup, robot_ssp):
    s = robot_ssp
    assert s.name == "robot" and s.element_names == ["arm", "controller", "motor1", "motor2"]
    assert s.start_time == 0.0 and s.stop_time == 10.0
    assert s.master == {"step_size": 1e-3, "order": "gauss-seidel", "extrapolation": False}
    assert {(c.start_element, c.start_connector, c.end_element, c.end_connector)
            for c in s.connections} == set(robot_connections("lumped"))
    arm = s.element("arm")
    assert arm.source == "resources/Arm.fmu" and arm.fmu_path.is_file()
    assert {c.name: (c.kind, c.unit) for c in arm.connectors}["tau1"] == ("input", "N.m")
    assert arm.parameters == pytest.approx(robot_parameters()["arm"])
    assert s.element("motor1").fmu_path == s.element("motor2").fmu_path   # one FMU, 2 uses
    with zipfile.ZipFile(robot_setup["ssp"]) as zf:
        names = set(zf.namelist())
    assert names == {"SystemStructure.ssd", "resources/Arm.fmu", "resources/Motor.fmu",
                     "resources/Controller.fmu"}


def test_ssd_is_valid_ssp_1_0(robot_setup):
    """fmpy's SSP reader validates the SSD against the SSP 1.0 XML schema."""
    from fmpy.ssp.ssd import read_ssd

    for key in ("ssp", "ssp_plain"):
        ssd = read_ssd(str(robot_setup[key]), validate=True)
        assert [e.name for e in ssd.system.elements] == ["arm", "controller", "motor1",
                                                          "motor2"]
    assert len(read_ssd(str(robot_setup["ssp"])).system.connections) == 10


def test_roundtrip(robot_ssp, tmp_path):
    s = robot_ssp
    s.master["note"] = "x"
    try:
        again = read_ssp(write_ssp(s, tmp_path / "again.ssp"), tmp_path / "unpacked")
    finally:
        del s.master["note"]
    assert again.element_names == s.element_names
    assert again.connections == s.connections
    assert again.master["note"] == "x"
    for a, b in zip(again.elements, s.elements, strict=True):
        assert a.parameters == b.parameters and a.connectors == b.connectors
        assert a.fmu_path.read_bytes() == b.fmu_path.read_bytes()
    assert (tmp_path / "unpacked" / "resources" / "Arm.fmu").is_file()


def test_parameter_set_in_ssv_file_and_prefix(robot_ssp, tmp_path):
    """Parameter values may live in a .ssv resource; a binding prefix is stripped."""
    text = ssd_xml(robot_ssp).decode()
    start = text.index("<ssd:ParameterBindings>", text.index('name="controller"'))
    end = text.index("</ssd:ParameterBindings>", start) + len("</ssd:ParameterBindings>")
    binding = ('<ssd:ParameterBindings><ssd:ParameterBinding source="resources/c.ssv" '
               'prefix="controller."/></ssd:ParameterBindings>')
    ssv = ('<?xml version="1.0" encoding="UTF-8"?>\n<ssv:ParameterSet '
           'xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" '
           'version="1.0" name="c"><ssv:Parameters><ssv:Parameter name="controller.Kp1">'
           '<ssv:Real value="123.5"/></ssv:Parameter><ssv:Parameter name="controller.f1">'
           '<ssv:Integer value="2"/></ssv:Parameter></ssv:Parameters></ssv:ParameterSet>')
    path = tmp_path / "ssv.ssp"
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("SystemStructure.ssd", text[:start] + binding + text[end:])
        zf.writestr("resources/c.ssv", ssv)
        for comp in robot_ssp.elements:
            if comp.source not in zf.namelist():
                zf.write(comp.fmu_path, comp.source)
    s = read_ssp(path)
    assert s.element("controller").parameters == {"Kp1": 123.5, "f1": 2.0}


@pytest.mark.parametrize("mutate, message", [
    (lambda t: t.replace("ssd:SystemStructureDescription", "ssd:Foo"), "root element"),
    (lambda t: t.replace("</ssd:System>", "", 1), "well-formed"),
    (lambda t: t.replace('startElement="arm"', 'startelement="arm"', 1), "startElement"),
    (lambda t: t.replace('type="application/x-fmu-sharedlibrary"', 'type="text/plain"', 1),
     "not an FMU"),
    (lambda t: t.replace('<ssv:Real value="3.0"', '<ssv:Real value="three"', 1),
     "not a number"),
    (lambda t: t.replace("<ssd:Elements>", '<ssd:Elements><ssd:System name="sub"/>', 1),
     "nested system"),
])
def test_malformed_ssd(robot_ssp, mutate, message):
    with pytest.raises(SspFormatError, match=message):
        parse_ssd(mutate(ssd_xml(robot_ssp).decode()).encode(), zipfile.ZipFile(
            __import__("io").BytesIO(_empty_zip())))


def _empty_zip() -> bytes:
    import io

    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w"):
        pass
    return buf.getvalue()


def test_archive_errors(tmp_path, robot_ssp):
    with pytest.raises(SspFormatError, match="does not exist"):
        read_ssp(tmp_path / "none.ssp")
    (tmp_path / "bad.ssp").write_text("not a zip")
    with pytest.raises(SspFormatError, match="not a zip"):
        read_ssp(tmp_path / "bad.ssp")
    with zipfile.ZipFile(tmp_path / "nossd.ssp", "w") as zf:
        zf.writestr("other.txt", "x")
    with pytest.raises(SspFormatError, match="no SystemStructure.ssd"):
        read_ssp(tmp_path / "nossd.ssp")
    with zipfile.ZipFile(tmp_path / "nofmu.ssp", "w") as zf:
        zf.writestr("SystemStructure.ssd", ssd_xml(robot_ssp))
    with pytest.raises(SspFormatError, match="resources/Arm.fmu.*not in the archive"):
        read_ssp(tmp_path / "nofmu.ssp")


def test_connection_str():
    c = SspConnection("a", "y", "b", "u")
    assert str(c) == "a.y -> b.u" and c.start == "a.y" and c.end == "b.u"
