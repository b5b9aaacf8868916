"""The main job: ``python -m library.main_job [OUTDIR]``.

1. Simulates the paper's two-link robot arm driven by two DC motors under per-joint PID control
   (10 s), writes trajectories (CSV), paper-style figures (PNG) and a summary.
2. Exports the robot, the arm and the DC motor as FMUs (FMI 2.0 and 3.0, Model Exchange and
   Co-Simulation in one FMU each) into ``fmus/`` and validates them with fmpy.
3. Verifies the monolithic model against a co-simulation of its motor and arm subsystem FMUs,
   when the co-simulation package is present.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

FMU_DIR = Path(__file__).resolve().parents[1] / "fmus"


def export_fmus(out_dir: Path = FMU_DIR) -> dict[str, dict]:
    """Export the robot and its subsystems; return per-FMU validation results."""
    from fmpy.validation import validate_fmu

    import bgmodelica as bg
    from bgmodelica.fmi.from_model import export_model
    from library.robots.arm import ArmWithTorques
    from library.robots.motor import DCMotor
    from library.robots.robot import RobotPID

    report: dict[str, dict] = {}
    for name, factory in (("robot", RobotPID), ("arm", ArmWithTorques), ("motor", DCMotor)):
        compiled = bg.compile(factory(name=name))
        for version in (2, 3):
            t0 = time.perf_counter()
            path = export_model(compiled, out_dir / f"fmi{version}", fmi_version=version,
                                fmu_type="both", stop_time=10.0)
            problems = validate_fmu(str(path))
            report[f"{path.parent.name}/{path.name}"] = {
                "valid": not problems, "problems": problems,
                "seconds": round(time.perf_counter() - t0, 2)}
    return report


def main(argv: list[str]) -> int:
    outdir = Path(argv[0] if argv else "results")
    outdir.mkdir(parents=True, exist_ok=True)
    from library.robots.main_job import run

    summary = run(outdir)
    fmus = export_fmus()
    for name, rep in fmus.items():
        print(f"FMU {name}: fmpy validate_fmu "
              + ("OK" if rep["valid"] else "FAILED: " + "; ".join(rep["problems"]))
              + f" ({rep['seconds']} s)")
    summary["fmus"] = fmus
    from bgmodelica.cosim import verify_robot
    from library.robots.subsystems import export_robot_setup

    setup = export_robot_setup(FMU_DIR)
    print(f"co-simulation set-ups -> {setup['ssp']}, {setup['ssp_plain']}")
    report = verify_robot(fmus={k: v for k, v in setup.items() if not k.startswith(("ssp",
                                                                                   "container"))})
    print(report.to_text())
    report.plot(outdir / "verify.png")
    summary["verification"] = report.to_dict()
    (outdir / "summary.json").write_text(json.dumps(summary, indent=2, default=str))
    print(f"summary -> {outdir / 'summary.json'}")
    failed = [n for n, r in fmus.items() if not r["valid"]]
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
