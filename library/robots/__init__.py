"""The paper's robot end to end: Baghli & El Bakkali (2014), a two-link planar arm driven by
two armature-controlled DC motors through gears, under per-joint PID or computed-torque control.

Modules:

- :mod:`.lagrange`: the paper's closed-form M(q), C(q, q'), G(q) (Eq. 8/11), numpy or CasADi;
- :mod:`.params`: default parameters and where they come from;
- :mod:`.motor`: :class:`~.motor.DCMotor`, the geared DC motor in component form;
- :mod:`.arm`: :class:`~.arm.TwoLinkArm` in multibody form (:mod:`library.planar`) and
  :class:`~.arm.ArmWithTorques` (joint torques as model inputs);
- :mod:`.robot`: :class:`~.robot.RobotPID` (Fig. 13-15), :class:`~.robot.RobotComputedTorque`
  (Fig. 12) and :func:`~.robot.arm_dynamics_functions` (M, C, G extracted from the compiled
  multibody arm);
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
