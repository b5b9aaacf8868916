"""The switch ``Sw`` of hybrid bond graphs (resistive form, Ron/Goff) against closed forms and
matrix exponentials, its mode sources (string, callable, when-driven Boolean, signal input,
constant), and the causality report for switched bonds."""

from __future__ import annotations

import numpy as np
import pytest

import bgmodelica as bm
from bgmodelica import Input
from bgmodelica.bondgraph import (
    J1,
    BondGraph,
    Graph,
    I,
    ModulusError,
    R,
    Se,
    Sw,
    analyze,
    assign_causality,
    ideal_modes,
)
from library.blocks import PWM, Sine
from library.bondgraph.switched import SwitchedDCMotor, SwitchedRC, SwitchedRL

TIGHT = dict(rtol=1e-9, atol=1e-11)


# -- closed forms -------------------------------------------------------------------------------

def rl_current(t, V=10.0, R=2.0, L=0.5, ts=0.1, Ron=1e-5, Goff=1e-5):
    """Series RL on V through a switch closing at ts: off, the switch is a resistance
    1/Goff; on, a resistance Ron (Goff = 0: ideal open switch, i = 0)."""
    Rn = R + Ron
    if Goff > 0:
        Rf = R + 1.0 / Goff
        i_off = V / Rf * (1 - np.exp(-Rf * np.minimum(t, ts) / L))
        i_ts = V / Rf * (1 - np.exp(-Rf * ts / L))
    else:
        i_off, i_ts = np.zeros_like(t), 0.0
    i_on = V / Rn + (i_ts - V / Rn) * np.exp(-Rn * (t - ts) / L)
    return np.where(t < ts, i_off, i_on)


def rc_voltage(t, V=5.0, R=100.0, Cap=1e-3, ts=0.05, Ron=1e-5, Goff=1e-5):
    Rn = R + Ron
    if Goff > 0:
        Rf = R + 1.0 / Goff
        v_off = V * (1 - np.exp(-np.minimum(t, ts) / (Rf * Cap)))
        v_ts = V * (1 - np.exp(-ts / (Rf * Cap)))
    else:
        v_off, v_ts = np.zeros_like(t), 0.0
    v_on = V + (v_ts - V) * np.exp(-(t - ts) / (Rn * Cap))
    return np.where(t < ts, v_off, v_on)


def motor_reference(t, Vs=12.0, R=1.0, L=0.05, k=0.1, J=1e-3, b=1e-3, t_on=0.05, t_off=0.5,
                    Ron=1e-5, Goff=1e-5):
    """Exact piecewise-linear solution (i, w) of the half-bridge DC motor.

    Motor voltage e_m at the 0-junction m: drive (hi on, lo off): (V - e_m)/Ron = Goff e_m + i
    -> e_m = (V - Ron i)/(1 + Ron Goff); freewheel (hi off, lo on): Goff (V - e_m) = e_m/Ron + i
    -> e_m = Ron (Goff V - i)/(1 + Ron Goff). Then L i' = e_m - R i - k w, J w' = k i - b w.
    """
    def segment(drive):
        gain = 1.0 / (1 + Ron * Goff) if drive else Ron * Goff / (1 + Ron * Goff)
        c = Ron / (1 + Ron * Goff)
        a = np.array([[-(R + c) / L, -k / L], [k / J, -b / J]])
        return a, np.array([gain * Vs / L, 0.0])

    def advance(x0, dt, drive):
        """x(dt) = x_ss + V exp(Lambda dt) V^-1 (x0 - x_ss), x_ss = -A^-1 B (A is
        invertible and diagonalizable: distinct eigenvalues)."""
        a, bvec = segment(drive)
        lam, vec = np.linalg.eig(a)
        x_ss = -np.linalg.solve(a, bvec)
        coef = np.linalg.solve(vec, x0 - x_ss)
        dt = np.atleast_1d(dt)
        return (x_ss[:, None] + vec @ (np.exp(np.outer(lam, dt)) * coef[:, None])).real.T

    x_on = advance(np.zeros(2), t_on, False)[0]
    x_off = advance(x_on, t_off - t_on, True)[0]
    out = np.zeros((len(t), 2))
    for sel, x0, t0, drive in ((t < t_on, np.zeros(2), 0.0, False),
                               ((t >= t_on) & (t < t_off), x_on, t_on, True),
                               (t >= t_off, x_off, t_off, False)):
        out[sel] = advance(x0, t[sel] - t0, drive)
    return out


# -- simulation against closed forms -------------------------------------------------------------

@pytest.mark.parametrize("small", [1e-5, 1e-8])
def test_rl_closing_switch_matches_closed_form(small):
    res = bm.simulate(SwitchedRL(), stop_time=1.0, interval=0.01,
                      params={"Ron": small, "Goff": small}, **TIGHT)
    t, i = res.time, res["j.f"]
    assert res.meta["event_times"] == pytest.approx([0.1], abs=1e-12)
    # the resistive form exactly (Ron, Goff in the closed form)
    assert np.max(np.abs(i - rl_current(t, Ron=small, Goff=small))) < 1e-7
    # the ideal switch (e = 0 on, f = 0 off) to within the leakage V*Goff and Ron/R
    ideal = rl_current(t, Ron=0.0, Goff=0.0)
    assert np.max(np.abs(i - ideal)) < 1.01 * 10.0 * small + 1e-7
    # mode and constitutive law of the switch: f = Goff e while off, e = Ron f while on
    on = res["sw.on"]
    e_sw, f_sw = res["sw.port.e"], res["sw.port.f"]    # flow into the switch (bond 4)
    assert np.all(on[t < 0.1] == 0.0) and np.all(on[t > 0.1] == 1.0)
    assert np.allclose(f_sw[t < 0.1], small * e_sw[t < 0.1], rtol=1e-9, atol=1e-15)
    assert np.allclose(e_sw[t > 0.1], small * f_sw[t > 0.1], rtol=1e-9, atol=1e-15)
    assert np.max(np.abs(e_sw[t > 0.1])) < 6.0 * small     # closed: e = Ron i, i <= 5 A


def test_rc_closing_switch_callable_mode():
    res = bm.simulate(SwitchedRC(), stop_time=0.5, interval=0.005, **TIGHT)
    t, v = res.time, res["cap.q"] / 1e-3
    assert res.meta["event_times"] == pytest.approx([0.05], abs=1e-12)
    assert np.max(np.abs(v - rc_voltage(t))) < 1e-6
    assert np.max(np.abs(v - rc_voltage(t, Ron=0.0, Goff=0.0))) < 3e-3    # 5 V * 0.05/(1e5*1e-3)


def test_dc_motor_half_bridge_when_driven():
    res = bm.simulate(SwitchedDCMotor(), stop_time=1.0, interval=0.005, **TIGHT)
    t = res.time
    assert res.meta["event_times"] == pytest.approx([0.05, 0.5], abs=1e-12)
    drive = res["drive"]
    assert np.all(drive[t < 0.05] == 0.0) and np.all(drive[(t > 0.05) & (t < 0.5)] == 1.0)
    assert np.all(drive[t > 0.5] == 0.0)
    assert np.all(res["lo.on"] == 1.0 - drive) and np.all(res["hi.on"] == drive)
    x = np.c_[res["i.f"], res["w.f"]]
    ref = motor_reference(t)
    err = np.max(np.abs(x - ref), axis=0)
    assert err[0] < 1e-6 and err[1] < 1e-5                  # i up to 7.8 A, w up to 114 rad/s
    ideal = motor_reference(t, Ron=0.0, Goff=0.0)
    assert np.max(np.abs(x - ideal), axis=0) == pytest.approx([0, 0], abs=1e-3)
    # motor voltage: Vs while driven (minus Ron i), ~0 while freewheeling
    on = (t > 0.05) & (t < 0.5)
    assert np.allclose(res["m.e"][on], 12.0, atol=1e-4)
    assert np.max(np.abs(res["m.e"][t > 0.5])) < 1e-4


def _rl_with(sw, blocks=None, drive_from=None, inp=False):
    """Se:10 -> 1 {R:2, I:0.5, sw}; ``blocks`` are added by name, ``drive_from`` (a dotted
    output name) or the model input ``u`` (``inp``) is connected to ``sw.u``."""

    class RL(BondGraph):
        if inp:
            u = Input(description="switch command")

        def __init__(self, **kw):
            super().__init__(**kw)
            for name, blk in (blocks or {}).items():
                self.add(name, blk)
            self.add("src", Se(E=10.0))
            self.add("j", J1())
            self.add("res", R(R=2.0))
            self.add("ind", I(I=0.5))
            self.add("sw", sw)
            if drive_from is not None:
                blk, out = drive_from.split(".")
                self.connect(getattr(self._children[blk], out), self.sw.u)
            if inp:
                self.connect(self.u, self.sw.u)
            self.bond(self.src, self.j)
            self.bond(self.j, self.res)
            self.bond(self.j, self.ind)
            self.bond(self.j, self.sw)

    return RL()


def test_signal_switch_from_a_block_is_a_state_event():
    model = _rl_with(Sw(signal=True), {"sine": Sine(f=1.0)}, "sine.y")   # sin(2 pi t) > 0.5
    res = bm.simulate(model, stop_time=0.4, interval=0.01, **TIGHT)
    ts = 1.0 / 12.0
    assert res.meta["event_times"] == pytest.approx([ts], abs=1e-9)
    assert np.max(np.abs(res["j.f"] - rl_current(res.time, ts=ts))) < 1e-6


def test_signal_switch_from_a_model_input_with_a_jump():
    model = _rl_with(Sw(signal=True, threshold=0.5), inp=True)
    res = bm.simulate(model, stop_time=0.5, interval=0.01,
                      inputs={"u": ([0.0, 0.2, 0.2, 1.0], [0.0, 0.0, 1.0, 1.0])}, **TIGHT)
    assert res.meta["event_times"] == pytest.approx([0.2], abs=1e-12)
    assert np.max(np.abs(res["j.f"] - rl_current(res.time, ts=0.2))) < 1e-7


def test_constant_and_boolean_block_modes():
    res = bm.simulate(_rl_with(Sw(on=True, Ron=1e-6)), stop_time=0.5, interval=0.01, **TIGHT)
    assert np.max(np.abs(res["j.f"] - rl_current(res.time, ts=0.0, Ron=1e-6))) < 1e-7
    res = bm.simulate(_rl_with(Sw(on=False)), stop_time=0.1, interval=0.01, **TIGHT)
    assert np.max(np.abs(res["j.f"])) < 1.01 * 10.0 * 1e-5
    # a Boolean of another component (the PWM block's `on`): a chopper, 2 events per period
    model = _rl_with(Sw(on=lambda m: m.pwm.on), {"pwm": PWM(f=50.0, duty=0.25)})
    assert "mode from pwm.on" in analyze(model).to_text()
    res = bm.simulate(model, stop_time=0.1, interval=0.001, **TIGHT)
    assert len(res.meta["event_times"]) == 10
    assert np.all(res["sw.on"] == res["pwm.on"])
    t, i = res.time, res["j.f"]
    first = t <= 0.005                                     # closed from 0 to 5 ms
    assert np.max(np.abs(i[first] - rl_current(t[first], ts=0.0))) < 1e-6


def test_mode_is_required_and_boolean():
    with pytest.raises(ModulusError, match="give the mode"):
        Sw()
    with pytest.raises(ModulusError, match="give the mode"):
        Sw(on="time > 1", signal=True)
    with pytest.raises(ModulusError, match="not a Boolean expression"):
        bm.compile(_rl_with(Sw(on="2*time")))
    with pytest.raises(ModulusError, match="unknown name"):
        bm.compile(_rl_with(Sw(on="time >= t_close")))


# -- causality report ---------------------------------------------------------------------------

def test_report_says_how_switched_bonds_are_handled():
    rep = analyze(SwitchedRL())
    text = rep.to_text()
    assert ("    sw (Sw:sw): switched bond 4, causality fixed (resistive form, Ron/Goff): "
            "resistance causality (flow in, effort out) in both modes; mode from time >= t_s"
            in text)
    assert "      ideal on (Se:0, e = 0): same storage causality" in text
    assert ("      ideal off (Sf:0, f = 0): would put ind (I:L) in derivative causality "
            "(resistive form: a fast mode, time constant set by Ron/Goff)" in text)
    assert ("  structural controllability/observability computed for the mode-independent "
            "structure (switches in resistive form)" in text)
    assert ("Structural controllability (Theorem 1): yes (mode-independent structure, switches "
            "in resistive form)" in text)
    assert "    Sw:sw          e4 = sw*f4" in text
    assert "    sw = Ron if on else 1/Goff (resistive switch), on: time >= t_s" in text
    assert "    d(p3)/dt = V - R*p3/L - sw*p3/L" in text
    assert rep.bgi.switches == {"sw": "resistance"} and "sw" not in rep.bgi.arbitrary
    d = rep.to_dict()
    assert d["switches"] == [{"name": "sw", "mode": "time >= t_s", "causality": "resistance",
                              "fixed_across_modes": True, "form": "resistive (Ron/Goff)"}]
    assert [(m["mode"], m["forced_derivative"]) for m in d["ideal_modes"]] == [
        ("on", []), ("off", ["ind"])]
    assert d["bgi"]["switches"] == {"sw": "resistance"}


def test_report_modes_of_when_driven_and_negated_booleans():
    text = analyze(SwitchedDCMotor()).to_text()
    assert "hi (Sw:hi): switched bond 2, causality fixed" in text
    assert text.count("in both modes; mode from drive") == 1
    assert "lo (Sw:lo): switched bond 4, causality fixed" in text
    assert "mode from not drive" in text
    assert "    hi = Ron if on else 1/Goff (resistive switch), on: drive" in text
    sig = analyze(_rl_with(Sw(signal=True), {"sine": Sine(f=1.0)}, "sine.y")).to_text()
    assert "mode from sw.u > 0.5" in sig


def test_ideal_modes_on_a_pure_graph():
    # a switch across a capacitor (closing it shorts C) and one across the source
    g = Graph("shorts")
    for name, kind in (("U", "Se"), ("a", "0"), ("sa", "Sw"), ("j", "1"), ("R", "R"),
                       ("b", "0"), ("cap", "C"), ("sb", "Sw")):
        g.add(name, kind, mode="t >= 1" if kind == "Sw" else "")
    g.bond("U", "a")
    g.bond("a", "sa")
    g.bond("a", "j")
    g.bond("j", "R")
    g.bond("j", "b")
    g.bond("b", "cap")
    g.bond("b", "sb")
    c = assign_causality(g)
    assert c.integral == ["cap"] and not c.conflicts
    assert c.switches == {"sa": "conductance", "sb": "conductance"}
    modes = {(m.switch, m.mode): m for m in ideal_modes(g, c)}
    assert modes["sb", "on"].forced == ["cap"] and modes["sb", "off"].consistent
    assert modes["sa", "on"].conflicts and not modes["sa", "on"].forced
    assert modes["sa", "off"].consistent
    text = analyze(g).to_text()
    assert "ideal on (Se:0, e = 0): would put cap (C) in derivative causality" in text
    assert "ideal on (Se:0, e = 0): causal conflict: " in text


def test_check_command_reports_switched_bonds(capsys):
    from bgmodelica.cli import main

    assert main(["check", "library.bondgraph.switched:SwitchedRL"]) == 0
    out = capsys.readouterr().out
    assert "event conditions (1):" in out
    assert ("sw (Sw:sw): switched bond 4, causality fixed (resistive form, Ron/Goff): "
            "resistance causality (flow in, effort out) in both modes; mode from time >= t_s"
            in out)
    assert "computed for the mode-independent structure" in out


def test_draw_with_a_switch(tmp_path):
    from bgmodelica.bondgraph import draw

    assert draw(SwitchedRL(), tmp_path / "rl.svg").stat().st_size > 1000


def test_signal_switch_from_a_piecewise_constant_block():
    """``0.5 < sw.u`` with ``sw.u = if_else(pwm.on, 1, 0)``: a relation whose indicator does not
    depend on time structurally (before the dense event functions of b89d5ce the event loop
    indexed the sparse dgdt output by relation number and raised IndexError here)."""
    model = _rl_with(Sw(signal=True), {"pwm": PWM(f=50.0, duty=0.25)}, "pwm.y")
    res = bm.simulate(model, stop_time=0.1, interval=0.001, **TIGHT)
    assert len(res.meta["event_times"]) == 10
    assert np.all(res["sw.on"] == res["pwm.on"])
