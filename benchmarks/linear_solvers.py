"""Linear solver of the Newton iterations against model size (the data behind
``linear_solver="auto"``, :mod:`bgmodelica.solver_options`).

The RC ladder (array-equation form, IDAS, 10 s, rtol = atol = 1e-6) at several sizes and the
robot (``RobotPID``, IDAS, 10 s, rtol 1e-6, atol 1e-8), each with every direct solver; best
of ``--repeat`` runs of ``simulate`` on the compiled model (integrator construction
included in the first run only, as in repeated use).

    python benchmarks/linear_solvers.py [--sizes 10 100 1000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bgmodelica import compile, simulate  # noqa: E402
from library.examples import RCLadderVector  # noqa: E402
from library.robots.robot import RobotPID  # noqa: E402

SOLVERS = ("qr", "csparse", "lapacklu")


def best(fn, repeat: int) -> float:
    fn()                                   # builds and caches the integrator
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main(sizes: list[int], repeat: int) -> dict:
    rows = {}
    for n in sizes:
        compiled = compile(RCLadderVector(n))
        out = [f"v[{n}]"]
        rows[f"ladder n={n}"] = {
            s: best(lambda s=s, c=compiled, o=out: simulate(c, stop_time=10.0, interval=0.01,
                                                          rtol=1e-6, atol=1e-6, outputs=o,
                                                          linear_solver=s), repeat)
            for s in SOLVERS if s != "lapacklu" or n <= 1000}
    robot = compile(RobotPID())
    rows["robot"] = {s: best(lambda s=s: simulate(robot, stop_time=10.0, interval=0.01,
                                                  rtol=1e-6, atol=1e-8, linear_solver=s),
                             repeat) for s in SOLVERS}
    print(f"{'model':16s}" + "".join(f"{s:>12s}" for s in SOLVERS) + "   [s, best of "
          f"{repeat}]")
    for name, row in rows.items():
        print(f"{name:16s}" + "".join(f"{row[s]:12.4f}" if s in row else f"{'-':>12s}"
                                      for s in SOLVERS))
    return rows


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="*", default=[10, 100, 1000, 10000])
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    main(a.sizes, a.repeat)
