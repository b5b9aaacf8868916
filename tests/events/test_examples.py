"""The hybrid acceptance examples against analytic or independently computed references
(closed forms, matrix exponentials, scipy integrations): bouncing ball, stick-slip, PWM motor,
the digitally controlled robot and the open-loop robot fed from a table with a jump."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import expm
from scipy.optimize import brentq

import bgmodelica as bg
from library.examples.hybrid import BouncingBall, PWMMotor, StickSlip

TIGHT = dict(rtol=1e-10, atol=1e-12)


# -- bouncing ball ------------------------------------------------------------------------------

def ball_reference(h0=1.0, v0=0.0, e=0.7, g=9.81, v_min=0.1):
    """Impact times and the flight pieces (t_start, h_start, v_start) of the ball."""
    t = (v0 + math.sqrt(v0 ** 2 + 2 * g * h0)) / g
    v_hit = v0 - g * t
    impacts, pieces = [t], [(0.0, h0, v0)]
    while e * abs(v_hit) >= v_min:
        v_up = -e * v_hit
        pieces.append((t, 0.0, v_up))
        t += 2 * v_up / g
        impacts.append(t)
        v_hit = -v_up
    pieces.append((t, 0.0, None))          # rest
    return impacts, pieces


def ball_height(t, pieces, g=9.81):
    out = np.zeros_like(t)
    for k, (ts, hs, vs) in enumerate(pieces):
        end = pieces[k + 1][0] if k + 1 < len(pieces) else np.inf
        sel = (t >= ts) & (t <= end)
        out[sel] = 0.0 if vs is None else hs + vs * (t[sel] - ts) - 0.5 * g * (t[sel] - ts) ** 2
    return out


def test_bouncing_ball_impacts_and_rest():
    res = bg.simulate(BouncingBall(), stop_time=3.0, interval=0.01, **TIGHT)
    impacts, pieces = ball_reference()
    events = np.array(res.meta["event_times"])
    assert len(events) == len(impacts) == 11          # rests at the 11th impact
    assert np.max(np.abs(events - impacts)) < 1e-8
    # left and right limits at each impact, then rest: h = v = 0, no more events
    k = int(np.nonzero(res.time == events[0])[0][0])
    assert res.time[k + 1] == events[0]
    assert res["v"][k] < -4.4 and res["v"][k + 1] == pytest.approx(0.7 * 4.4294469, rel=1e-6)
    assert np.all(res["h"][res.time > impacts[-1]] == 0.0)
    assert np.all(res["v"][res.time > impacts[-1]] == 0.0)
    assert res["flying"][-1] == 0.0
    # height everywhere within 1e-7 m (at event rows compare the right limits too)
    assert np.max(np.abs(res["h"] - ball_height(res.time, pieces))) < 1e-7


def test_bouncing_ball_on_a_fine_output_grid():
    """Thousands of output points between impacts: the first crossing is found in a late
    chunk of the stretch's indicators (the first impact near column 4,500), and the rows of
    a long stretch are evaluated at once; both agree with the flight pieces."""
    res = bg.simulate(BouncingBall(), stop_time=1.5, interval=1e-4, **TIGHT)
    impacts, pieces = ball_reference()
    events = np.array(res.meta["event_times"])
    expected = [t for t in impacts if t <= 1.5]
    assert len(events) == len(expected) and np.max(np.abs(events - expected)) < 1e-8
    assert len(res.time) == 15001 + 2 * len(expected)      # each event adds two rows
    assert np.max(np.abs(res["h"] - ball_height(res.time, pieces))) < 1e-7


def test_bouncing_ball_parameters_by_name():
    res = bg.simulate(BouncingBall(), stop_time=2.0, interval=0.01,
                      params={"h0": 2.0, "v0": 1.0, "e": 0.5}, **TIGHT)
    impacts, _ = ball_reference(h0=2.0, v0=1.0, e=0.5)
    n = len(res.meta["event_times"])
    assert n == len([t for t in impacts if t <= 2.0])
    assert np.max(np.abs(np.array(res.meta["event_times"]) - impacts[:n])) < 1e-8
    assert res["h"][0] == 2.0 and res["v"][0] == 1.0


# -- stick-slip ---------------------------------------------------------------------------------

def stick_slip_reference(t_end, m=1.0, F0=6.0, f=0.5, Fc=3.0, Fs=4.0):
    """Piecewise closed form: in each mode the motion under F0 sin(w t) - Fc*mode integrates
    exactly; mode changes at breakaway (|F| = Fs, asin) and at v = 0 (brentq)."""
    w = 2 * math.pi * f

    def motion(ta, xa, va, mode):
        def v(t):
            return va + F0 / (m * w) * (math.cos(w * ta) - math.cos(w * t)) \
                - Fc * mode * (t - ta) / m

        def x(t):
            return (xa + va * (t - ta) + F0 / (m * w) * (math.cos(w * ta) * (t - ta)
                    - (math.sin(w * t) - math.sin(w * ta)) / w)
                    - Fc * mode * (t - ta) ** 2 / (2 * m))
        return x, v

    pieces = []
    t, x0, v0, mode = 0.0, 0.0, 0.0, 0
    while t < t_end:
        if mode == 0:
            # next time |F0 sin(w t)| crosses Fs upward in magnitude
            a = math.asin(Fs / F0) / w
            period = 1 / f
            cands = []
            for k in range(int(t * f) - 1, int(t * f) + 3):
                for tc, sgn in ((k * period + a, 1), (k * period + period / 2 + a, -1)):
                    if tc > t + 1e-12:
                        cands.append((tc, sgn))
            tn, sgn = min(cands)
            pieces.append((t, min(tn, t_end), x0, 0.0, 0))
            t, v0, mode = tn, 0.0, sgn
            continue
        x, v = motion(t, x0, v0, mode)
        grid = np.linspace(t, t + 2.0, 4001)
        vals = np.array([v(s) for s in grid]) * mode
        idx = np.nonzero(vals[1:] < 0)[0]
        tn = brentq(v, grid[idx[0]], grid[idx[0] + 1], xtol=1e-15, rtol=1e-15) \
            if idx.size else np.inf
        pieces.append((t, min(tn, t_end), x0, v0, mode))
        if tn >= t_end:
            break
        x0 = x(tn)
        F = F0 * math.sin(w * tn)
        mode = 0 if abs(F) <= Fs else (1 if F > 0 else -1)
        t, v0 = tn, 0.0
    return pieces, motion


def test_stick_slip_against_piecewise_closed_form():
    res = bg.simulate(StickSlip(), stop_time=10.0, interval=0.01, **TIGHT)
    pieces, motion = stick_slip_reference(10.0)
    x_ref = np.empty_like(res.time)
    v_ref = np.empty_like(res.time)
    for i, t in enumerate(res.time):
        # at an event row pair, the left row belongs to the earlier piece
        left = i + 1 < len(res.time) and res.time[i + 1] == t
        for ta, tb, xa, va, mode in pieces:
            if ta <= t <= tb and not (left and t == ta and ta > 0) and not (
                    not left and t == tb and tb < 10.0 and i > 0 and res.time[i - 1] == t):
                if mode:
                    x, v = motion(ta, xa, va, mode)
                    x_ref[i], v_ref[i] = x(t), v(t)
                else:
                    x_ref[i], v_ref[i] = xa, 0.0
                break
    assert np.max(np.abs(res["x"] - x_ref)) < 1e-6
    assert np.max(np.abs(res["v"] - v_ref)) < 1e-6
    breakaways = [ta for ta, _, _, _, mode in pieces[1:] if mode != 0]
    assert set(np.round(breakaways, 8)) <= set(np.round(res.meta["event_times"], 8))


# -- PWM motor ----------------------------------------------------------------------------------

def test_pwm_motor_against_matrix_exponential():
    R, L, k, J, b, Vs, f, duty = 1.0, 1e-3, 0.05, 2e-5, 1e-5, 24.0, 20e3, 0.6
    stop = 0.01                                   # 200 periods, 400 switching instants
    res = bg.simulate(PWMMotor(), stop_time=stop, interval=1e-4, **TIGHT)
    assert res.meta["n_events"] == 400
    A = np.array([[-R / L, -k / L], [k / J, -b / J]])
    B = np.array([1 / L, 0.0])

    def step(x, h, u):
        E = expm(A * h)
        return E @ x + np.linalg.solve(A, (E - np.eye(2)) @ B) * u

    T = 1 / f
    x = np.zeros(2)
    ref_t, ref_x = [0.0], [x]
    for n in range(int(round(stop * f))):
        t0 = n * T
        on_end = t0 + duty * T
        # outputs inside the period
        for tk in res.time[(res.time > t0) & (res.time < t0 + T)]:
            u, base, tb = (Vs, x, t0) if tk < on_end else (0.0, step(x, duty * T, Vs), on_end)
            ref_t.append(tk)
            ref_x.append(step(base, tk - tb, u))
        x = step(step(x, duty * T, Vs), (1 - duty) * T, 0.0)
    ref = dict(zip(ref_t, ref_x, strict=False))
    ref[stop] = x
    i_rng = np.ptp(res["i"])
    w_rng = np.ptp(res["w"])
    worst_i = worst_w = 0.0
    for t, i_val, w_val in zip(res.time, res["i"], res["w"], strict=True):
        if t in ref:
            worst_i = max(worst_i, abs(i_val - ref[t][0]) / i_rng)
            worst_w = max(worst_w, abs(w_val - ref[t][1]) / w_rng)
    assert worst_i < 1e-6 and worst_w < 1e-6
    # the switching instants are exact
    ev = np.array(res.meta["event_times"])
    expected = np.sort(np.concatenate([np.arange(1, 201) * T, np.arange(200) * T + duty * T]))
    assert np.max(np.abs(ev - expected)) < 1e-15


# -- the robot under digital control and the open-loop robot fed from a table -----------------

def _plant_rhs(u, arm, motor):
    from library.robots import lagrange

    R, L, k1, Jm, b, k2 = (motor[n] for n in ("R", "L", "k1", "Jm", "b", "k2"))

    def f(_t, x):
        q, w, cur = x[0:2], x[2:4], x[4:6]
        M = lagrange.mass_matrix(q, arm) + Jm * k2 ** 2 * np.eye(2)
        rhs = (k1 * k2 * cur - b * k2 ** 2 * w - lagrange.coriolis_matrix(q, w, arm) @ w
               - lagrange.gravity_vector(q, arm))
        return np.concatenate([w, np.linalg.solve(M, rhs), (u - R * cur - k1 * k2 * w) / L])

    return f


def test_robot_digital_pid_against_sampled_recurrence():
    from library.robots import RobotDigitalPID
    from library.robots.params import ARM, MOTOR, PID, REFERENCE, VMAX

    Ts, stop = 2e-3, 0.3
    res = bg.simulate(RobotDigitalPID(), stop_time=stop, interval=0.01,
                      params={"Ts": Ts}, **TIGHT)
    gains = [(PID["Kp1"], PID["Ki1"], PID["Kd1"]), (PID["Kp2"], PID["Ki2"], PID["Kd2"])]
    ref = [(REFERENCE["A1"], REFERENCE["f1"]), (REFERENCE["A2"], REFERENCE["f2"])]
    x = np.zeros(6)
    I = np.zeros(2)
    e_prev = None
    states = {0.0: x}
    volts = {}
    n = int(round(stop / Ts))
    for k in range(n):
        tk = k * Ts
        e = np.array([A * math.sin(2 * math.pi * f * tk) for A, f in ref]) - x[:2]
        I = I + Ts * e
        D = np.zeros(2) if e_prev is None else (e - e_prev) / Ts
        e_prev = e
        u = np.array([np.clip(kp * e[j] + ki * I[j] + kd * D[j], -VMAX, VMAX)
                      for j, (kp, ki, kd) in enumerate(gains)])
        volts[round(tk, 12)] = u
        sol = solve_ivp(_plant_rhs(u, ARM, MOTOR), (tk, tk + Ts), x, method="DOP853",
                        rtol=1e-12, atol=1e-13)
        x = sol.y[:, -1]
        states[round(tk + Ts, 12)] = x
    # compare at the sample instants (right limits; the states are continuous)
    worst_q = worst_i = 0.0
    for t, q1, q2, i1, i2 in zip(res.time, res["arm.q1"], res["arm.q2"], res["motor1.i"],
                                 res["motor2.i"], strict=True):
        key = round(t, 12)
        if key in states:
            xs = states[key]
            worst_q = max(worst_q, abs(q1 - xs[0]), abs(q2 - xs[1]))
            worst_i = max(worst_i, abs(i1 - xs[4]), abs(i2 - xs[5]))
    assert worst_q < 1e-6 and worst_i < 1e-6
    # the held voltage equals the recurrence's u_k right after t_k
    t = res.time
    for key, u in list(volts.items())[1::10]:
        right = np.nonzero(t == key)[0]
        if right.size:
            assert res["motor1.u"][right[-1]] == pytest.approx(u[0], abs=1e-6)
            assert res["motor2.u"][right[-1]] == pytest.approx(u[1], abs=1e-6)


def test_open_loop_robot_from_csv_table_with_jump(tmp_path):
    from library.robots import RobotOpenLoop
    from library.robots.params import ARM, MOTOR

    csv = tmp_path / "u.csv"
    csv.write_text("time,U1,U2\n0,0,0\n0.2,4,-2\n0.5,4,-2\n0.5,-3,1\n1.0,2,2\n")
    res = bg.simulate(RobotOpenLoop(), stop_time=1.2, interval=0.01, inputs=csv,
                      dynamic=False, **TIGHT)
    assert 0.5 in res.meta["event_times"]

    def u_of(t):
        tt = [0, 0.2, 0.5, 0.5, 1.0]
        u1, u2 = [0, 4, 4, -3, 2], [0, -2, -2, 1, 2]
        if t >= 1.0:
            return np.array([2.0, 2.0])
        if t < 0.5:
            return np.array([np.interp(t, tt[:3], u1[:3]), np.interp(t, tt[:3], u2[:3])])
        return np.array([np.interp(t, tt[3:], u1[3:]), np.interp(t, tt[3:], u2[3:])])

    base = _plant_rhs(np.zeros(2), ARM, MOTOR)

    def rhs(t, x):
        out = base(t, x)
        out[4:6] += u_of(t) / MOTOR["L"]
        return out

    x = np.zeros(6)
    got = {}
    for a, b in ((0.0, 0.2), (0.2, 0.5), (0.5, 1.0), (1.0, 1.2)):
        pts = res.time[(res.time >= a) & (res.time <= b)]
        sol = solve_ivp(rhs, (a, b), x, method="DOP853", rtol=1e-12, atol=1e-13,
                        t_eval=np.unique(pts))
        for t, col in zip(sol.t, sol.y.T, strict=True):
            got[t] = col
        x = sol.y[:, -1]
    worst = max(max(abs(q1 - got[t][0]), abs(q2 - got[t][1]))
                for t, q1, q2 in zip(res.time, res["q1"], res["q2"], strict=True))
    assert worst < 1e-6
    # the jump: left and right limits of the input at t = 0.5
    k = np.nonzero(res.time == 0.5)[0]
    assert len(k) == 2
    assert res["motor1.u"][k[0]] == pytest.approx(4.0) and res["motor1.u"][k[1]] == \
        pytest.approx(-3.0)


def test_pendulum_against_wall_high_index_with_impacts():
    """Index-3 Cartesian pendulum hitting a wall, against the angle ODE with scipy events."""
    from library.examples.hybrid import PendulumWall

    res = bg.simulate(PendulumWall(), stop_time=5.0, interval=0.01, **TIGHT)
    assert np.max(np.abs(res["x"] ** 2 + res["y"] ** 2 - 1.0)) < 1e-8

    def wall(_t, s):
        return math.sin(s[0]) + 0.3
    wall.terminal, wall.direction = True, -1
    t, s, impacts = 0.0, [math.asin(0.6), 0.0], []
    while True:
        sol = solve_ivp(lambda _t, s: [s[1], -9.81 * math.sin(s[0])], (t, 5.0), s,
                        events=wall, rtol=1e-12, atol=1e-13, method="DOP853")
        if not sol.t_events[0].size:
            break
        t = sol.t_events[0][0]
        impacts.append(t)
        s = [sol.y_events[0][0][0], -0.8 * sol.y_events[0][0][1]]
    fired = [t for k, t in enumerate(res.meta["event_times"])
             if k == 0 or t - res.meta["event_times"][k - 1] > 1e-9]
    assert len(fired) == len(impacts) == 3
    assert np.max(np.abs(np.array(fired) - impacts)) < 1e-7
