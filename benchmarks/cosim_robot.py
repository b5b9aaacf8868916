"""Co-simulation of the paper's PID robot against the monolithic model, and its cost.

Run: ``python benchmarks/cosim_robot.py [--steps 10e-3,5e-3,2e-3,1e-3,5e-4] [--stop-time 10]
[--coupling lumped|plain] [--plot verify.png] [--json verify.json] [--repeat 3]``.

1. ``verify_robot``: error per joint against ``RobotPID`` (IDAS, rtol 1e-10) for every macro
   step, Jacobi / Gauss-Seidel, with and without extrapolation, the observed order, a Model
   Exchange run, and the fmucontainer cross-check (same as ``bgmodelica verify``).
2. Wall-clock seconds per simulated second (best of ``--repeat``) at a 1 ms macro step: our
   master (Co-Simulation FMUs, both orders), the fmucontainer container (the same FMUs stepped
   by its C runtime, run by fmpy) and the monolithic model (IDAS, rtol 1e-6).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bgmodelica import compile, simulate  # noqa: E402
from bgmodelica.cosim.master import Master  # noqa: E402
from bgmodelica.cosim.xcheck import build_container, run_container  # noqa: E402
from library.robots.robot import RobotPID  # noqa: E402
from library.robots.subsystems import build_robot_fmus, robot_system  # noqa: E402
from library.robots.verification import verify_robot  # noqa: E402


def best_of(fn, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", default="10e-3,5e-3,2e-3,1e-3,5e-4")
    ap.add_argument("--stop-time", type=float, default=10.0)
    ap.add_argument("--coupling", choices=["lumped", "plain"], default="lumped")
    ap.add_argument("--plot", help="PNG: error vs macro step")
    ap.add_argument("--json", help="write the report as JSON")
    ap.add_argument("--repeat", type=int, default=3, help="timing repetitions (best of)")
    args = ap.parse_args()
    steps = [float(s) for s in args.steps.split(",")]

    with tempfile.TemporaryDirectory(prefix="bgm_bench_cosim_") as tmp:
        t0 = time.perf_counter()
        fmus = build_robot_fmus(Path(tmp) / "fmu", couplings=(args.coupling,))
        print(f"FMUs built in {time.perf_counter() - t0:.1f} s: {', '.join(fmus)}")
        report = verify_robot(steps, args.stop_time, coupling=args.coupling, fmus=fmus,
                              progress=lambda m: print(f"  .. {m}", file=sys.stderr))
        print(report.to_text())
        if args.plot:
            print(f"plot -> {report.plot(args.plot)}")
        if args.json:
            Path(args.json).write_text(json.dumps(report.to_dict(), indent=2) + "\n")
            print(f"json -> {args.json}")

        print(f"\nwall-clock seconds per simulated second (best of {args.repeat}, "
              f"{args.stop_time:g} s, macro step 1 ms):")
        system = robot_system(fmus, coupling=args.coupling)
        master = Master(system)
        T = args.stop_time
        rows = []
        for order in ("jacobi", "gauss-seidel"):
            sec = best_of(lambda o=order: master.simulate(T, 1e-3, order=o), args.repeat)
            rows.append((f"bgmodelica.cosim master, CS FMUs, {order}", sec / T))
        container = build_container(system, Path(tmp) / "container", step_size=1e-3)
        sec = best_of(lambda: run_container(container, T, 1e-3), args.repeat)
        rows.append(("fmucontainer (C runtime) via fmpy, jacobi", sec / T))
        compiled = compile(RobotPID())
        sec = best_of(lambda: simulate(compiled, stop_time=T, interval=1e-3, dynamic=False),
                      args.repeat)
        rows.append(("monolithic RobotPID, IDAS rtol 1e-6", sec / T))
        for name, value in rows:
            print(f"  {name:<48}{value:9.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
