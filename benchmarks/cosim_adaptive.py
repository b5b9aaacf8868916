"""Adaptive vs fixed macro steps on the robot's split (Arm, Motor, Controller FMUs).

Run: ``python benchmarks/cosim_adaptive.py [--stop-time 2] [--target 1e-5]
[--steps 1e-3,5e-4,2e-4,1e-4,5e-5] [--tolerances 1e-3,1e-4,1e-5,1e-6] [--json out.json]``.

The reference is the monolithic ``RobotPID`` (IDAS, rtol 1e-10). Every run is Jacobi with
linearly extrapolated inputs and the FMUs' embedded solvers at tolerance 1e-10; the error is
max |q_cosim - q_ref| over both joints at the communication points. Printed: macro steps
(accepted / rejected for the adaptive runs), rounds of FMU steps (each steps every FMU once),
error and wall time; then the largest fixed step meeting ``--target`` against the adaptive
run meeting it with the fewest macro steps.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bgmodelica import compile, simulate  # noqa: E402
from bgmodelica.cosim.adaptive import cosimulate_adaptive  # noqa: E402
from bgmodelica.cosim.master import Master  # noqa: E402
from library.robots.robot import RobotPID  # noqa: E402
from library.robots.subsystems import build_robot_fmus, robot_system  # noqa: E402

JOINTS = ("arm.q1", "arm.q2")
SOLVER = 1e-10


def _error(res, ref) -> float:
    worst = 0.0
    for q in JOINTS:
        exact = np.interp(res.time, ref.time, ref[q])
        worst = max(worst, float(np.max(np.abs(res[q] - exact))))
    return worst


def run(stop_time: float, steps: list[float], tolerances: list[float], target: float,
        work: Path) -> dict:
    fmus = build_robot_fmus(work / "fmu")
    system = robot_system(dict(fmus))
    tol = {el: {"solver.tolerance": SOLVER} for el in system.element_names}
    ref = simulate(compile(RobotPID()), stop_time=stop_time, interval=1e-4, rtol=1e-10,
                   atol=1e-12, dynamic=False)
    rows = []
    for h in steps:
        t0 = time.perf_counter()
        res = Master(system).simulate(stop_time, h, extrapolation=True, parameters=tol)
        rows.append({"method": "fixed", "step": h, "macro_steps": res.meta["steps"],
                     "rejected": 0, "step_rounds": res.meta["steps"],
                     "error": _error(res, ref), "seconds": time.perf_counter() - t0})
    for rtol in tolerances:
        t0 = time.perf_counter()
        res = cosimulate_adaptive(system, stop_time, rtol, parameters=tol)
        m = res.meta
        rows.append({"method": "adaptive", "tolerance": rtol,
                     "macro_steps": m["communication_points"], "accepted": m["steps_accepted"],
                     "rejected": m["steps_rejected"], "step_rounds": m["step_rounds"],
                     "error": _error(res, ref), "seconds": time.perf_counter() - t0})
    fixed_ok = [r for r in rows if r["method"] == "fixed" and r["error"] <= target]
    adapt_ok = [r for r in rows if r["method"] == "adaptive" and r["error"] <= target]
    best_fixed = min(fixed_ok, key=lambda r: r["macro_steps"]) if fixed_ok else None
    best_adapt = min(adapt_ok, key=lambda r: r["macro_steps"]) if adapt_ok else None
    return {"stop_time": stop_time, "target": target, "rows": rows,
            "best_fixed": best_fixed, "best_adaptive": best_adapt}


def table(report: dict) -> str:
    lines = ["| method | macro steps | rejected | FMU step rounds | max error q [rad] | "
             "wall [s] |", "|---|---:|---:|---:|---:|---:|"]
    for r in report["rows"]:
        what = f"fixed H = {r['step']:g} s" if r["method"] == "fixed" else \
            f"adaptive, tol {r['tolerance']:g}"
        lines.append(f"| {what} | {r['macro_steps']} | {r['rejected']} | {r['step_rounds']} | "
                     f"{r['error']:.2e} | {r['seconds']:.2f} |")
    return "\n".join(lines)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--stop-time", type=float, default=2.0)
    ap.add_argument("--target", type=float, default=1e-5)
    ap.add_argument("--steps", default="1e-3,5e-4,2e-4,1e-4")
    ap.add_argument("--tolerances", default="1e-3,1e-4,1e-5,1e-6")
    ap.add_argument("--json", help="write the report as JSON")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="bgm_bench_adaptive_") as tmp:
        report = run(args.stop_time, [float(s) for s in args.steps.split(",")],
                     [float(s) for s in args.tolerances.split(",")], args.target, Path(tmp))
    print(f"robot split, {args.stop_time:g} s, Jacobi + extrapolation, target "
          f"{args.target:g} rad")
    print(table(report))
    bf, ba = report["best_fixed"], report["best_adaptive"]
    if bf and ba:
        print(f"target met with {ba['macro_steps']} adaptive macro steps vs {bf['macro_steps']} "
              f"fixed ({bf['macro_steps'] / ba['macro_steps']:.1f}x fewer); FMU step rounds "
              f"{ba['step_rounds']} vs {bf['step_rounds']}")
    else:
        print("target not met by " + ("the fixed steps" if not bf else "the adaptive runs"))
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
