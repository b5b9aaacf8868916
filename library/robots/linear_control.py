"""The robot as a control engineer sees it: operating point, linear model, poles, Bode plot,
structural vs numeric controllability, and a per-joint PID tuned on the linear model then
simulated on the nonlinear robot.

- :func:`holding_voltages`: the constant motor voltages that hold the arm at a pose
  (at rest, ``k2 k1 U / R = G(q)``).
- :func:`linear_model`: :func:`bgmodelica.linearize` of :class:`~.robot.RobotOpenLoop` at the
  steady state reached with those voltages (start values only as guesses).
- :func:`tune_pid`: one PID per joint, by loop shaping on the diagonal channels of the linear
  model (python-control): crossover ``wc``, phase lead from the derivative; checked on the
  full 2x2 linear closed loop.
- :class:`RobotJointPID`: the nonlinear robot under those PIDs, tracking a smooth step
  ``q0 + dq (1 - exp(-t/Tr))`` from the pose (simulated with ``init="steady-state"``: the
  integrators start at the holding voltages).
- :func:`run`: all of it, with the figures of the README (``docs/figures/``).

``python -m library.robots.linear_control [OUTDIR]`` writes the figures and prints the numbers.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import numpy as np

from bgmodelica import Component, Parameter, Variable, connect, der, exp, time

from .lagrange import gravity_vector
from .motor import DCMotor
from .params import MOTOR
from .robot import _RobotArm

__all__ = ["POSE", "holding_voltages", "linear_model", "tune_pid", "RobotJointPID", "run"]

#: the operating pose of the README [rad]: link 1 at -1 rad (57 degrees below the horizontal),
#: link 2 bent by 0.6 rad
POSE = (-1.0, 0.6)


def holding_voltages(q=POSE, motor: dict[str, float] | None = None) -> np.ndarray:
    """Motor voltages [V] that hold the arm at rest at pose ``q``: U = R G(q) / (k1 k2)."""
    m = {**MOTOR, **(motor or {})}
    return m["R"] * gravity_vector(np.asarray(q, float)) / (m["k1"] * m["k2"])


def linear_model(q=POSE, guess_offset: float = 0.2):
    """The :class:`~bgmodelica.analysis.Linearization` of RobotOpenLoop at the steady state
    with the holding voltages of pose ``q`` (the start values, ``guess_offset`` away from
    the pose, are only guesses)."""
    from bgmodelica.analysis import linearization

    from .robot import RobotOpenLoop

    U = holding_voltages(q)
    return linearization(RobotOpenLoop(), {"U1": U[0], "U2": U[1],
                                           "arm.q1": q[0] + guess_offset,
                                           "arm.q2": q[1] - guess_offset}, steady_state=True)


def _pid_tf(kp: float, ki: float, kd: float, tf: float):
    import control

    s = control.tf("s")
    return kp + ki / s + kd * s / (tf * s + 1)


def tune_pid(lin, wc: float = 25.0, ti_factor: float = 4.0, td_factor: float = 0.25,
             n_filter: float = 10.0) -> dict[str, Any]:
    """Per-joint PID ``Kp + Ki/s + Kd s/(Tf s + 1)`` by loop shaping on the diagonal channel
    ``U_i -> q_i`` of ``lin``: Ti = ti_factor/wc, Td = td_factor/wc, Tf = Td/n_filter, and Kp
    such that the loop gain is 1 at ``wc`` [rad/s]. Returns the gains, each loop's phase
    margin and crossover, and the closed-loop poles of the full 2x2 linear model."""
    import control

    plant = lin.ss()
    gains: dict[str, Any] = {}
    ctrls = []
    for k in range(2):
        g = lin.frequency_response([wc])[0, k, k]
        ti, td = ti_factor / wc, td_factor / wc
        tf_ = td / n_filter
        shape = _pid_tf(1.0, 1.0 / ti, td, tf_)
        kp = 1.0 / abs(g * complex(shape(1j * wc)))
        c = _pid_tf(kp, kp / ti, kp * td, tf_)
        siso = control.ss(lin.A, lin.B[:, [k]], lin.C[[k], :], lin.D[[k]][:, [k]])
        gm, pm, _, wpc = control.margin(control.ss2tf(siso) * c)[:4]
        j = k + 1
        gains.update({f"Kp{j}": kp, f"Ki{j}": kp / ti, f"Kd{j}": kp * td, f"Tf{j}": tf_})
        gains[f"phase_margin{j}"] = float(pm)
        gains[f"crossover{j}"] = float(wc)
        ctrls.append(control.ss(c))
    K = control.append(*ctrls)
    P = control.ss(plant.A, plant.B, plant.C, plant.D)
    closed = control.feedback(P * K, np.eye(2))
    gains["closed_loop"] = closed
    gains["closed_loop_poles"] = np.sort_complex(closed.poles())
    return gains


class _JointPID(Component):
    """``u = Kp e + Ki I + Kd (e - D)/Tf`` with ``I' = e`` and ``Tf D' = e - D``: the transfer
    function ``Kp + Ki/s + Kd s/(Tf s + 1)`` from the error e = r - q [rad] to u [V]."""

    Kp = Parameter(100.0, unit="V/rad", description="Proportional gain")
    Ki = Parameter(100.0, unit="V/(rad.s)", description="Integral gain")
    Kd = Parameter(2.0, unit="V.s/rad", description="Derivative gain")
    Tf = Parameter(0.0025, unit="s", description="Derivative filter time constant")
    e = Variable(unit="rad", description="Tracking error")
    I = Variable(unit="rad.s", start=0.0, description="Integral of the error")  # noqa: E741
    D = Variable(unit="rad", start=0.0, description="Filtered error (derivative filter)")
    u = Variable(unit="V", description="Command (motor voltage)")

    def equations(self):
        yield der(self.I) == self.e
        yield self.Tf * der(self.D) == self.e - self.D
        yield self.u == self.Kp * self.e + self.Ki * self.I + self.Kd * (self.e - self.D) / self.Tf


class RobotJointPID(_RobotArm):
    """The robot (arm + geared DC motors, as :class:`~.robot.RobotOpenLoop`) under one PID per
    joint (:func:`tune_pid`), tracking ``q_i* = q0_i + dq_i (1 - exp(-t/Tr))``.

    Parameters: the arm's and motors' (as RobotOpenLoop); pid1.Kp, pid1.Ki, pid1.Kd, pid1.Tf
    and pid2.* (PID, [V/rad], [V/(rad.s)], [V.s/rad], [s]); q01, q02 [rad] (start pose), dq1,
    dq2 [rad] (step), Tr [s] (reference time constant). Variables: ref1, ref2 [rad], pid1.u,
    pid2.u [V]; joint angles arm.q1, arm.q2. Simulate with ``init="steady-state"``: at t = 0
    the reference is the pose, the integrators hold the arm.
    """

    q01 = Parameter(POSE[0], unit="rad", description="Start pose, joint 1")
    q02 = Parameter(POSE[1], unit="rad", description="Start pose, joint 2")
    dq1 = Parameter(0.1, unit="rad", description="Reference step, joint 1")
    dq2 = Parameter(-0.1, unit="rad", description="Reference step, joint 2")
    Tr = Parameter(0.05, unit="s", description="Reference time constant")
    ref1 = Variable(unit="rad", description="Reference of joint 1")
    ref2 = Variable(unit="rad", description="Reference of joint 2")

    def _build(self) -> None:
        self.motor1 = DCMotor()
        self.motor2 = DCMotor()
        self.pid1 = _JointPID()
        self.pid2 = _JointPID()

    def equations(self):
        yield self.ref1 == self.q01 + self.dq1 * (1 - exp(-time / self.Tr))
        yield self.ref2 == self.q02 + self.dq2 * (1 - exp(-time / self.Tr))
        yield self.pid1.e == self.ref1 - self.arm.q1
        yield self.pid2.e == self.ref2 - self.arm.q2
        yield self.motor1.u == self.pid1.u
        yield self.motor2.u == self.pid2.u
        yield connect(self.motor1.flange, self.arm.flange1)
        yield connect(self.motor2.flange, self.arm.flange2)


def run(outdir: str | Path = "docs/figures", dq=(0.1, -0.1), t_end: float = 1.5,
        quiet: bool = False) -> dict[str, Any]:
    """Linear model at :data:`POSE`, Bode plot, structural-vs-numeric table, PID tuned on the
    linear model and simulated on the nonlinear robot; figures into ``outdir``."""
    import control
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    import bgmodelica as bg
    from bgmodelica.analysis import controllability, observability
    from bgmodelica.analysis.compare import compare_bond_graph
    from bgmodelica.analysis.plots import bode_plot
    from library.bondgraph.paper import TwoLinkManipulator

    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    lin = linear_model()
    pt = lin.point
    ctrb = controllability(lin.A, lin.B)
    obsv = observability(lin.A, lin.C)
    bode = bode_plot(lin, out / "robot_bode.png", omega=np.logspace(-3, 4, 500),
                     title=f"RobotOpenLoop at q = ({POSE[0]:g}, {POSE[1]:g}) rad held by "
                           f"U = ({pt['U1']:.4f}, {pt['U2']:.4f}) V")
    bgm = TwoLinkManipulator()
    cmp = compare_bond_graph(bgm, bg.compile(bgm))
    pid = tune_pid(lin)
    params = {k: pid[k] for k in ("Kp1", "Ki1", "Kd1", "Tf1", "Kp2", "Ki2", "Kd2", "Tf2")}
    sim_params = {f"pid{k[-1]}.{k[:-1]}": v for k, v in params.items()}
    sim_params.update({"dq1": dq[0], "dq2": dq[1], "arm.q1": POSE[0] + 0.1,
                       "arm.q2": POSE[1] - 0.1})
    res = bg.simulate(RobotJointPID(), stop_time=t_end, interval=t_end / 600,
                      params=sim_params, init="steady-state", rtol=1e-9, atol=1e-11)
    T = res.time
    tr = 0.05
    r = np.vstack([dq[0] * (1 - np.exp(-T / tr)), dq[1] * (1 - np.exp(-T / tr))])
    lin_resp = control.forced_response(pid["closed_loop"], T, r)
    y_lin = np.asarray(lin_resp.outputs)
    y_nl = np.vstack([res["arm.q1"] - POSE[0], res["arm.q2"] - POSE[1]])
    dev = np.max(np.abs(y_nl - y_lin), axis=1)
    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for k, ax in enumerate(axes):
        ax.plot(T, r[k] + POSE[k], "k:", label="reference")
        ax.plot(T, y_nl[k] + POSE[k], label="nonlinear robot (bgmodelica)")
        ax.plot(T, y_lin[k] + POSE[k], "--", label="linear model (python-control)")
        ax.set_ylabel(f"q{k + 1} [rad]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    axes[-1].set_xlabel("time [s]")
    axes[0].set_title(f"PID tuned on the linear model: step of ({dq[0]:+g}, {dq[1]:+g}) rad "
                      "from the pose")
    fig.tight_layout()
    step_fig = out / "robot_pid_step.png"
    fig.savefig(step_fig, dpi=120)
    plt.close(fig)
    summary = {
        "pose": [pt["q1"], pt["q2"]], "voltages": [pt["U1"], pt["U2"]],
        "eigenvalues": lin.eigenvalues, "controllability_rank": ctrb.rank,
        "observability_rank": obsv.rank, "structural": cmp, "pid": params | {
            "phase_margin1": pid["phase_margin1"], "phase_margin2": pid["phase_margin2"]},
        "closed_loop_poles": pid["closed_loop_poles"], "max_linear_vs_nonlinear": dev,
        "max_step": np.max(np.abs(y_nl), axis=1), "figures": [bode, step_fig],
    }
    if not quiet:
        print(f"pose q = ({pt['q1']:.12g}, {pt['q2']:.12g}) rad held by U = "
              f"({pt['U1']:.6g}, {pt['U2']:.6g}) V")
        print("poles: " + ", ".join(f"{v.real:.6g}{v.imag:+.6g}j" for v in lin.eigenvalues))
        print(f"numeric ranks: controllability {ctrb.rank}/{ctrb.n}, observability "
              f"{obsv.rank}/{obsv.n}")
        print(cmp.to_text())
        print("PID: " + ", ".join(f"{k} = {v:.4g}" for k, v in params.items()
                                  if k[0] in "KT") + f"; phase margins "
              f"{pid['phase_margin1']:.1f}, {pid['phase_margin2']:.1f} deg")
        print("closed-loop poles: " + ", ".join(f"{v.real:.4g}{v.imag:+.4g}j"
                                                for v in pid["closed_loop_poles"]))
        print(f"step response, nonlinear vs linear: max difference {dev[0]:.3g}, "
              f"{dev[1]:.3g} rad (step {dq[0]:+g}, {dq[1]:+g} rad)")
        print("figures: " + ", ".join(map(str, summary["figures"])))
    return summary


if __name__ == "__main__":
    run(sys.argv[1] if len(sys.argv) > 1 else "docs/figures")
