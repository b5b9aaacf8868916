"""Verification of the co-simulation against the monolithic model: the paper's PID robot.

The robot's study on top of the generic :func:`bgmodelica.cosim.verify.verify_model`
machinery (:func:`~bgmodelica.cosim.verify.run_schemes` runs the schemes and compares by
name; ``bgmodelica verify library.robots.robot:RobotPID robot.ssp`` is the generic command on
the same set-up).

:func:`verify_robot` builds the subsystem FMUs (:mod:`library.robots.subsystems`), simulates
the monolithic :class:`~library.robots.robot.RobotPID` tightly (IDAS, rtol 1e-10) as the
reference, and co-simulates the split robot for every macro step, both orders (Jacobi,
Gauss-Seidel), with and without input extrapolation. It reports per joint the largest
``|q_cosim - q_mono|`` over the communication points, the observed order of convergence
between consecutive steps, wall-clock seconds per simulated second next to the monolithic
ones, a Model Exchange run, and the cross-check against ``fmucontainer``
(:func:`~bgmodelica.cosim.xcheck.cross_check`).

Since the split is exact (:class:`~library.robots.subsystems.RobotFromSubsystems` equals
``RobotPID``; the report shows the difference), every error in the table is coupling error.
"""

from __future__ import annotations

import importlib.util
import math
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from bgmodelica.cosim.errors import InvalidExperimentError
from bgmodelica.cosim.verify import (  # noqa: F401 -- re-exported for the robot's users
    DIVERGED,
    MAX_REFERENCE_POINTS,
    SCHEMES,
    _grid,
    _observed,
    check_options,
    run_schemes,
)

DEFAULT_STEPS = (10e-3, 5e-3, 2e-3, 1e-3, 5e-4)
#: The compared variables: the joint angles [rad].
JOINTS = ("arm.q1", "arm.q2")


@dataclass
class VerifyRow:
    """One co-simulation run: scheme, macro step, error per joint [rad], observed order
    (against the previous, larger step), wall time per simulated second."""

    interface: str
    order: str
    extrapolation: bool
    step: float
    error: list[float]                    # per joint, inf if the run diverged
    observed_order: list[float | None]
    wall_per_second: float | None
    status: str = "ok"                    # ok | diverged

    @property
    def scheme(self) -> str:
        return f"{self.order}{' + extrapolation' if self.extrapolation else ''}"

    def to_dict(self) -> dict[str, Any]:
        return {"interface": self.interface, "order": self.order,
                "extrapolation": self.extrapolation, "step": self.step,
                "error_q1": _finite(self.error[0]), "error_q2": _finite(self.error[1]),
                "observed_order_q1": self.observed_order[0],
                "observed_order_q2": self.observed_order[1],
                "wall_seconds_per_simulated_second": self.wall_per_second,
                "status": self.status}


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


@dataclass
class VerifyReport:
    """Result of :func:`verify_robot`; ``to_text()`` for people, ``to_dict()`` for JSON."""

    coupling: str
    stop_time: float
    steps: list[float]
    rows: list[VerifyRow]
    monolithic: dict[str, Any]
    split_check: dict[str, float]
    cross_checks: list[dict[str, Any]] = field(default_factory=list)
    timings: dict[str, float] = field(default_factory=dict)
    fmus: dict[str, str] = field(default_factory=dict)
    me_stop_time: float | None = None

    def rows_for(self, order: str, extrapolation: bool, interface: str = "cs"
                 ) -> list[VerifyRow]:
        return [r for r in self.rows if r.order == order and r.extrapolation == extrapolation
                and r.interface == interface]

    def error(self, step: float, order: str, extrapolation: bool, joint: int,
              interface: str = "cs") -> float:
        for r in self.rows_for(order, extrapolation, interface):
            if abs(r.step - step) <= 1e-12:
                return r.error[joint - 1]
        raise KeyError(f"no run with step {step}, {order}, extrapolation={extrapolation}")

    def to_dict(self) -> dict[str, Any]:
        return {"coupling": self.coupling, "stop_time": self.stop_time, "steps": self.steps,
                "rows": [r.to_dict() for r in self.rows], "monolithic": self.monolithic,
                "split_check": self.split_check, "cross_checks": self.cross_checks,
                "timings": self.timings, "fmus": self.fmus, "me_stop_time": self.me_stop_time}

    def to_text(self) -> str:
        mono = self.monolithic
        lines = [f"Co-simulation of the PID robot vs the monolithic RobotPID "
                 f"({self.stop_time:g} s, {self.coupling} coupling)",
                 f"reference: IDAS rtol {mono['rtol']:g}, atol {mono['atol']:g}; split "
                 f"model (subsystems reconnected) vs RobotPID: max |dq| = "
                 f"{max(self.split_check.values()):.1e} rad",
                 "error = max over communication points of |q_cosim - q_mono| [rad]; "
                 "p = observed order vs the previous step; wall = s per simulated s", ""]
        for interface in ("cs", "me"):
            rows_if = [r for r in self.rows if r.interface == interface]
            if not rows_if:
                continue
            if interface == "me":
                lines.append(f"Model Exchange FMUs (master's SciPy Radau integrator), "
                             f"{self.me_stop_time:g} s:")
            header = (f"{'scheme':<28}{'step [ms]':>10}{'err q1':>11}{'p':>6}{'err q2':>11}"
                      f"{'p':>6}{'wall':>9}")
            lines += [header, "-" * len(header)]
            for order, ex in SCHEMES:
                for r in self.rows_for(order, ex, interface):
                    e = [f"{x:11.2e}" if math.isfinite(x) else f"{'diverged':>11}"
                         for x in r.error]
                    p = [f"{x:6.2f}" if x is not None else f"{'-':>6}"
                         for x in r.observed_order]
                    wall = f"{r.wall_per_second:9.3f}" if r.wall_per_second is not None \
                        else f"{'-':>9}"
                    lines.append(f"{r.scheme:<28}{r.step * 1e3:10.3g}{e[0]}{p[0]}{e[1]}"
                                 f"{p[1]}{wall}")
            lines.append("")
        lines.append(f"monolithic RobotPID: {mono['wall_per_second']:.3f} s per "
                     f"simulated s at rtol {mono['default_rtol']:g} "
                     f"({mono['tight_wall_per_second']:.3f} at rtol {mono['rtol']:g}); "
                     f"compile {mono['compile_seconds']:.2f} s")
        for cc in self.cross_checks:
            if "skipped" in cc:
                lines.append(f"cross-check vs fmucontainer skipped: {cc['skipped']}")
                continue
            lines.append(
                f"cross-check vs fmucontainer ({cc['order']}, step {cc['step'] * 1e3:g} ms, "
                f"{cc['stop_time']:g} s, {cc['points']} points): max |difference| = "
                f"{cc['worst_abs_diff']:.1e} ({cc['worst']})")
        return "\n".join(lines)

    def plot(self, path: str | Path) -> Path:
        """Error against macro step (log-log), per joint, every scheme, with slopes 1, 2."""
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 2, figsize=(11, 4.5), sharey=True)
        styles = {("jacobi", False): "o-", ("jacobi", True): "s--",
                  ("gauss-seidel", False): "^-", ("gauss-seidel", True): "v--"}
        h = np.array(self.steps)
        for j, ax in enumerate(axes):
            for (order, ex), style in styles.items():
                rows = self.rows_for(order, ex)
                hs = [r.step for r in rows if math.isfinite(r.error[j])]
                es = [r.error[j] for r in rows if math.isfinite(r.error[j])]
                if hs:
                    ax.loglog(np.array(hs) * 1e3, es, style,
                              label=f"{order}{' + extrap.' if ex else ''}")
            for slope, ls in ((1, ":"), (2, "-.")):
                ref = [r.error[j] for r in self.rows_for("gauss-seidel", slope == 2)
                       if math.isfinite(r.error[j])]
                if ref:
                    e0 = ref[-1]
                    ax.loglog(h * 1e3, e0 * (h / h.min()) ** slope, "k" + ls, lw=0.8,
                              label=f"slope {slope}")
            ax.axhline(1e-3, color="r", lw=0.6, alpha=0.5)
            ax.set_xlabel("macro step [ms]")
            ax.set_title(f"joint {j + 1}: max |q{j + 1} cosim - q{j + 1} mono|")
            ax.grid(True, which="both", alpha=0.3)
        axes[0].set_ylabel("error [rad]")
        axes[1].legend(fontsize=8)
        fig.suptitle(f"PID robot, {self.stop_time:g} s: co-simulation ({self.coupling} "
                     "coupling) vs monolithic")
        fig.tight_layout()
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(path, dpi=120)
        plt.close(fig)
        return path


def verify_robot(steps: Sequence[float] = DEFAULT_STEPS, stop_time: float = 10.0, *,
                 coupling: str = "lumped", schemes: Sequence[tuple[str, bool]] = SCHEMES,
                 me_step: float | None = 1e-3, me_stop_time: float | None = 2.0,
                 cross_check_step: float | None = 1e-3,
                 cross_check_stop_time: float | None = None,
                 work_dir: str | Path | None = None, fmus: dict[str, str | Path] | None = None,
                 solver_tolerance: float = 1e-10, reference_rtol: float = 1e-10,
                 progress: Callable[[str], None] | None = None) -> VerifyReport:
    """Co-simulate the split PID robot against the monolithic model (see module docstring).

    ``steps``: macro steps [s] (largest first); ``schemes``: (order, extrapolation) pairs;
    ``me_step``/``me_stop_time``: one Model Exchange run per scheme at that step and horizon
    (None: skip); ``cross_check_step``: step of the fmucontainer cross-check over
    ``cross_check_stop_time`` (default ``stop_time``; None step: skip). ``fmus``: prebuilt
    FMUs (model name -> path) instead of building them in ``work_dir`` (default: a temporary
    directory). ``solver_tolerance``: the CS FMUs' ``solver.tolerance``.
    """
    from bgmodelica import compile, simulate
    from bgmodelica.cosim.xcheck import cross_check
    from library.robots.robot import RobotPID
    from library.robots.subsystems import (
        RobotFromSubsystems,
        build_robot_fmus,
        robot_system,
    )

    say = progress or (lambda _msg: None)
    try:
        steps = sorted((float(s) for s in steps), reverse=True)
    except (TypeError, ValueError):
        raise InvalidExperimentError(f"macro steps must be numbers, got {steps!r}") from None
    grid = check_options(steps, stop_time, me_step, me_stop_time, cross_check_step,
                         cross_check_stop_time)
    if coupling not in ("lumped", "plain"):
        raise InvalidExperimentError(f"coupling must be 'lumped' or 'plain', not {coupling!r}")
    timings: dict[str, float] = {}
    tmp = None
    if fmus is None:
        if work_dir is None:
            tmp = tempfile.TemporaryDirectory(prefix="bgm_verify_")
            work_dir = tmp.name
        say("building the subsystem FMUs")
        t0 = time.perf_counter()
        fmus = build_robot_fmus(Path(work_dir) / "fmu", couplings=(coupling,))
        timings["build_fmus"] = time.perf_counter() - t0
    try:
        system = robot_system(dict(fmus), coupling=coupling)
        tol = {el: {"solver.tolerance": solver_tolerance} for el in system.element_names}

        say("monolithic reference")
        t0 = time.perf_counter()
        compiled = compile(RobotPID())
        compile_s = time.perf_counter() - t0
        t0 = time.perf_counter()
        ref = simulate(compiled, stop_time=stop_time, interval=grid, rtol=reference_rtol,
                       atol=reference_rtol * 1e-2, dynamic=False, solver="idas")
        tight = (time.perf_counter() - t0) / stop_time
        t0 = time.perf_counter()
        simulate(compiled, stop_time=stop_time, interval=min(steps), dynamic=False)
        default = (time.perf_counter() - t0) / stop_time
        monolithic = {"rtol": reference_rtol, "atol": reference_rtol * 1e-2,
                      "default_rtol": 1e-6, "wall_per_second": default,
                      "tight_wall_per_second": tight, "compile_seconds": compile_s,
                      "output_interval": grid}

        say("split model vs RobotPID")
        split = simulate(compile(RobotFromSubsystems(coupling)), stop_time=min(stop_time, 3.0),
                         interval=0.01, rtol=reference_rtol, atol=reference_rtol * 1e-2,
                         dynamic=False, solver="idas")
        n_split = len(split.time)
        split_check = {f"arm.q{j}": float(np.max(np.abs(split[f"arm.q{j}"]
                                                         - ref[f"arm.q{j}"][
                                                             np.round(split.time / grid)
                                                             .astype(int)])))
                       for j in (1, 2)} if n_split else {}

        rows: list[VerifyRow] = []
        plans = [("cs", steps, stop_time)]
        if me_step:
            plans.append(("me", [float(me_step)], float(me_stop_time or stop_time)))
        pairs = {j: j for j in JOINTS}
        for interface, hs, horizon in plans:
            for r in run_schemes(system, ref, pairs, hs, horizon, schemes=schemes,
                                 interface=interface, parameters=tol, progress=say):
                rows.append(VerifyRow(r.interface, r.order, r.extrapolation, r.step,
                                      [r.errors[j] for j in JOINTS],
                                      [r.observed_order[j] for j in JOINTS],
                                      r.wall_per_second, r.status))
        timings["cosimulation"] = sum((r.wall_per_second or 0) for r in rows)

        checks: list[dict[str, Any]] = []
        if cross_check_step and importlib.util.find_spec("fmu_manipulation_toolbox") is None:
            checks.append({"skipped": "fmu-manipulation-toolbox is not installed"})
        elif cross_check_step:
            horizon = float(cross_check_stop_time or stop_time)
            for order in ("jacobi", "gauss-seidel"):
                say(f"cross-check with fmucontainer ({order})")
                cc = cross_check(system, stop_time=horizon, step=float(cross_check_step),
                                 order=order, parameters=tol)
                checks.append(cc.to_dict())
        return VerifyReport(coupling, float(stop_time), steps, rows, monolithic, split_check,
                            checks, timings, {k: str(v) for k, v in fmus.items()},
                            float(me_stop_time or stop_time) if me_step else None)
    finally:
        if tmp is not None:
            tmp.cleanup()


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m library.robots.verification [--steps ...] [--json] [--plot out.png]``: the
    robot's full study (what ``bgmodelica verify`` printed before it became generic)."""
    import argparse
    import json
    import sys

    from bgmodelica.cli import _error_line
    from bgmodelica.errors import ModelError

    p = argparse.ArgumentParser(prog="python -m library.robots.verification",
                                description="PID robot: monolithic vs co-simulation (errors, "
                                            "convergence order, timing, fmucontainer check)")
    p.add_argument("--steps", default="10e-3,5e-3,2e-3,1e-3,5e-4",
                   help="comma-separated macro steps [s]")
    p.add_argument("--stop-time", type=float, default=10.0, help="[s] (default 10)")
    p.add_argument("--coupling", choices=["lumped", "plain"], default="lumped",
                   help="subsystem split (see library.robots.subsystems)")
    p.add_argument("--json", action="store_true", help="machine-readable report")
    p.add_argument("--plot", help="PNG: error vs macro step per joint")
    p.add_argument("--no-me", action="store_true", help="skip the Model Exchange runs")
    p.add_argument("--no-cross-check", action="store_true",
                   help="skip the fmucontainer cross-check")
    p.add_argument("--fmu-dir", help="build (and keep) the FMUs here")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    args = p.parse_args(argv)

    def progress(msg: str) -> None:
        if not args.quiet:
            sys.stderr.write(f"  {msg}\n")
            sys.stderr.flush()

    try:
        steps = [float(s) for s in args.steps.split(",") if s.strip()]
        plot = Path(args.plot) if args.plot else None
        if plot is not None and not plot.parent.is_dir():
            raise InvalidExperimentError(f"cannot write the plot {plot}: the folder "
                                         f"{plot.parent} does not exist")
        report = verify_robot(steps, args.stop_time, coupling=args.coupling,
                              me_step=None if args.no_me else 1e-3,
                              cross_check_step=None if args.no_cross_check else 1e-3,
                              work_dir=Path(args.fmu_dir) if args.fmu_dir else None,
                              progress=progress)
    except (ModelError, ValueError) as err:
        print(_error_line(err) if isinstance(err, ModelError) else f"error: {err}",
              file=sys.stderr)
        return 2
    print(json.dumps(report.to_dict(), indent=2) if args.json else report.to_text())
    if plot is not None:
        report.plot(plot)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
