"""The master's flat loop (:mod:`bgmodelica.cosim.flat_loop`), in Jacobi and Gauss-Seidel
order, gives the general loop's results to the last bit, and stands aside where it does not
apply."""

from __future__ import annotations

import numpy as np
import pytest
from cosim_helpers import HORIZON, tight

from bgmodelica.cosim import flat_loop
from bgmodelica.cosim.errors import CosimStepError
from bgmodelica.cosim.master import Master


def _both(monkeypatch, run):
    """``run()`` through the flat loop, then through the general loop."""
    taken = []
    real_run = flat_loop.FlatLoop.run

    def spy(self, *args, **kw):
        taken.append(True)
        return real_run(self, *args, **kw)

    monkeypatch.setattr(flat_loop.FlatLoop, "run", spy)
    fast = run()
    assert taken, "the flat loop was not used"
    monkeypatch.setattr(flat_loop, "applies", lambda *a, **k: False)
    general = run()
    return fast, general


def _first_local(master, element: str) -> str:
    return next(v.name for v in master.infos[element].variables.values()
                if v.causality == "local" and v.type == "Real")


@pytest.mark.parametrize("options", [
    {},
    {"propagate": False},
    {"record_every": 7},
    {"record": "locals"},
    {"max_abs": 1e6, "record_every": 3},
    {"order": "gauss-seidel"},
    {"order": "gauss-seidel", "propagate": False, "record_every": 4},
    {"order": "gauss-seidel", "sequence": ["controller", "arm", "motor2", "motor1"]},
])
def test_bit_identical_to_the_general_loop(monkeypatch, robot_ssp, options):
    master = Master(robot_ssp)
    if options.get("record") == "locals":       # a local variable of two elements
        options = {"record": [f"{el}.{_first_local(master, el)}" for el in ("arm", "motor1")]}
    fast, general = _both(monkeypatch, lambda: master.simulate(
        0.2, 1e-3, parameters=tight(robot_ssp), **options))
    assert fast.names == general.names
    assert np.array_equal(fast.time, general.time)
    assert np.array_equal(fast.values, general.values)
    every = options.get("record_every", 1)
    assert fast.values.shape[0] == 1 + -(-200 // every)
    assert fast.meta["terminated"] is None


def test_same_divergence_error(monkeypatch, robot_setup):
    """The unstable direct split at 5 ms: the same error, at the same step, either way."""
    plain = Master(robot_setup["ssp_plain"])
    messages = []

    def run():
        with pytest.raises(CosimStepError, match="diverges") as info:
            plain.simulate(HORIZON, 5e-3, max_abs=1e4, parameters=tight(plain.system))
        messages.append(str(info.value))

    _both(monkeypatch, run)
    assert messages[0] == messages[1]


def test_not_used_where_it_does_not_apply(robot_ssp):
    master = Master(robot_ssp)
    calls = []
    real = flat_loop.applies

    def spy(units, **kw):
        calls.append(real(units, **kw))
        return calls[-1]

    flat_loop.applies = spy
    try:
        master.simulate(0.01, 1e-3, order="gauss-seidel", extrapolation=True)
        master.simulate(0.01, 1e-3, extrapolation=True)
        Master(robot_ssp, interface="me").simulate(0.01, 1e-3)
        master.simulate(0.01, 1e-3)
        master.simulate(0.01, 1e-3, order="gauss-seidel")
    finally:
        flat_loop.applies = real
    assert calls == [False, False, False, True, True]


@pytest.mark.parametrize("order", ["jacobi", "gauss-seidel"])
def test_same_termination(monkeypatch, robot_ssp, order):
    """An FMU that asks to terminate (doStep: Discard, fmi2Terminated) at t = 0.05 ends both
    loops at the same point with the same record."""
    from bgmodelica.cosim.units import CoSimUnit

    real_bind = CoSimUnit._bind_raw

    def bind(self):
        real_bind(self)
        if self.name == "arm":
            step = self._raw["step"]
            self._raw["step"] = lambda c, t, h, flag: 2 if t >= 0.05 - 1e-12 else step(c, t, h,
                                                                                       flag)

    monkeypatch.setattr(CoSimUnit, "_bind_raw", bind)
    monkeypatch.setattr(CoSimUnit, "_fmi2_terminated", lambda self: True)
    master = Master(robot_ssp)
    fast, general = _both(monkeypatch, lambda: master.simulate(0.2, 1e-3, order=order))
    assert fast.meta["terminated"] == general.meta["terminated"]
    assert fast.meta["terminated"]["element"] == "arm"
    assert fast.time[-1] == pytest.approx(0.05)
    assert np.array_equal(fast.time, general.time)
    assert np.array_equal(fast.values, general.values)


@pytest.fixture(scope="module")
def fmi3_system(tmp_path_factory):
    from library.robots.subsystems import build_robot_fmus, robot_system

    return robot_system(build_robot_fmus(tmp_path_factory.mktemp("fmi3"), fmi_version=3,
                                         fmu_type="cs"))


def test_fmi3_units(monkeypatch, fmi3_system):
    """FMI 3.0 Co-Simulation units: the same results both ways, and a terminate request
    (fmi3DoStep's terminateSimulation) ends both at the same point."""
    master = Master(fmi3_system)
    fast, general = _both(monkeypatch, lambda: master.simulate(0.1, 1e-3, record_every=3))
    assert np.array_equal(fast.values, general.values)
    monkeypatch.undo()
    fast, general = _both(monkeypatch, lambda: master.simulate(0.1, 1e-3, order="gauss-seidel"))
    assert np.array_equal(fast.values, general.values)
    assert np.array_equal(fast.time, general.time)

    from bgmodelica.cosim.units import CoSimUnit

    real_step3 = CoSimUnit._step3

    def step3(self, t, h):
        if self.name == "motor2" and t >= 0.03 - 1e-12:
            self.terminated, self.stop_reason = True, "asked to terminate (test)"
            return
        real_step3(self, t, h)

    monkeypatch.undo()
    monkeypatch.setattr(CoSimUnit, "_step3", step3)
    fast, general = _both(monkeypatch, lambda: master.simulate(0.1, 1e-3))
    assert fast.meta["terminated"] == general.meta["terminated"]
    assert fast.meta["terminated"]["element"] == "motor2"
    assert np.array_equal(fast.values, general.values)
    assert fast.time[-1] == pytest.approx(0.03) and np.array_equal(fast.time, general.time)
