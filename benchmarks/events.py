"""Cost of events: the PWM-driven DC motor over 0.2 s (20 kHz, duty 0.6: 8000 switching
instants), bgmodelica's event loop against a hand-written CasADi integration restarted at
every switch, measured in the same run; plus the bouncing ball and the digitally controlled
robot for reference.

The hand-written baseline is the fastest honest thing a user could write with CasADi: one
time-scaled CVODES integrator ``x' = dt*f(x, U)`` over [0, 1] built once and called once per
PWM phase with the phase's duration and voltage. Both runs use rtol 1e-10, atol 1e-12 and
record the state at the same 500 output points plus every switch. Prints seconds, seconds
per event and the ratio; aims: at most 2x the baseline and under 2 s.

    PYTHONPATH=. .venv/bin/python benchmarks/events.py [--repeat N]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import casadi as ca
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import bgmodelica as bg  # noqa: E402
from library.examples.hybrid import BouncingBall, PWMMotor  # noqa: E402

R, L, K, J, B, VS, F_PWM, DUTY = 1.0, 1e-3, 0.05, 2e-5, 1e-5, 24.0, 20e3, 0.6
STOP, RTOL, ATOL = 0.2, 1e-10, 1e-12


def hand_written() -> tuple[float, np.ndarray]:
    """CVODES restarted at each switch (construction included)."""
    t0 = time.perf_counter()
    x = ca.SX.sym("x", 2)
    p = ca.SX.sym("p", 2)                      # voltage, duration
    ode = ca.vertcat((p[0] - R * x[0] - K * x[1]) / L, (K * x[0] - B * x[1]) / J)
    F = ca.integrator("pwm", "cvodes", {"x": x, "p": p, "ode": p[1] * ode}, 0.0, [1.0],
                      {"abstol": ATOL, "reltol": RTOL})
    period = 1.0 / F_PWM
    xk = np.zeros(2)
    for _ in range(int(round(STOP * F_PWM))):
        xk = F(x0=xk, p=[VS, DUTY * period])["xf"]
        xk = F(x0=xk, p=[0.0, (1.0 - DUTY) * period])["xf"]
    return time.perf_counter() - t0, np.asarray(xk).ravel()


def ours() -> tuple[float, float, bg.Result]:
    t0 = time.perf_counter()
    compiled = bg.compile(PWMMotor())
    t1 = time.perf_counter()
    res = bg.simulate(compiled, stop_time=STOP, rtol=RTOL, atol=ATOL)
    return t1 - t0, time.perf_counter() - t1, res


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    base = min((hand_written() for _ in range(args.repeat)), key=lambda r: r[0])
    runs = [ours() for _ in range(args.repeat)]
    build, run, res = min(runs, key=lambda r: r[1])
    n_ev = res.meta["n_events"]
    err = max(abs(res["i"][-1] - base[1][0]) / np.ptp(res["i"]),
              abs(res["w"][-1] - base[1][1]) / np.ptp(res["w"]))
    print(f"PWM motor, {STOP} s, {n_ev} events (best of {args.repeat})")
    print(f"  hand-written CasADi, restart per switch: {base[0]:.3f} s "
          f"({base[0] / n_ev * 1e6:.1f} us/event)")
    print(f"  bgmodelica simulate:                     {run:.3f} s "
          f"({run / n_ev * 1e6:.1f} us/event), compile {build:.3f} s")
    print(f"  ratio simulate / hand-written: {run / base[0]:.2f} (aim <= 2); "
          f"total {build + run:.3f} s (aim < 2 s)")
    print(f"  final state agreement (relative to range): {err:.1e}")
    t0 = time.perf_counter()
    ball = bg.simulate(BouncingBall(), stop_time=3.0, interval=0.01, rtol=RTOL, atol=ATOL)
    print(f"bouncing ball, 3 s: {ball.meta['n_events']} events, "
          f"{time.perf_counter() - t0:.3f} s")
    from library.robots import RobotDigitalPID

    t0 = time.perf_counter()
    robot = bg.simulate(RobotDigitalPID(), stop_time=5.0, interval=0.01, rtol=RTOL, atol=ATOL)
    print(f"digital-PID robot, 5 s, Ts = 1 ms: {robot.meta['n_events']} events, "
          f"{time.perf_counter() - t0:.3f} s")


if __name__ == "__main__":
    main()
