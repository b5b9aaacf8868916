"""Ideal switching elements of library.electrical (Modelica.Electrical.Analog.Ideal) and the
HalfWaveRectifier acceptance example, against the MSL piecewise-linear laws, closed forms and
an independent piecewise scipy integration."""

from __future__ import annotations

import math

import numpy as np
import pytest
from library_testing import TIGHT
from scipy.integrate import solve_ivp

import bgmodelica as bg
from bgmodelica import Component
from library.blocks import PWM, Ramp, Step
from library.electrical import (
    Capacitor,
    ConstantVoltage,
    ControlledIdealClosingSwitch,
    ControlledIdealCommutingSwitch,
    ControlledIdealOpeningSwitch,
    Ground,
    IdealClosingSwitch,
    IdealCommutingSwitch,
    IdealDiode,
    IdealOpeningSwitch,
    Resistor,
    SignalVoltage,
    SineVoltage,
)
from library.examples.hybrid import HalfWaveRectifier


def diode_law(v, Ron, Goff, Vknee):
    """MSL IdealSemiconductor: i(v), piecewise linear with the knee at v = Vknee."""
    v = np.asarray(v, dtype=float)
    return np.where(v < Vknee, Goff * v, (v - Vknee) / Ron + Goff * Vknee)


def event_rows(res, t_event):
    """Indices of the left- and right-limit rows of the event at ``t_event``."""
    k = np.nonzero(res.time == t_event)[0]
    assert len(k) == 2, (t_event, k)
    return int(k[0]), int(k[1])


# -- (1) the diode characteristic ---------------------------------------------------------------

@pytest.mark.parametrize("Ron, Goff, Vknee", [(1e-5, 1e-5, 0.0), (0.5, 0.05, 0.7)])
def test_ideal_diode_characteristic(Ron, Goff, Vknee):
    # a source swept from -2 V to 2 V across the diode in series with 10 Ohm
    m = Component(name="sweep")
    m.add("ramp", Ramp(height=4.0, offset=-2.0, duration=1.0))
    m.add("source", SignalVoltage())
    m.add("diode", IdealDiode(Ron=Ron, Goff=Goff, Vknee=Vknee))
    m.add("load", Resistor(R=10.0))
    m.add("ground", Ground())
    m.connect(m.ramp.y, m.source.u)
    m.connect(m.source.p, m.diode.p)
    m.connect(m.diode.n, m.load.p)
    m.connect(m.load.n, m.ground.p)
    m.connect(m.source.n, m.ground.p)
    res = bg.simulate(m, stop_time=1.0, interval=1e-3, **TIGHT)
    v, i = res["diode.v"], res["diode.i"]
    assert v.min() < -1.3 and i.max() > 0.1 and v.max() >= Vknee
    # i(v) follows the MSL law everywhere (including both rows at the event)
    assert np.max(np.abs(i - diode_law(v, Ron, Goff, Vknee))) < 1e-9
    # one switching, blocking -> conducting, exactly where v crosses the knee
    s_events = [t for t in res.meta["event_times"] if 0.0 < t < 1.0]
    causes = res.meta["event_causes"]
    assert causes.get("s < 0") == 1, causes
    (t_on,) = [t for t in s_events if res["diode.off"][event_rows(res, t)[0]] == 1.0]
    left, right = event_rows(res, t_on)
    assert res["diode.off"][left] == 1.0 and res["diode.off"][right] == 0.0
    assert abs(v[right] - Vknee) < 1e-9 and abs(i[right] - Goff * Vknee) < 1e-9
    # the closed form of the series circuit: the source voltage at the knee current
    u_knee = Vknee + 10.0 * Goff * Vknee
    assert abs(t_on - (u_knee + 2.0) / 4.0) < 1e-9
    # the Boolean state matches the sign of v - Vknee away from the event
    away = np.abs(res.time - t_on) > 1e-6
    assert np.array_equal(res["diode.off"][away] == 1.0, (v < Vknee)[away])


# -- (2) the half-wave rectifier against an independent piecewise integration -------------------

def rectifier_reference(t_out, t_end, V=10.0, f=50.0, Ron=1e-5, Goff=1e-5, R=100.0, C=100e-6):
    """v_out, i_d at ``t_out`` and the switching instants, by scipy: in each mode the load is
    the linear ODE C v' = G (vs - v) - v/R with G = 1/Ron (conducting) or Goff (blocking);
    solve_ivp (LSODA, stiff while conducting) stops at the switching condition vs - v = 0
    (= the sign of the diode's s in both modes), crossing downwards while conducting (the
    current would turn negative) and upwards while blocking. v(0) = 0, conducting at t = 0
    (s(0) = 0 is not < 0)."""
    w = 2 * math.pi * f

    def vs(t):
        return V * np.sin(w * t)

    t0, v0, conducting = 0.0, 0.0, True
    switches = []
    v_out = np.full(len(t_out), np.nan)
    G_of = np.full(len(t_out), np.nan)
    while t0 < t_end:
        G = 1.0 / Ron if conducting else Goff

        def rhs(t, y, G=G):
            return [(G * (vs(t) - y[0]) - y[0] / R) / C]

        def crossing(t, y):
            return vs(t) - y[0]

        crossing.terminal = True
        crossing.direction = -1 if conducting else 1
        sol = solve_ivp(rhs, (t0, t_end), [v0], method="LSODA", events=crossing,
                        rtol=1e-12, atol=1e-14, dense_output=True)
        assert sol.success, sol.message
        hit = sol.status == 1
        t1 = float(sol.t_events[0][0]) if hit else t_end
        sel = (t_out >= t0) & (t_out <= t1)
        if sel.any():
            v_out[sel] = sol.sol(t_out[sel])[0]
            G_of[sel] = G
        v0 = float(sol.y_events[0][0][0]) if hit else float(sol.y[0, -1])
        if hit:
            switches.append(t1)
            conducting = not conducting
        t0 = t1
    return v_out, G_of * (vs(t_out) - v_out), np.array(switches)


def test_half_wave_rectifier_against_piecewise_scipy():
    res = bg.simulate(HalfWaveRectifier(), stop_time=0.1, interval=1e-4, **TIGHT)
    v_ref, i_ref, t_sw = rectifier_reference(res.time, 0.1)
    assert res["v_out"][0] == 0.0
    err_v = np.max(np.abs(res["v_out"] - v_ref))
    err_i = np.max(np.abs(res["i_d"] - i_ref))
    assert err_v < 1e-6, err_v
    assert err_i < 1e-3, err_i
    # the load is the capacitor, the diode current charges it and feeds the resistor
    assert np.max(np.abs(res["v_out"] - res["capacitor.v"])) == 0.0
    assert np.max(np.abs(res["i_d"] - res["diode.i"])) == 0.0

    # events: the reference's switchings, two per period (the first half period starts
    # conducting, so 1 + 2*4 in 0.1 s), alternately off and on, each with two result rows
    events = np.array(res.meta["event_times"])
    assert res.meta["event_causes"] == {"s < 0": 9}
    assert len(events) == len(t_sw) == 9
    assert np.max(np.abs(events - t_sw)) < 1e-6
    period = np.floor(events * 50.0 + 1e-9)
    assert list(np.bincount(period.astype(int))) == [1, 2, 2, 2, 2]
    for k, t in enumerate(events):
        left, right = event_rows(res, t)
        turning_off = k % 2 == 0
        assert res["diode.off"][left] == (0.0 if turning_off else 1.0)
        assert res["diode.off"][right] == (1.0 if turning_off else 0.0)
        # the current is continuous (zero) at both kinds of switching
        assert abs(res["i_d"][left]) < 1e-3 and abs(res["i_d"][right]) < 1e-3
    # turn-off where the ideal (Ron = Goff = 0) current C vs' + vs/R vanishes:
    # tan(w t) = -w R C; turn-on where the source catches up with the decaying load voltage
    w, RC = 2 * math.pi * 50.0, 100.0 * 100e-6
    t_off = (math.pi - math.atan(w * RC)) / w + np.arange(5) / 50.0
    assert np.max(np.abs(events[0::2] - t_off)) < 1e-6
    for t_on in events[1::2]:
        k = event_rows(res, t_on)[1]
        assert abs(10.0 * math.sin(w * t_on) - res["v_out"][k]) < 1e-6
        assert 0.0 < (t_on * 50.0) % 1.0 < 0.25      # on the rising quarter of the sine

    # conducting rows: v_out follows the source (up to Ron*i); blocking: the diode is reversed
    on = res["diode.off"] == 0.0
    t = res.time
    assert np.max(np.abs(res["v_out"][on] - 10.0 * np.sin(w * t[on]))) < 1e-4
    assert np.all(res["diode.v"][~on] <= 1e-9)


def test_half_wave_rectifier_parameters_by_name():
    params = {"V": 5.0, "f": 60.0, "R": 50.0, "C": 200e-6, "Ron": 2e-5, "Goff": 2e-6}
    res = bg.simulate(HalfWaveRectifier(), stop_time=1 / 60.0, interval=1e-4, params=params,
                      **TIGHT)
    for name, value in params.items():
        assert res[name][-1] == value
    # the subcomponents are bound to the top-level parameters: the changed circuit matches
    v_ref, i_ref, t_sw = rectifier_reference(res.time, 1 / 60.0, V=5.0, f=60.0, Ron=2e-5,
                                             Goff=2e-6, R=50.0, C=200e-6)
    assert np.max(np.abs(res["v_out"] - v_ref)) < 1e-6
    assert np.max(np.abs(res["i_d"] - i_ref)) < 1e-3
    assert np.max(res["v_out"]) == pytest.approx(5.0, abs=1e-3)
    w = 2 * math.pi * 60.0
    assert res.meta["event_times"][0] == pytest.approx((math.pi - math.atan(w * 50.0 * 200e-6)) / w,
                                                       abs=1e-6)


# -- (3) switches with a timed control ----------------------------------------------------------

def _switch_circuit(switch, control):
    """10 V -> switch -> 10 Ohm -> ground, the switch's Boolean input from ``control.y``."""
    m = Component(name="switched")
    m.add("source", ConstantVoltage(V=10.0))
    m.add("switch", switch)
    m.add("load", Resistor(R=10.0))
    m.add("ground", Ground())
    m.add("control", control)
    m.connect(m.source.p, m.switch.p)
    m.connect(m.switch.n, m.load.p)
    m.connect(m.load.n, m.ground.p)
    m.connect(m.source.n, m.ground.p)
    m.connect(m.control.y, m.switch.control)
    return m


#: load current with the switch closed (Ron in series) and open (1/Goff in series)
I_CLOSED = 10.0 / (10.0 + 1e-5)
I_OPEN = 10.0 * 1e-5 / (1.0 + 10.0 * 1e-5)


@pytest.mark.parametrize("opening", [True, False])
def test_opening_and_closing_switch_with_step_control(opening):
    cls = IdealOpeningSwitch if opening else IdealClosingSwitch
    res = bg.simulate(_switch_circuit(cls(), Step(height=1.0, start_time=0.3)), stop_time=1.0,
                      interval=0.05, **TIGHT)
    assert res.meta["event_times"] == [0.3]
    before, after = (I_CLOSED, I_OPEN) if opening else (I_OPEN, I_CLOSED)
    t, i = res.time, res["load.i"]
    left, right = event_rows(res, 0.3)
    assert np.max(np.abs(i[: left + 1] - before)) < 1e-12
    assert np.max(np.abs(i[right:] - after)) < 1e-12
    assert np.all(t[: left + 1] <= 0.3) and np.all(t[right:] >= 0.3)
    off = res["switch.off"]
    assert off[left] == (0.0 if opening else 1.0) and off[right] == (1.0 if opening else 0.0)
    # the switch laws: closed v = Ron*i, open i = Goff*v
    v_sw, i_sw = res["switch.v"], res["switch.i"]
    assert np.max(np.abs(np.where(off == 1.0, i_sw - 1e-5 * v_sw, v_sw - 1e-5 * i_sw))) < 1e-12


def test_opening_switch_with_pwm_control():
    # control high (switch open) on [k/2, k/2 + 1/8): both edges are time events
    res = bg.simulate(_switch_circuit(IdealOpeningSwitch(Ron=0.1, Goff=1e-3),
                                      PWM(f=2.0, duty=0.25)),
                      stop_time=1.0, interval=0.01, **TIGHT)
    assert res.meta["event_times"] == pytest.approx([0.125, 0.5, 0.625, 1.0], abs=1e-12)
    t = res.time
    high = (np.mod(t, 0.5) < 0.125)
    closed, opened = 10.0 / 10.1, 10.0 * 1e-3 / (1.0 + 10.0 * 1e-3)
    regular = ~np.isin(t, res.meta["event_times"])
    expected = np.where(high, opened, closed)
    assert np.max(np.abs(res["load.i"][regular] - expected[regular])) < 1e-12


def test_commuting_switch_with_step_control():
    m = Component(name="commuting")
    m.add("source", ConstantVoltage(V=10.0))
    m.add("switch", IdealCommutingSwitch())
    m.add("R1", Resistor(R=10.0))
    m.add("R2", Resistor(R=20.0))
    m.add("ground", Ground())
    m.add("control", Step(height=1.0, start_time=0.4))
    m.connect(m.source.p, m.switch.p)
    m.connect(m.switch.n1, m.R1.p)
    m.connect(m.switch.n2, m.R2.p)
    m.connect(m.R1.n, m.ground.p)
    m.connect(m.R2.n, m.ground.p)
    m.connect(m.source.n, m.ground.p)
    m.connect(m.control.y, m.switch.control)
    res = bg.simulate(m, stop_time=1.0, interval=0.05, **TIGHT)
    assert res.meta["event_times"] == [0.4]
    left, right = event_rows(res, 0.4)
    # path currents: closed 10/(R + 1e-5); open 1e-5*10/(1 + R*1e-5)
    on1, off1 = 10.0 / (10.0 + 1e-5), 1e-4 / (1.0 + 10.0 * 1e-5)
    on2, off2 = 10.0 / (20.0 + 1e-5), 1e-4 / (1.0 + 20.0 * 1e-5)
    i1, i2 = res["R1.i"], res["R2.i"]
    assert np.max(np.abs(i1[: left + 1] - on1)) < 1e-12
    assert np.max(np.abs(i2[: left + 1] - off2)) < 1e-12
    assert np.max(np.abs(i1[right:] - off1)) < 1e-12
    assert np.max(np.abs(i2[right:] - on2)) < 1e-12
    assert np.max(np.abs(res["switch.p.i"] - i1 - i2)) < 1e-12


@pytest.mark.parametrize("cls", [ControlledIdealOpeningSwitch, ControlledIdealClosingSwitch,
                                 ControlledIdealCommutingSwitch])
def test_controlled_switches_switch_at_the_control_level(cls):
    # control voltage sin(2 pi t) against level 0.5: above it on (1/12, 5/12) (state events);
    # the switched path charges a capacitor (10 V, 10 Ohm, 10 mF)
    m = Component(name="controlled")
    m.add("source", ConstantVoltage(V=10.0))
    m.add("switch", cls(level=0.5))
    m.add("load", Resistor(R=10.0))
    m.add("cap", Capacitor(C=0.01, v=0.0))
    m.add("ground", Ground())
    m.add("cv", SineVoltage(V=1.0, f=1.0))
    m.connect(m.source.p, m.switch.p)
    m.connect(m.switch.n if cls is not ControlledIdealCommutingSwitch else m.switch.n2,
              m.load.p)
    m.connect(m.load.n, m.cap.p)
    m.connect(m.cap.n, m.ground.p)
    m.connect(m.source.n, m.ground.p)
    m.connect(m.cv.p, m.switch.control)
    m.connect(m.cv.n, m.ground.p)
    if cls is ControlledIdealCommutingSwitch:
        m.add("R1", Resistor(R=1.0))
        m.connect(m.switch.n1, m.R1.p)
        m.connect(m.R1.n, m.ground.p)
    res = bg.simulate(m, stop_time=1.0, interval=0.01, **TIGHT)
    events = res.meta["event_times"]
    assert np.max(np.abs(np.array(events) - [1 / 12, 5 / 12])) < 1e-10
    assert res["switch.control.i"].max() == 0.0 == res["switch.control.i"].min()
    # the load path conducts while control.v > level for the closing/commuting switch, while
    # control.v <= level for the opening switch; closed-form charging of the capacitor
    conducts_high = cls is not ControlledIdealOpeningSwitch
    t = res.time
    tau_on = (10.0 + 1e-5) * 0.01
    tau_off = (10.0 + 1 / 1e-5) * 0.01

    def charge(v0, t0, t1, tau):
        return 10.0 + (v0 - 10.0) * np.exp(-(t1 - t0) / tau)

    taus = [tau_off, tau_on, tau_off] if conducts_high else [tau_on, tau_off, tau_on]
    bounds = [0.0, 1 / 12, 5 / 12, 1.0]
    v0 = 0.0
    expected = np.empty_like(t)
    for k in range(3):
        t0, t1 = bounds[k], bounds[k + 1]
        sel = (t >= t0) & (t <= t1)
        expected[sel] = charge(v0, t0, t[sel], taus[k])
        v0 = charge(v0, t0, t1, taus[k])
    right = [event_rows(res, e)[1] for e in events]
    for k, r in enumerate(right):        # at event rows the right limit belongs to the next piece
        t0 = bounds[k + 1]
        expected[r] = charge(expected[r - 1], t0, t0, taus[k + 1])
    assert np.max(np.abs(res["cap.v"] - expected)) < 1e-7
