"""Accuracy and cost independent of the output grid: the Cartesian pendulum (index 3, dynamic
state selection) over 5 s at default tolerances, on output intervals 0.1, 0.01 and 0.001 s.

Prints, per interval, the largest position error against the angle ODE integrated by scipy at
1e-13, the wall time, the number of state switches and the wall time relative to the 0.1 s
run (aims: error <= 1e-4 on every grid, the 1 ms run within 3x the 0.1 s run), then the error
at rtol 1e-10 (aim <= 1e-7).

    PYTHONPATH=. .venv/bin/python benchmarks/output_grid.py [--repeat N]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import bgmodelica as bg  # noqa: E402
from library.examples.constrained import Pendulum  # noqa: E402

STOP = 5.0


def error(res) -> float:
    ref = solve_ivp(lambda _t, s: [s[1], -9.81 * np.sin(s[0])], (0.0, STOP), [np.pi / 2, 0.0],
                    method="DOP853", rtol=1e-13, atol=1e-13, dense_output=True)
    th = ref.sol(res.time)[0]
    return max(np.max(np.abs(res["x"] - np.sin(th))), np.max(np.abs(res["y"] + np.cos(th))))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    compiled = bg.compile(Pendulum())
    bg.simulate(compiled, stop_time=STOP, interval=0.1)          # variants compiled once
    base = None
    print(f"Cartesian pendulum, {STOP} s, rtol 1e-6 (default), best of {args.repeat}")
    for interval in (0.1, 0.01, 0.001):
        best, res = np.inf, None
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            res = bg.simulate(compiled, stop_time=STOP, interval=interval)
            best = min(best, time.perf_counter() - t0)
        base = base or best
        print(f"  interval {interval:<6g} error {error(res):.2e}  wall {best:.3f} s  "
              f"({best / base:.2f}x the 0.1 s run)  switches {len(res.meta['state_switches'])}")
    res = bg.simulate(compiled, stop_time=STOP, interval=0.01, rtol=1e-10, atol=1e-12)
    print(f"  rtol 1e-10: error {error(res):.2e} (aim <= 1e-7)")


if __name__ == "__main__":
    main()
