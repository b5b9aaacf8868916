"""Event blocks: Relay, LimiterEvents, Sampler, ZeroOrderHold, UnitDelay, DiscretePID, PWM,
TimeTable, each against an analytic or independently computed result (rtol 1e-10).

At an event instant a result holds two rows with the same time: the left limit, then the
right limit (:func:`pairs` finds them).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import expm

import bgmodelica as bg
from bgmodelica import Component
from library.blocks import (
    PWM,
    Constant,
    DiscretePID,
    Feedback,
    FirstOrder,
    Gain,
    Integrator,
    Limiter,
    LimiterEvents,
    Relay,
    Sampler,
    Sine,
    Step,
    TimeTable,
    UnitDelay,
    ZeroOrderHold,
)

RTOL = 1e-10
#: integrator tolerances well below RTOL, so the comparisons measure the event handling
EXACT = {"rtol": 1e-12, "atol": 1e-14}


def chain(*pairs: tuple, **blocks) -> Component:
    """A model of ``blocks`` (name=block) joined by ``(from "a.y", to "b.u")`` pairs."""
    m = Component(name="Chain")
    for name, block in blocks.items():
        m.add(name, block)
    for a, b in pairs:
        (ca, sa), (cb, sb) = a.split("."), b.split(".")
        m.connect(getattr(m.children()[ca], sa), getattr(m.children()[cb], sb))
    return m


def pairs(result) -> np.ndarray:
    """Indices i of the left-limit rows of events (time[i] == time[i + 1])."""
    return np.nonzero(np.diff(result.time) == 0)[0]


def close(actual, expected, scale: float = 1.0) -> None:
    np.testing.assert_allclose(np.asarray(actual, dtype=float),
                               np.asarray(expected, dtype=float),
                               rtol=RTOL, atol=RTOL * scale)


# -- Relay ------------------------------------------------------------------------------------


@pytest.mark.parametrize("pre_y_start", [False, True])
def test_relay_switches_at_analytic_hysteresis_times(pre_y_start):
    # u = 2 sin(pi t); on when u > 0.8 (sin = 0.4 rising), off when u < -0.6 (sin = -0.3
    # falling). Every relation crossing is an event (4 per period); the output switches at 2.
    A, u_hi, u_lo, y_on, y_off, stop = 2.0, 0.8, -0.6, 3.0, -1.0, 4.0
    m = chain(("s.y", "r.u"), ("r.y", "i.u"), s=Sine(amplitude=A, f=0.5),
              r=Relay(uLow=u_lo, uHigh=u_hi, y_on=y_on, y_off=y_off, pre_y_start=pre_y_start),
              i=Integrator())
    result = bg.simulate(m, stop_time=stop, interval=0.1, **EXACT)
    a_hi, a_lo = math.asin(u_hi / A) / math.pi, math.asin(-u_lo / A) / math.pi
    on_times = [a_hi + 2 * k for k in range(2)]                   # sin rises through 0.4
    off_times = [1 + a_lo + 2 * k for k in range(2)]              # sin falls through -0.3
    other = [1 - a_hi + 2 * k for k in range(2)] + [2 - a_lo + 2 * k for k in range(2)]
    if pre_y_start:                 # u(0) = 0 >= uLow: stays on until the first off time
        on_times = on_times[1:]
    crossings = sorted(on_times + off_times + other)
    if pre_y_start:                 # the upward crossing of uHigh while on is still an event
        crossings = sorted(crossings + [a_hi])
    close(result.meta["event_times"], crossings, stop)
    on = result["r.on"]
    assert on[0] == float(pre_y_start)
    i = pairs(result)
    rises = result.time[i[(on[i] == 0) & (on[i + 1] == 1)]]
    falls = result.time[i[(on[i] == 1) & (on[i + 1] == 0)]]
    close(rises, on_times, stop)
    close(falls, off_times, stop)
    assert set(np.unique(on)) == {0.0, 1.0}
    close(result["r.y"], np.where(on == 1, y_on, y_off))
    # the integral of the output: y_on times the time on, y_off the time off
    edges = sorted([(t, 1) for t in on_times] + [(t, 0) for t in off_times])
    state, last, t_on = float(pre_y_start), 0.0, 0.0
    for t, new in edges + [(stop, None)]:
        t_on += (t - last) * state
        state, last = new, t
    close(result.final("i.y"), y_on * t_on + y_off * (stop - t_on), stop)


# -- Limiter with events --------------------------------------------------------------------


def test_limiter_events_hit_the_corners_exactly():
    A, hi, lo = 2.0, 1.5, -0.5
    m = chain(("s.y", "lim.u"), ("lim.y", "i.u"), s=Sine(amplitude=A, f=0.5),
              lim=LimiterEvents(u_max=hi, u_min=lo), i=Integrator())
    result = bg.simulate(m, stop_time=2.0, interval=0.05, **EXACT)
    a, b = math.asin(hi / A) / math.pi, math.asin(-lo / A) / math.pi
    corners = [a, 1 - a, 1 + b, 2 - b]
    close(result.meta["event_times"], corners, 2.0)
    assert result.meta["event_causes"] == {"u_max < u": 2, "u < u_min": 2}
    t = result.time
    close(result["lim.y"], np.clip(A * np.sin(np.pi * t), lo, hi), A)
    # integral of the clipped sine, piecewise analytic
    F = lambda t0, t1: A / np.pi * (np.cos(np.pi * t0) - np.cos(np.pi * t1))  # noqa: E731
    total = F(0, a) + hi * (1 - 2 * a) + F(1 - a, 1 + b) + lo * (1 - 2 * b) + F(2 - b, 2)
    close(result.final("i.y"), total)
    # the plain Limiter keeps its continuous form: no events
    plain = chain(("s.y", "lim.u"), ("lim.y", "i.u"), s=Sine(amplitude=A, f=0.5),
                  lim=Limiter(u_max=hi, u_min=lo), i=Integrator())
    assert bg.simulate(plain, stop_time=2.0, interval=0.05).meta.get("event_times", []) == []


# -- Sampler, ZeroOrderHold, UnitDelay ------------------------------------------------------


def test_sampler_hold_and_unit_delay_at_and_between_samples():
    Ts, t0, y_start, stop = 0.25, 0.1, -7.0, 1.2
    u = lambda t: 2.0 * np.sin(2 * np.pi * 0.3 * np.asarray(t) + 0.4)  # noqa: E731
    m = chain(("s.y", "smp.u"), ("s.y", "zoh.u"), ("s.y", "ud.u"),
              s=Sine(amplitude=2.0, f=0.3, phase=0.4),
              smp=Sampler(Ts=Ts, start_time=t0), zoh=ZeroOrderHold(Ts=Ts, start_time=t0),
              ud=UnitDelay(Ts=Ts, start_time=t0, y_start=y_start))
    result = bg.simulate(m, stop_time=stop, interval=0.05)
    t_k = t0 + Ts * np.arange(5)                       # 0.1, 0.35, ..., 1.1
    close(result.meta["event_times"], t_k, stop)
    t = result.time
    left = np.zeros(len(t), dtype=bool)
    left[pairs(result)] = True
    # samples taken by each row: up to and including t (right limits), before t (left limits)
    n = np.array([np.sum(t_k < tt) if lft else np.sum(t_k <= tt)
                  for tt, lft in zip(t, left, strict=True)])
    assert {0, 5} <= set(n)
    last = np.where(n >= 1, u(t_k[np.maximum(n - 1, 0)]), u(0.0))    # initial(): u(0)
    close(result["smp.y"], last, 2.0)
    close(result["zoh.y"], last, 2.0)
    previous = np.where(n >= 2, u(t_k[np.maximum(n - 2, 0)]), y_start)
    close(result["ud.y"], previous, 7.0)
    # between samples the outputs are constant while the input moves
    inside = (~left) & (np.abs(t[:, None] - t_k[None, :]).min(axis=1) > 1e-3)
    assert inside.sum() > 15 and np.ptp(u(t[inside])) > 1.0


def test_zero_order_hold_breaks_a_feedback_loop():
    # zoh.u = 1 - 0.5*zoh.y with direct feedthrough: y = pre(y_sample) delays the loop by
    # one sample: y_k = 1 - 0.5*y_(k-1), y_(-1) = 0 (the start of y_sample)
    m = chain(("c.y", "fb.u1"), ("g.y", "fb.u2"), ("fb.y", "zoh.u"), ("zoh.y", "g.u"),
              c=Constant(k=1.0), fb=Feedback(), g=Gain(k=0.5), zoh=ZeroOrderHold(Ts=0.1))
    result = bg.simulate(m, stop_time=0.5, interval=0.1)
    y, expected = 0.0, []
    for _ in range(6):
        y = 1.0 - 0.5 * y
        expected.append(y)
    i = pairs(result)
    close(result.meta["event_times"], 0.1 * np.arange(1, 6))
    close(result["zoh.y"][0], expected[0])
    close(result["zoh.y"][i], expected[:-1])
    close(result["zoh.y"][i + 1], expected[1:])


# -- DiscretePID ----------------------------------------------------------------------------


def test_discrete_pid_on_first_order_plant_matches_exact_recurrence():
    Ts, Kp, Ki, Kd, y_max, y_min = 0.05, 4.0, 6.0, 0.05, 2.5, -1.0
    k, T, x0, stop = 1.5, 0.3, 0.2, 1.0
    r = lambda t: np.where(np.asarray(t) >= 0.5, -0.5, 1.0)  # noqa: E731  setpoint step
    m = chain(("sp.y", "pid.u_s"), ("plant.y", "pid.u_m"), ("pid.y", "plant.u"),
              sp=Step(height=-1.5, offset=1.0, start_time=0.5),
              pid=DiscretePID(Kp=Kp, Ki=Ki, Kd=Kd, Ts=Ts, y_max=y_max, y_min=y_min),
              plant=FirstOrder(k=k, T=T, y_start=x0))
    result = bg.simulate(m, stop_time=stop, interval=0.01, rtol=1e-13, atol=1e-15)
    # hand-written recurrence; the plant over one held sample by the matrix exponential of
    # [[A, B], [0, 0]]*Ts (exact zero-order-hold discretization of T x' = k u - x)
    A, B = np.array([[-1.0 / T]]), np.array([[k / T]])
    M = expm(np.block([[A, B], [np.zeros((1, 2))]]) * Ts)
    Ad, Bd = M[:1, :1], M[:1, 1:]
    t_k = np.array([j * Ts for j in range(21)])        # the instants sample(0, Ts) hits
    x, I, e_prev, xs, us = np.array([x0]), 0.0, None, [], []
    for tk in t_k:
        e = float(r(tk)) - x[0]
        I += Ts * e
        D = 0.0 if e_prev is None else (e - e_prev) / Ts
        e_prev = e
        u = min(y_max, max(y_min, Kp * e + Ki * I + Kd * D))
        xs.append(x[0])
        us.append(u)
        x = Ad @ x + Bd[:, 0] * u
    xs, us = np.array(xs), np.array(us)
    assert us.max() == y_max and us.min() == y_min      # both limits are active
    i = pairs(result)
    close(result.time[i], t_k[1:], stop)                # samples after t = 0 (t = 0: init)
    close(result["pid.y"][0], us[0], y_max)
    close(result["pid.y"][i], us[:-1], y_max)           # left limits: previous output held
    close(result["pid.y"][i + 1], us[1:], y_max)
    close(result["plant.y"][i], xs[1:])
    close(result["plant.y"][i + 1], xs[1:])
    # between the samples: the exact response to the held output
    t = result.time
    j = np.clip(np.searchsorted(t_k, t, side="right") - 1, 0, 20)
    mask = np.ones(len(t), dtype=bool)
    mask[i] = False                                     # left limits belong to the sample before
    decay = np.exp(-(t - t_k[j]) / T)
    close(result["plant.y"][mask], (xs[j] * decay + k * us[j] * (1 - decay))[mask])
    close(result["pid.y"][mask], us[j][mask], y_max)


# -- PWM ------------------------------------------------------------------------------------


def test_pwm_edges_are_exact_and_duty_is_kept():
    V, f, duty, stop = 5.0, 4.0, 0.3, 1.0
    m = chain(("pwm.y", "i.u"), pwm=PWM(V=V, f=f, duty=duty), i=Integrator())
    result = bg.simulate(m, stop_time=stop, interval=0.1, **EXACT)
    rising = np.arange(1, 5) / f                          # t = 0 is the initial sample
    falling = (np.arange(4) + duty) / f
    close(result.meta["event_times"], np.sort(np.concatenate([rising, falling])), stop)
    y, i = result["pwm.y"], pairs(result)
    close(result.time[i[(y[i] == 0) & (y[i + 1] == V)]], rising, stop)
    close(result.time[i[(y[i] == V) & (y[i + 1] == 0)]], falling, stop)
    assert y[0] == V and np.all(result["pwm.on"] == (y == V))
    close(result.final("i.y"), V * duty * stop)            # mean V*duty over whole periods
    # delayed start: 0 before start_time, then periods from start_time
    m = chain(("pwm.y", "i.u"), pwm=PWM(V=2.0, f=10.0, duty=0.25, start_time=0.33),
              i=Integrator())
    result = bg.simulate(m, stop_time=0.6, interval=0.1, **EXACT)
    y, i, t = result["pwm.y"], pairs(result), result.time
    close(t[i[(y[i] == 0) & (y[i + 1] == 2.0)]], 0.33 + np.arange(3) / 10.0)
    close(t[i[(y[i] == 2.0) & (y[i + 1] == 0)]], 0.33 + (np.arange(3) + 0.25) / 10.0)
    assert np.all(y[t < 0.33] == 0)
    close(result.final("i.y"), 2.0 * 3 * 0.025)


# -- TimeTable ------------------------------------------------------------------------------


TABLE = np.array([[0.2, 1.0], [0.5, 2.0], [1.0, 2.0], [1.0, -1.0], [1.6, 0.5]])


def table_reference(times, values, t, smoothness, extrapolation, side):
    """The table at ``t`` (numpy): the left or right limit at a breakpoint."""
    times, values = np.asarray(times, float), np.asarray(values, float)
    t0, t1 = times[0], times[-1]
    local = t
    if extrapolation == "periodic":
        local = t0 + np.mod(t - t0, t1 - t0)
        if side == "left" and abs(local - t0) < 1e-12 and t > t0:
            local = t1                                    # left limit at a period boundary
    snap = np.abs(times - local) < 1e-12
    if snap.any():
        local = times[np.argmax(snap)]
    if smoothness == "hold":
        j = np.searchsorted(times, local, side="right" if side == "right" else "left") - 1
        return values[min(max(j, 0), len(values) - 1)]
    # linear: at a breakpoint the left limit is its first row, the right limit its last
    # (a repeated time is a jump); in between, the segment from the last row of the
    # breakpoint before to the first row of the breakpoint after
    at = np.nonzero(times == local)[0]
    if at.size:
        return values[at[0] if side == "left" else at[-1]]
    j = np.searchsorted(times, local, side="right")
    if j == 0 or j == len(times):
        return values[0] if j == 0 else values[-1]
    w = (local - times[j - 1]) / (times[j] - times[j - 1])
    return (1 - w) * values[j - 1] + w * values[j]


def check_table(result, name, times, values, smoothness, extrapolation, breakpoints,
                offset=0.0):
    t, y = result.time, result[name]
    left = np.zeros(len(t), dtype=bool)
    left[pairs(result)] = True
    near = np.abs(t[:, None] - np.asarray(breakpoints)[None, :]).min(axis=1) < 1e-9
    is_event = left | np.roll(left, 1)
    rows = is_event | ~near                                # skip grid rows ulps from a jump
    expected = [offset + table_reference(times, values, tt, smoothness, extrapolation,
                                         "left" if lft else "right")
                for tt, lft in zip(t, left, strict=True)]
    close(y[rows], np.asarray(expected)[rows], 2.0)
    assert rows.sum() > 20


def test_time_table_linear_hold_and_jump():
    m = Component(name="Tables")
    m.add("lin", TimeTable(TABLE, offset=0.25))
    m.add("hold", TimeTable(TABLE, smoothness="hold"))
    result = bg.simulate(m, stop_time=2.0, interval=0.05)
    breakpoints = [0.2, 0.5, 1.0, 1.6]
    close(result.meta["event_times"], breakpoints)
    check_table(result, "lin.y", TABLE[:, 0], TABLE[:, 1], "linear", "hold", breakpoints, 0.25)
    check_table(result, "hold.y", TABLE[:, 0], TABLE[:, 1], "hold", "hold", breakpoints)
    # the jump at t = 1: left limit 2 (+ offset), right limit -1 (+ offset)
    k = int(np.nonzero(result.time == 1.0)[0][0])
    assert result.time[k + 1] == 1.0
    close([result["lin.y"][k], result["lin.y"][k + 1]], [2.25, -0.75])
    close([result["hold.y"][k], result["hold.y"][k + 1]], [2.0, -1.0])


def run_periodic(table, scale, stop):
    m = chain(tab=TimeTable(table, extrapolation="periodic", timeScale=scale))
    result = bg.simulate(m, stop_time=stop, interval=0.05)
    times = table[:, 0] * scale
    period = times[-1] - times[0]
    breakpoints = sorted({round(b + n * period, 12) for b in times for n in range(-1, 12)
                          if 0 < b + n * period <= stop})
    close(result.meta["event_times"], breakpoints, stop)
    check_table(result, "tab.y", times, table[:, 1], "linear", "periodic", breakpoints)


def test_time_table_periodic_with_time_scale():
    # dyadic times (0 .. 0.375 s after scaling, period 0.375): every breakpoint
    # t_i + n*period is exact in floating point
    table = np.array([[0.0, 1.0], [0.125, 2.0], [0.5, 2.0], [0.5, -1.0], [0.75, 0.5]])
    run_periodic(table, 0.5, 3.0)


def test_time_table_periodic_inexact_period():
    # 0 .. 0.7 s, period 0.7: breakpoints t_i + n*period are inexact in floating point; the
    # events must still change segment (the wrap rows: left 0.5, right 1.0)
    table = TABLE - [TABLE[0, 0], 0.0]
    m = chain(tab=TimeTable(table, extrapolation="periodic", timeScale=0.5))
    result = bg.simulate(m, stop_time=3.0, interval=0.05)
    close(result.meta["event_times"], [0.15, 0.4, 0.7, 0.85, 1.1, 1.4, 1.55, 1.8, 2.1, 2.25,
                                       2.5, 2.8, 2.95], 3.0)
    t, y = result.time, result["tab.y"]
    for k in pairs(result):
        if any(abs(t[k] - w) < 1e-9 for w in (0.7, 1.4, 2.1, 2.8)):
            close([y[k], y[k + 1]], [0.5, 1.0])
    far = np.abs(t[:, None] - np.arange(0.0, 3.01, 0.05)[None, :]).min(axis=1) < 1e-12
    times = table[:, 0] * 0.5
    exp = [table_reference(times, table[:, 1], tt, "linear", "periodic", "right")
           for tt in t]
    bps = np.array([0.15, 0.4, 0.7, 0.85, 1.1, 1.4, 1.55, 1.8, 2.1, 2.25, 2.5, 2.8, 2.95])
    away = far & (np.abs(t[:, None] - bps[None, :]).min(axis=1) > 1e-6)
    close(y[away], np.asarray(exp)[away], 2.0)


def test_time_table_periodic_starting_after_time_zero():
    m = chain(tab=TimeTable(TABLE, extrapolation="periodic", timeScale=0.5))
    result = bg.simulate(m, stop_time=1.0, interval=0.25)    # table times 0.1 .. 0.8
    close(result.meta["event_times"], [0.1, 0.25, 0.5, 0.8, 0.95])


def test_time_table_from_csv_by_column_name_and_index(tmp_path):
    path = tmp_path / "table.csv"
    rows = ["time,a,b"] + [f"{tt},{a},{b}" for tt, a, b in
                           [(0.0, 0.0, 5.0), (1.0, 1.0, 4.0), (2.0, 3.0, 4.0), (2.0, 0.0, -2.0),
                            (3.0, 1.0, 1.0)]]
    path.write_text("\n".join(rows) + "\n")
    data = np.array([[float(v) for v in r.split(",")] for r in rows[1:]])
    m = Component(name="Csv")
    m.add("a", TimeTable(str(path), column="a"))
    m.add("b", TimeTable(path, column=3, smoothness="hold", extrapolation="periodic"))
    result = bg.simulate(m, stop_time=5.0, interval=0.05)
    check_table(result, "a.y", data[:, 0], data[:, 1], "linear", "hold", [1.0, 2.0, 3.0])
    check_table(result, "b.y", data[:, 0], data[:, 2], "hold", "periodic",
                [1.0, 2.0, 3.0, 4.0, 5.0])
    with pytest.raises(ValueError, match="column"):
        TimeTable(path, column="c")
    with pytest.raises(ValueError, match="column"):
        TimeTable(TABLE, column=1)                        # column 1 is time
    with pytest.raises(ValueError, match="smoothness"):
        TimeTable(TABLE, smoothness="spline")
    with pytest.raises(ValueError, match="extrapolation"):
        TimeTable(TABLE, extrapolation="mirror")
