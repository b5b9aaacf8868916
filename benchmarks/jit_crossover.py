"""When just-in-time compilation of the model functions pays off (``simulate(jit=True)``).

For the robot (``RobotPID``) and the RC ladder (array-equation form), measures in one run:
the first ``simulate`` with and without JIT (integrator construction, plus the C compilation
with JIT), the best of ``--repeat`` later runs of each (integrator cached), and from these
the crossover: the number of 10-s runs after which the JIT total is the smaller,
``ceil((first_jit - first_plain) / (run_plain - run_jit))``.

    python benchmarks/jit_crossover.py [--sizes 100 1000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bgmodelica import compile, simulate  # noqa: E402
from library.examples import RCLadderVector  # noqa: E402
from library.robots.robot import RobotPID  # noqa: E402


def measure(make, opts: dict, repeat: int) -> dict:
    out = {}
    for jit in (False, True):
        compiled = compile(make())          # a fresh model: no integrator cached yet
        t0 = time.perf_counter()
        res = simulate(compiled, jit=jit, **opts)
        first = time.perf_counter() - t0
        runs = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            simulate(compiled, jit=jit, **opts)
            runs.append(time.perf_counter() - t0)
        out[jit] = (first, min(runs), res)
    (f0, r0, a), (f1, r1, b) = out[False], out[True]
    gain = r0 - r1
    crossover = math.ceil((f1 - f0) / gain) if gain > 0 else float("inf")
    dev = max(float(abs(a[n] - b[n]).max()) for n in a.names[:3])
    return {"first_plain": f0, "first_jit": f1, "run_plain": r0, "run_jit": r1,
            "speedup": r0 / r1, "crossover_runs": crossover, "max_deviation": dev}


def main(sizes: list[int], repeat: int) -> dict:
    cases = {"robot": (RobotPID, dict(stop_time=10.0, interval=0.01, rtol=1e-6, atol=1e-8))}
    for n in sizes:
        cases[f"ladder n={n}"] = (lambda n=n: RCLadderVector(n),
                                  dict(stop_time=10.0, interval=0.01, rtol=1e-6, atol=1e-6,
                                       outputs=[f"v[{n}]"]))
    rows = {name: measure(make, opts, repeat) for name, (make, opts) in cases.items()}
    print(f"{'model':14s} {'first':>8s} {'first JIT':>10s} {'run':>8s} {'run JIT':>8s} "
          f"{'speedup':>8s} {'crossover':>10s}   [s; crossover in 10-s runs]")
    for name, r in rows.items():
        print(f"{name:14s} {r['first_plain']:8.3f} {r['first_jit']:10.3f} {r['run_plain']:8.4f} "
              f"{r['run_jit']:8.4f} {r['speedup']:8.2f} {r['crossover_runs']:>10}"
              f"   (max |JIT - plain| {r['max_deviation']:.1e})")
    return rows


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="*", default=[100, 1000])
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    main(a.sizes, a.repeat)
