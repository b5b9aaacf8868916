"""Misuse of the FMUs returns an error status with a log message, never a crash."""

from __future__ import annotations

import ctypes
import math

import numpy as np
import pytest
from fmi_harness import FMICallException, open_fmu
from fmi_models import VERSIONS


def _raises_error(call, *args) -> None:
    with pytest.raises(FMICallException) as info:
        call(*args)
    assert info.value.status == 3  # fmi2Error / fmi3Error


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("kind", ["me", "cs"])
def test_wrong_instantiation_token(build_fmu, version, kind):
    o = open_fmu(build_fmu("osc", version, kind), kind, token="{00000000-0000-0000-0000-0}",
                 instantiate=False)
    try:
        with pytest.raises(Exception, match="Failed to instantiate"):
            o.instantiate()
        assert any("GUID" in m or "instantiationToken" in m for m in o.errors()), o.messages
    finally:
        o.fmu.freeLibrary()


@pytest.mark.parametrize("version", VERSIONS)
def test_interface_not_provided(build_fmu, version):
    """A ME-only binary refuses to be instantiated for Co-Simulation."""
    path = build_fmu("osc", version, "me")
    o = open_fmu(path, "cs", instantiate=False)
    try:
        with pytest.raises(Exception, match="Failed to instantiate"):
            o.instantiate()
        assert o.errors()
    finally:
        o.fmu.freeLibrary()


@pytest.mark.parametrize("version", VERSIONS)
def test_do_step_before_initialization(build_fmu, version):
    o = open_fmu(build_fmu("osc", version, "cs"), "cs")
    try:
        _raises_error(o.fmu.doStep, 0.0, 0.1)
        assert any("not allowed in Instantiated" in m for m in o.errors()), o.messages
        # the instance is still usable afterwards
        o.initialize()
        o.fmu.doStep(0.0, 0.1)
        # a communication point that does not match the FMU time
        _raises_error(o.fmu.doStep, 5.0, 0.1)
        _raises_error(o.fmu.doStep, 0.1, -1.0)
        o.fmu.doStep(0.1, 0.1)
        assert o.get(["time"])[0] == pytest.approx(0.2)
    finally:
        o.close()


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("kind", ["me", "cs"])
def test_nan_and_out_of_range_values(build_fmu, version, kind):
    o = open_fmu(build_fmu("osc", version, kind), kind)
    try:
        _raises_error(o.set, {"damper.d": math.nan})
        _raises_error(o.set, {"force": math.inf})
        _raises_error(o.set, {"mass.m": -1.0})           # min = 0
        _raises_error(o.set, {"mass.s": math.nan})
        errors = "\n".join(o.errors())
        assert "not finite" in errors and "outside its range" in errors
        # failed calls change nothing
        assert o.get(["damper.d", "mass.m"]) == [0.4, 1.0]
        # an atomic multi-set: one bad value, nothing is set
        _raises_error(o.set, {"spring.c": 2.0, "damper.d": math.nan})
        assert o.get(["spring.c"]) == [4.0]
        o.initialize()
        _raises_error(o.set, {"force": math.nan})
    finally:
        o.close()


@pytest.mark.parametrize("version", VERSIONS)
def test_unknown_and_read_only_variables(build_fmu, version):
    o = open_fmu(build_fmu("osc", version, "me"), "me")
    try:
        fmu = o.fmu
        getter = fmu.getReal if version == 2 else fmu.getFloat64
        _raises_error(getter, [999])
        _raises_error(o.set, {"pos": 1.0})               # output
        _raises_error(o.set, {"der(mass.v)": 1.0})       # derivative
        _raises_error(o.set, {"time": 1.0})
        if version == 2:
            _raises_error(fmu.getInteger, [1])
            _raises_error(fmu.setBoolean, [1], [True])
            assert fmu.getInteger([]) == []
        else:
            _raises_error(fmu.getInt32, [1])
            _raises_error(fmu.setBoolean, [1], [True])
            assert list(fmu.getInt64([])) == []
        assert any("unknown value reference 999" in m for m in o.errors())
    finally:
        o.close()


@pytest.mark.parametrize("version", VERSIONS)
def test_me_mode_rules(build_fmu, version):
    o = open_fmu(build_fmu("osc", version, "me"), "me")
    try:
        fmu = o.fmu
        _raises_error(fmu.enterContinuousTimeMode)       # before initialization
        o.initialize()
        fmu.enterContinuousTimeMode()
        # tunable parameters: Event Mode only, not Continuous-Time Mode
        _raises_error(o.set, {"spring.c": 5.0})
        o.set({"force": 1.0})                            # inputs are fine
        # states with initial="exact" can only be set before initialization via SetReal
        _raises_error(o.set, {"mass.s": 0.1})
        x = (ctypes.c_double * 3)()
        _raises_error(fmu.getContinuousStates, x, 3)     # wrong size
        fmu.enterEventMode()
        o.set({"spring.c": 5.0})
        assert o.get(["spring.f"]) == pytest.approx([5.0])
        assert any("Continuous-Time Mode" in m for m in o.errors())
    finally:
        o.close()


@pytest.mark.parametrize("version", VERSIONS)
def test_model_evaluation_nan_is_an_error(build_fmu, version):
    """mass.m = 0 is in range but makes der(mass.v) infinite."""
    o = open_fmu(build_fmu("osc", version, "cs"), "cs")
    try:
        o.initialize(values={"mass.m": 0.0}, exit_init=False)
        _raises_error(o.fmu.exitInitializationMode)
        assert any("der(mass.v)" in m for m in o.errors()), o.messages
    finally:
        o.close()


@pytest.mark.parametrize("version", VERSIONS)
def test_wrong_interface_function_and_null_instance(build_fmu, version):
    """ME functions called on a CS instance, and calls with a NULL instance."""
    o = open_fmu(build_fmu("osc", version, "cs"), "cs")
    try:
        o.initialize()
        dll = ctypes.CDLL(o.fmu.dll._name)  # own function objects (fmpy sets argtypes on its)
        set_time = getattr(dll, f"fmi{version}SetTime")
        set_time.argtypes = [ctypes.c_void_p, ctypes.c_double]
        set_time.restype = ctypes.c_int
        assert set_time(o.fmu.component, 1.0) == 3
        assert any("Model Exchange" in m for m in o.errors())
        assert set_time(None, 1.0) == 3
        free = getattr(dll, f"fmi{version}FreeInstance")
        free.argtypes = [ctypes.c_void_p]
        free(None)
        if version == 3:
            inst = dll.fmi3InstantiateScheduledExecution
            inst.restype = ctypes.c_void_p
            assert inst(b"x", o.md.guid.encode(), None, 0, 0, None, None, None, None,
                        None) is None
    finally:
        o.close()


@pytest.mark.parametrize("version", VERSIONS)
def test_debug_logging_categories(build_fmu, version):
    o = open_fmu(build_fmu("motor", version, "cs"), "cs")
    try:
        o.fmu.setDebugLogging(True, ["logSolver"])
        _raises_error(o.fmu.setDebugLogging, True, ["noSuchCategory"])
        o.initialize()
        o.fmu.doStep(0.0, 1e-3)
        o.fmu.terminate()
        info = [m for s, c, m in o.messages if c == "logSolver"]
        assert any("solver statistics" in m for m in info), o.messages
    finally:
        o.close()


@pytest.mark.parametrize("version", VERSIONS)
def test_fmu_state_roundtrip(build_fmu, version):
    o = open_fmu(build_fmu("motor", version, "cs"), "cs")
    try:
        fmu = o.fmu
        o.initialize()
        for k in range(5):
            fmu.doStep(k * 1e-3, 1e-3)
        get_state = fmu.getFMUstate if version == 2 else fmu.getFMUState
        set_state = fmu.setFMUstate if version == 2 else fmu.setFMUState
        free_state = fmu.freeFMUstate if version == 2 else fmu.freeFMUState
        serialize = fmu.serializeFMUstate if version == 2 else fmu.serializeFMUState
        deserialize = fmu.deSerializeFMUstate if version == 2 else fmu.deserializeFMUState
        state = get_state()
        blob = serialize(state)
        t0 = o.get(["time"])[0]
        for k in range(5):
            fmu.doStep(t0 + k * 1e-3, 1e-3)
        first = o.get(["speed", "current", "time"])
        set_state(state)
        assert o.get(["time"])[0] == t0
        for k in range(5):
            fmu.doStep(t0 + k * 1e-3, 1e-3)
        assert o.get(["speed", "current", "time"]) == first
        restored = deserialize(blob)
        set_state(restored)
        assert o.get(["time"])[0] == t0
        free_state(restored)
        free_state(state)
        # a corrupted serialized state is rejected
        _raises_error(deserialize, b"\x00" * len(blob))
    finally:
        o.close()


@pytest.mark.parametrize("version", VERSIONS)
def test_reset_restores_start_values(build_fmu, version):
    o = open_fmu(build_fmu("loop", version, "cs"), "cs")
    try:
        o.initialize(values={"cap.v0": 3.0})
        o.fmu.doStep(0.0, 0.1)
        o.fmu.reset()
        assert o.get(["cap.v0"]) == [1.0]
        o.initialize()
        assert o.get(["cap.v"]) == [1.0]
        o.fmu.doStep(0.0, 0.1)
        assert np.isfinite(o.get(["res.i"])[0])
    finally:
        o.close()
