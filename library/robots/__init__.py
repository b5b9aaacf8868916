"""The paper's robot end to end: Baghli & El Bakkali (2014), a two-link planar arm driven by
two armature-controlled DC motors through gears, under per-joint PID or computed-torque control.

Modules:

- :mod:`.lagrange`: the paper's closed-form M(q), C(q, q'), G(q) (Eq. 8/11), numpy or CasADi;
- :mod:`.params`: default parameters and where they come from;
- :mod:`.motor`: :class:`~.motor.DCMotor`, the geared DC motor in component form;
- :mod:`.arm`: :class:`~.arm.TwoLinkArm` in multibody form (:mod:`library.planar`) and
  :class:`~.arm.ArmWithTorques` (joint torques as model inputs);
- :mod:`.robot`: :class:`~.robot.RobotPID` (Fig. 13-15), :class:`~.robot.RobotComputedTorque`
  (Fig. 12), :class:`~.robot.RobotOpenLoop` (the plant: motor voltages in, joint angles out)
  and :func:`~.robot.arm_dynamics_functions` (M, C, G extracted from the compiled multibody
  arm);
- :mod:`.baseline`: the hand-written robot ODE used by tests and benchmarks;
- :mod:`.main_job`: ``run(outdir)``: the 10 s PID simulation, CSV, figures, summary.

Compilation notes. The multibody arm is a structurally index-3 DAE (Cartesian frame
coordinates tied by the joints); Pantelides differentiates the position constraints twice and
the dummy-derivative selection, honouring ``state_select=PREFER`` on the joint coordinates,
keeps q1, q2, w1, w2 as states. The accelerations and constraint forces form one linear
algebraic loop (43 unknowns in the PID robot) that tearing + symbolic solution turns into
explicit assignments: the simulated system is an ODE (no algebraic variables). Structure
leaves a choice at the dummy-derivative levels, so the simulator's *dynamic* state selection
would check it at every output point; for this open chain the joint coordinates are valid
everywhere, so the robot simulations here pass ``dynamic=False``.
"""

from __future__ import annotations

import importlib
from typing import Any

#: The models, importable as ``library.robots:RobotPID`` etc. (loaded on first use, so that
#: ``library.robots.lagrange`` stays importable without CasADi or the component library).
_EXPORTS = {"RobotPID": ".robot", "RobotOpenLoop": ".robot", "RobotComputedTorque": ".robot",
            "RobotDigitalPID": ".digital", "DigitalJointPID": ".digital",
            "TwoLinkArm": ".arm", "ArmWithTorques": ".arm", "DCMotor": ".motor",
            "RobotJointPID": ".linear_control"}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        return getattr(importlib.import_module(_EXPORTS[name], __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))
