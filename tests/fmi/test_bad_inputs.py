"""Exported FMUs and bad values from the importer: declared ranges reach
``modelDescription.xml`` (FMI 2.0 and 3.0), the C runtime refuses out-of-range or NaN
parameter values and ``doStep`` past the stop time given at set-up, with an error status and
a logged message naming the variable -- checked through fmpy's low-level ``FMU2Slave`` /
``FMU3Slave`` -- and the export refuses defaults outside their own ranges."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
import zipfile

import pytest
from fmi_harness import FMICallException, open_fmu
from fmi_models import VERSIONS

from bgmodelica import Component, Input, Output, Parameter, Variable, der
from bgmodelica.fmi import FmuSpecError


class Tank(Component):
    """A der(h) = u - k h; outputs the level h and the outflow q = k h."""

    A = Parameter(2.0, unit="m2", description="Cross section", min=0.5, max=10.0)
    k = Parameter(0.3, unit="m2/s", description="Outflow coefficient", min=0.0)
    u = Input(unit="m3/s", description="Inflow", min=-5.0, max=5.0)
    h = Variable(start=1.0, fixed=True, unit="m", min=0.0, max=100.0)
    level = Output(unit="m", description="Level", min=0.0)
    q = Output(unit="m3/s", description="Outflow")

    def equations(self):
        yield self.A * der(self.h) == self.u - self.k * self.h
        yield self.level == 2.0 * self.h / 2.0
        yield self.q == self.k * self.h


@pytest.fixture(scope="module")
def tank(tmp_path_factory):
    """``tank[version]``: the Tank model exported as a Co-Simulation FMU."""
    from bgmodelica.fmi.from_model import export_model

    out = tmp_path_factory.mktemp("tank_fmus")
    return {v: export_model(Tank(name="Tank"), out / f"fmi{v}", fmi_version=v, fmu_type="cs")
            for v in VERSIONS}


def _raises_error(call, *args, **kw) -> None:
    with pytest.raises(FMICallException) as info:
        call(*args, **kw)
    assert info.value.status == 3  # fmi2Error / fmi3Error


@pytest.mark.parametrize("version", VERSIONS)
def test_ranges_in_model_description(tank, version):
    with zipfile.ZipFile(tank[version]) as zf:
        root = ET.fromstring(zf.read("modelDescription.xml"))
    if version == 2:
        attrs = {sv.get("name"): sv.find("Real").attrib for sv in root.iter("ScalarVariable")}
    else:
        attrs = {v.get("name"): v.attrib for v in root.iter("Float64")}

    def rng(name):
        a = attrs[name]
        return (float(a["min"]) if "min" in a else None, float(a["max"]) if "max" in a else None)

    assert rng("A") == (0.5, 10.0)          # parameter, both bounds
    assert rng("k") == (0.0, None)          # parameter, min only
    assert rng("u") == (-5.0, 5.0)          # input
    assert rng("h") == (0.0, 100.0)         # state
    assert rng("level") == (0.0, None)      # output
    assert rng("q") == (None, None)         # nothing declared: nothing written
    assert rng("der(h)") == (None, None)
    # fmpy reads them the same way (and its validation accepts the document)
    from fmpy import read_model_description
    from fmpy.validation import validate_fmu

    md = {v.name: v for v in read_model_description(str(tank[version])).modelVariables}
    assert (md["A"].min, md["A"].max) == ("0.5", "10.0")
    assert validate_fmu(str(tank[version])) == []


@pytest.mark.parametrize("version", VERSIONS)
def test_out_of_range_parameters_are_rejected(tank, version):
    setter = "fmi2SetReal" if version == 2 else "fmi3SetFloat64"
    o = open_fmu(tank[version], "cs")
    try:
        _raises_error(o.set, {"A": 20.0})
        _raises_error(o.set, {"A": 0.25})
        _raises_error(o.set, {"k": -1e-300})
        _raises_error(o.set, {"A": math.nan})
        _raises_error(o.set, {"A": -math.inf})
        _raises_error(o.set, {"u": 6.0})
        _raises_error(o.set, {"h": -1.0})
        _raises_error(o.set, {"solver.tolerance": 1.0})
        errors = o.errors()
        assert f"{setter}: value 20 for A is outside its range [0.5, 10] (min, max); the " \
               "value is not set" in errors
        assert f"{setter}: value 0.25 for A is outside its range [0.5, 10] (min, max); the " \
               "value is not set" in errors
        assert any("for k is outside its range [0, inf]" in m for m in errors), errors
        assert any(m.startswith(f"{setter}: value nan for A is not finite") for m in errors)
        assert any(m.startswith(f"{setter}: value -inf for A is not finite") for m in errors)
        assert any("for u is outside its range [-5, 5]" in m for m in errors)
        assert any("for h is outside its range [0, 100]" in m for m in errors)
        assert o.get(["A", "k", "u", "h"]) == [2.0, 0.3, 0.0, 1.0]   # nothing was set
        o.set({"A": 10.0, "k": 0.0})                                  # the bounds are fine
        o.set({"A": 0.5})
        # tunable: refused out of range in Step Mode too, accepted inside
        o.initialize()
        n = len(o.errors())
        _raises_error(o.set, {"A": 11.0})
        assert "value 11 for A is outside its range" in o.errors()[n]
        o.set({"A": 4.0})
        o.fmu.doStep(0.0, 0.1)
        assert o.get(["A"]) == [4.0]
    finally:
        o.close()


def _setup(o, version, start, stop):
    if version == 2:
        o.fmu.setupExperiment(startTime=start, stopTime=stop)
        o.fmu.enterInitializationMode()
    else:
        o.fmu.enterInitializationMode(startTime=start, stopTime=stop)
    o.fmu.exitInitializationMode()


@pytest.mark.parametrize("version", VERSIONS)
def test_do_step_past_stop_time(tank, version):
    do_step = "fmi2DoStep" if version == 2 else "fmi3DoStep"
    o = open_fmu(tank[version], "cs")
    try:
        _setup(o, version, 0.0, 0.1)
        o.fmu.doStep(0.0, 0.05)
        o.fmu.doStep(0.05, 0.05)                   # ends exactly at the stop time
        level = o.get(["level"])
        _raises_error(o.fmu.doStep, 0.1, 1e-6)
        msg = o.errors()[-1]
        assert msg.startswith(f"{do_step}: the step from t=0.10000000000000001 by "
                              "9.9999999999999995e-07 ends at 0.10000100000000001, past the "
                              "stop time 0.10000000000000001 given at initialization "
                              "(stopTimeDefined); the step is not taken"), msg
        assert o.get(["time"]) == [pytest.approx(0.1)]      # nothing happened
        assert o.get(["level"]) == level
        o.fmu.doStep(0.1, 0.0)                               # a zero step is fine
    finally:
        o.close()
    # steps t_k = k h may overshoot by rounding; a start time other than 0 counts too
    o = open_fmu(tank[version], "cs")
    try:
        _setup(o, version, 1.0, 1.3)
        for k in range(3):
            o.fmu.doStep(1.0 + k * 0.1, 0.1)
        assert o.get(["time"])[0] == pytest.approx(1.3)
        _raises_error(o.fmu.doStep, o.get(["time"])[0], 0.1)
    finally:
        o.close()
    # without stopTimeDefined, steps beyond the DefaultExperiment stop time are fine
    o = open_fmu(tank[version], "cs")
    try:
        o.initialize()
        o.fmu.doStep(0.0, 5.0)
        assert o.get(["time"]) == [pytest.approx(5.0)] and not o.errors()
    finally:
        o.close()


@pytest.mark.parametrize("version", VERSIONS)
def test_master_reports_the_fmu_message(tank, tmp_path, version):
    """Through the co-simulation master, the FMU's own message ends in the one-line error."""
    from bgmodelica.cosim.errors import CosimStepError
    from bgmodelica.cosim.master import Master
    from bgmodelica.cosim.ssp import system_from_fmus

    system = system_from_fmus("tanks", {"t1": tank[version], "t2": tank[version]},
                              [("t1", "q", "t2", "u"), ("t2", "q", "t1", "u")],
                              parameters={"t2": {"k": 6.0}})
    with pytest.raises(CosimStepError) as err:
        Master(system).simulate(0.1, 0.01)
    msg = str(err.value)
    setter = "fmi2SetReal" if version == 2 else "fmi3SetFloat64"
    assert f"{setter}: value 6 for u is outside its range [-5, 5]" in msg and "\n" not in msg
    assert "element 't1'" in msg


def test_export_refuses_defaults_outside_their_range(tmp_path):
    from bgmodelica.fmi.from_model import export_model

    with pytest.raises(FmuSpecError, match=r"parameter 'A': start 20.0 outside \[0.5, 10.0\]"):
        export_model(Tank(name="Tank", A=20.0), tmp_path)
    with pytest.raises(FmuSpecError, match=r"state 'h': its consistent initial value -1 is "
                                           r"outside its declared range \[0, 100\]"):
        export_model(Tank(name="Tank", h=-1.0), tmp_path)

    class Bad(Tank):
        A = Parameter(2.0, unit="m2", min=5.0, max=1.0)
    with pytest.raises(FmuSpecError, match=r"parameter 'A': min 5 > max 1"):
        export_model(Bad(name="Bad"), tmp_path)
    assert not list(tmp_path.iterdir())                      # nothing written
