"""Optimal control of the paper's robot: from hanging at rest to a pose at rest in 1 s with
the least energy, |U1|, |U2| <= 12 V (``bgmodelica optimize``, see docs/optimize.md).

Prints the wall time (compile included), the objective int U1^2 + U2^2 dt [V^2 s], the
re-simulation error (largest state deviation between the collocation trajectory and the
model simulated with the optimal voltages) and the distance of the re-simulated final pose
from the target [rad]. Targets: under 60 s, final error under 1e-3 rad.

    PYTHONPATH=. .venv/bin/python benchmarks/optimize_robot.py
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import bgmodelica as bg  # noqa: E402
from library.robots import RobotOpenLoop  # noqa: E402

INITIAL = {"arm.q1": -math.pi / 2, "arm.q2": 0.0, "arm.w1": 0.0, "arm.w2": 0.0,
           "motor1.i": 0.0, "motor2.i": 0.0}
FINAL = {"arm.q1": -1.0708, "arm.q2": 0.3, "arm.w1": 0.0, "arm.w2": 0.0}


def main() -> None:
    t0 = time.perf_counter()
    res = bg.optimize(RobotOpenLoop(), {"U1": (-12, 12), "U2": (-12, 12)}, initial=INITIAL,
                      final=FINAL, stop_time=1.0, lagrange="U1^2+U2^2")
    wall = time.perf_counter() - t0
    reached = res.final_values()
    pose = max(abs(reached[n] - FINAL[n]) for n in ("arm.q1", "arm.q2"))
    sol = res.solution
    print(f"robot min-energy move: {wall:.2f} s wall (target < 60 s), "
          f"{len(sol.trajectory.mesh) - 1} intervals after {len(res.history) - 1} "
          f"refinements, IPOPT {sol.status}")
    print(f"  objective int U1^2+U2^2 dt = {res.objective:.8g} V^2 s")
    print(f"  re-simulation error {res.resimulation_error:.3g}; final pose error "
          f"{pose:.3g} rad (target < 1e-3)")


if __name__ == "__main__":
    main()
