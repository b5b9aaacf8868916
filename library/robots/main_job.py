"""Main job: the paper's PID-controlled two-link robot (Baghli & El Bakkali 2014, Fig. 13-15).

``run(outdir)`` compiles :class:`~library.robots.robot.RobotPID`, simulates 10 s, and writes

- ``robot.csv``: time, references, joint angles/speeds, tracking errors, motor voltages and
  currents, tip position;
- ``fig14_joint1.png``, ``fig15_joint2.png``: reference vs output per joint (paper style);
- ``tracking_error.png``: q* - q per joint;
- ``motors.png``: motor voltages and currents;
- ``digital_pid.png``: the robot under a sampled PID (:class:`~library.robots.RobotDigitalPID`,
  Ts = 1 ms, zero-order hold) beside the continuous PID: joint angles and the held voltage;
- ``summary.json``: the returned summary (max tracking error per joint after 1 s, compile
  and run times, states, solver statistics).

``python -m library.robots.main_job [OUTDIR]`` runs it from the command line.
"""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

STOP_TIME = 10.0
INTERVAL = 0.005
SETTLE = 1.0          # tracking errors are reported after this time [s]

CSV_COLUMNS = ["ref1.q", "arm.q1", "ref2.q", "arm.q2", "e1", "e2", "arm.w1", "arm.w2",
               "motor1.u", "motor2.u", "motor1.i", "motor2.i", "arm.rod2.frame_b.x",
               "arm.rod2.frame_b.y"]


def simulate_robot(stop_time: float = STOP_TIME, interval: float = INTERVAL,
                   params: dict[str, float] | None = None, **options: Any):
    """Compile and simulate the PID robot; return ``(compiled, result, compile_seconds)``.

    Joint coordinates are valid states everywhere for this open chain, so the dynamic state
    selection of the simulator is switched off (``dynamic=False``, see the module notes of
    :mod:`library.robots`); ``options`` go to :func:`bgmodelica.simulate`.
    """
    from bgmodelica import compile, simulate

    from .robot import RobotPID

    t0 = time.perf_counter()
    compiled = compile(RobotPID())
    build = time.perf_counter() - t0
    options.setdefault("dynamic", False)
    result = simulate(compiled, stop_time=stop_time, interval=interval, params=params,
                      **options)
    return compiled, result, build


def _figures(res, outdir: Path) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = res.time
    paths = []
    for j, (fig_no, title) in enumerate((("14", "PID 1 - First Link"),
                                         ("15", "PID 2 - Second Link")), start=1):
        fig, ax = plt.subplots(figsize=(7, 4.2))
        ax.plot(t, res[f"ref{j}.q"], "b-", lw=1.4, label="ref")
        ax.plot(t, res[f"arm.q{j}"], "r--", lw=1.4, label="Output")
        ax.set_xlim(0, t[-1])
        ax.set_ylim(-2, 2)
        ax.set_xlabel("Time [sec]")
        ax.set_ylabel("Input/Output response [rad]")
        ax.set_title(f"{title} (paper Fig. {fig_no})")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right")
        fig.tight_layout()
        path = outdir / f"fig{fig_no}_joint{j}.png"
        fig.savefig(path, dpi=120)
        plt.close(fig)
        paths.append(path)

    fig, ax = plt.subplots(figsize=(7, 4.2))
    for j, style in ((1, "b-"), (2, "r-")):
        ax.plot(t, 1e3 * res[f"e{j}"], style, lw=1.2, label=f"joint {j}: q{j}* - q{j}")
    ax.axvline(SETTLE, color="k", lw=0.8, ls=":")
    ax.set_xlim(0, t[-1])
    ax.set_xlabel("Time [sec]")
    ax.set_ylabel("tracking error [mrad]")
    ax.set_title("Tracking error (PID)")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper right")
    fig.tight_layout()
    path = outdir / "tracking_error.png"
    fig.savefig(path, dpi=120)
    plt.close(fig)
    paths.append(path)

    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    vmax = res.parameters.get("Vmax")
    for j, style in ((1, "b-"), (2, "r-")):
        ax1.plot(t, res[f"motor{j}.u"], style, lw=1.2, label=f"motor {j}")
        ax2.plot(t, res[f"motor{j}.i"], style, lw=1.2, label=f"motor {j}")
    if vmax is not None and vmax < 1e3:
        for s in (1, -1):
            ax1.axhline(s * vmax, color="k", lw=0.8, ls=":")
    ax1.set_ylabel("armature voltage U [V]")
    ax2.set_ylabel("armature current i [A]")
    ax2.set_xlabel("Time [sec]")
    ax1.set_title("DC motors: PID output voltage and current")
    for ax in (ax1, ax2):
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right")
    ax2.set_xlim(0, t[-1])
    fig.tight_layout()
    path = outdir / "motors.png"
    fig.savefig(path, dpi=120)
    plt.close(fig)
    paths.append(path)
    return paths


def digital_figure(res_continuous, outdir: Path, stop_time: float = 2.0,
                   Ts: float = 5e-3) -> tuple[Path, dict[str, float]]:
    """Simulate :class:`RobotDigitalPID` (sample period ``Ts``) and plot it beside the
    continuous PID result ``res_continuous``; returns the figure and summary figures."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from bgmodelica import simulate

    from .digital import RobotDigitalPID

    dig = simulate(RobotDigitalPID(), stop_time=stop_time, interval=INTERVAL,
                   params={"Ts": Ts}, rtol=1e-8, atol=1e-10)
    cont = res_continuous
    sel = cont.time <= stop_time
    fig, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
    for j, ax in zip((1, 2), axes[:2], strict=True):
        ax.plot(cont.time[sel], cont[f"ref{j}.q"][sel], "k:", lw=1, label=f"q{j}* reference")
        ax.plot(cont.time[sel], cont[f"arm.q{j}"][sel], lw=1.2, label="continuous PID")
        ax.plot(dig.time, dig[f"arm.q{j}"], "--", lw=1.2, label=f"sampled PID, Ts = {Ts:g} s")
        ax.set_ylabel(f"q{j} [rad]")
        ax.grid(alpha=0.3)
        ax.legend(loc="best", fontsize=8)
    axes[2].plot(cont.time[sel], cont["motor1.u"][sel], lw=1, label="motor1.u continuous")
    axes[2].plot(dig.time, dig["motor1.u"], lw=1, drawstyle="steps-post",
                 label="motor1.u sampled (held)")
    axes[2].set_ylabel("voltage [V]")
    axes[2].set_xlabel("time [s]")
    axes[2].grid(alpha=0.3)
    axes[2].legend(loc="best", fontsize=8)
    axes[0].set_title("Two-link robot: continuous vs sampled (digital) PID")
    fig.tight_layout()
    path = outdir / "digital_pid.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    info = {"events": float(dig.meta["n_events"]), "run_seconds": float(dig.meta["run_seconds"]),
            "max_abs_q_difference_rad": float(max(
                np.max(np.abs(np.interp(dig.time, cont.time, cont[f"arm.q{j}"])
                              - dig[f"arm.q{j}"])) for j in (1, 2)))}
    return path, info


def run(outdir: Path, stage: Callable[[str, float, str], None] | None = None) -> dict:
    """Simulate the PID robot for 10 s; write CSV, figures and summary into ``outdir``.

    ``stage(name, seconds, what)`` is called after each stage (simulation, figures, sampled
    PID); by default it prints one line per stage.
    """
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    if stage is None:
        def stage(name: str, seconds: float, what: str = "") -> None:
            print(f"{name}: {what} ({seconds:.1f} s)", flush=True)
    t0 = time.perf_counter()
    compiled, res, build = simulate_robot()
    after = res.time >= SETTLE
    csv_path = res.to_csv(outdir / "robot.csv", CSV_COLUMNS)
    err = {f"q{j}": float(np.max(np.abs(res[f"e{j}"][after]))) for j in (1, 2)}
    stage("robot simulation", time.perf_counter() - t0,
          f"RobotPID 10 s, max |q* - q| after {SETTLE:g} s: joint 1 {err['q1']:.4g} rad, "
          f"joint 2 {err['q2']:.4g} rad; compile {build:.2f} s, simulate "
          f"{float(res.meta['run_seconds']):.2f} s -> {csv_path}")
    t0 = time.perf_counter()
    figures = _figures(res, outdir)
    stage("figures", time.perf_counter() - t0, ", ".join(p.name for p in figures))
    t0 = time.perf_counter()
    digital_path, digital = digital_figure(res, outdir)
    figures.append(digital_path)
    stage("sampled PID", time.perf_counter() - t0,
          f"RobotDigitalPID 2 s, {digital['events']:.0f} events -> {digital_path.name}")
    info = compiled.summary()
    summary = {
        "model": "library.robots.robot.RobotPID",
        "stop_time_s": STOP_TIME,
        "max_abs_tracking_error_after_1s_rad": err,
        "max_abs_voltage_V": {f"motor{j}": float(np.max(np.abs(res[f"motor{j}.u"])))
                              for j in (1, 2)},
        "max_abs_current_A": {f"motor{j}": float(np.max(np.abs(res[f"motor{j}.i"])))
                              for j in (1, 2)},
        "compile_seconds": build,
        "run_seconds": float(res.meta["run_seconds"]),
        "compile_stages_seconds": {k: float(v) for k, v in compiled.timings.items()},
        "equations": info["equations"],
        "structural_index": info["structural_index"],
        "states": info["states"],
        "algebraic_variables": info["algebraic_variables"],
        "solver_steps": int(res.meta["stats"].get("nsteps", 0)),
        "digital_pid": digital,
        "csv": str(csv_path),
        "figures": [str(p) for p in figures],
    }
    (outdir / "summary.json").write_text(json.dumps(summary, indent=2))
    return summary


if __name__ == "__main__":
    run(Path(sys.argv[1] if len(sys.argv) > 1 else "results"))
