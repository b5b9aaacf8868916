"""The main job: ``python -m library.main_job [OUTDIR]`` (what ``bash scripts/main.sh`` runs).

Everything is written into ``OUTDIR`` (default ``results``); nothing into the repository or
the installed packages:

1. ``robot.csv``, ``summary.json`` and the paper-style figures of the paper's two-link robot
   arm driven by two DC motors under per-joint PID control (10 s; ``digital_pid.png``: the
   sampled PID beside it) -- :func:`library.robots.main_job.run`;
2. ``fmus/fmi2/*.fmu``, ``fmus/fmi3/*.fmu``: the robot, the arm and the DC motor as FMUs
   (Model Exchange and Co-Simulation in one FMU each), validated with fmpy;
3. ``fmus/robot.ssp``, ``fmus/robot_plain.ssp``, ``fmus/cosim/*.fmu``,
   ``fmus/cosim/robot_container.json``: the co-simulation set-ups of the split robot;
4. ``verify.png`` and ``summary.json["verification"]``: the co-simulation of the subsystem FMUs
   against the monolithic model at one macro step (1 ms, four schemes, cross-checked with
   ``fmucontainer``); the convergence table over five steps is ``bgmodelica verify``.

The FMU builds (a C compilation each) and the co-simulations run in a pool of worker processes
beside the simulations; a compiled FMU binary is reused by a later run into the same OUTDIR
when its C sources are unchanged (``OUTDIR/.build-cache``). One line per stage reports its
wall time, and the last line the total.
"""

from __future__ import annotations

import json
import os
import sys
import threading
import time
from concurrent.futures import Future, ProcessPoolExecutor
from dataclasses import replace
from pathlib import Path
from typing import Any

#: The monolithic FMUs: file stem -> factory (module, name) -- importable in worker processes.
MONOLITHIC = {"robot": ("library.robots.robot", "RobotPID"),
              "arm": ("library.robots.arm", "ArmWithTorques"),
              "motor": ("library.robots.motor", "DCMotor")}
#: The subsystem FMUs of the co-simulation set-ups (``library.robots.subsystems``).
SUBSYSTEMS = ("Arm", "Motor", "Controller", "ControllerAngleD")
#: Macro step [s] of the verification run (the SSP's default experiment).
VERIFY_STEP = 1e-3


def use_build_cache(cache_dir: str) -> None:
    """Worker initializer: reuse the shared library of an FMU whose C sources, compiler and
    flags are unchanged since an earlier run into the same OUTDIR (``OUTDIR/.build-cache``;
    delete it to force a rebuild). The FMU itself is rebuilt and zipped as always."""
    import hashlib
    import shutil

    from bgmodelica.fmi import build, export

    compile_library = build.compile_shared_library
    cache = Path(cache_dir)

    def cached(src_dir: Path, out_path: Path, compiler: str | None = None) -> Path:
        h = hashlib.sha256()
        h.update(repr((build.find_compiler(compiler), build.CFLAGS, Path(out_path).name))
                 .encode())
        for f in sorted(Path(src_dir).iterdir()):
            if f.suffix in (".c", ".h"):
                h.update(f.name.encode())
                h.update(f.read_bytes())
        hit = cache / f"{h.hexdigest()[:32]}{Path(out_path).suffix}"
        if hit.is_file():
            Path(out_path).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(hit, out_path)
            return Path(out_path)
        path = compile_library(src_dir, out_path, compiler)
        cache.mkdir(parents=True, exist_ok=True)
        tmp = hit.with_name(hit.name + f".{os.getpid()}.part")
        shutil.copyfile(path, tmp)
        os.replace(tmp, hit)
        return path

    export.compile_shared_library = cached


def export_fmu_job(name: str, out_dir: str, fmi_version: int) -> dict[str, Any]:
    """Export one monolithic FMU (:data:`MONOLITHIC`) and validate it with fmpy."""
    import importlib

    from fmpy.validation import validate_fmu

    from bgmodelica.fmi.from_model import export_model

    t0 = time.perf_counter()
    module, cls = MONOLITHIC[name]
    model = getattr(importlib.import_module(module), cls)(name=name)
    path = export_model(model, Path(out_dir) / f"fmi{fmi_version}", fmi_version=fmi_version,
                        fmu_type="both", stop_time=10.0)
    problems = validate_fmu(str(path))
    return {"path": str(path), "valid": not problems, "problems": problems,
            "seconds": round(time.perf_counter() - t0, 2)}


def subsystem_fmu_job(name: str, out_dir: str) -> tuple[str, str, float]:
    """Export one subsystem FMU of the co-simulation set-ups, with the settings of
    :func:`library.robots.subsystems.build_robot_fmus` (FMI 2.0, ME and CS, tolerance 1e-8)."""
    from bgmodelica.fmi.from_model import export_model
    from library.robots import subsystems

    t0 = time.perf_counter()
    factory = subsystems._FACTORIES[name]  # one FMU per job, so that they build in parallel
    path = export_model(factory(), Path(out_dir), fmi_version=2, fmu_type="both",
                        stop_time=10.0, tolerance=1e-8)
    return name, str(path), time.perf_counter() - t0


def verify_job(fmus: dict[str, str], order: str) -> Any:
    """:func:`library.robots.verification.verify_robot` at :data:`VERIFY_STEP` (Jacobi and
    Gauss-Seidel, with and without extrapolation), Co-Simulation FMUs only; the cross-checks
    run as separate jobs (:func:`cross_check_job`)."""
    try:
        from library.robots.verification import verify_robot
    except ImportError:                       # before the robot's study moved to the library
        from bgmodelica.cosim import verify_robot

    return verify_robot(steps=(VERIFY_STEP,), schemes=((order, False), (order, True)),
                        me_step=None, cross_check_step=None, fmus=fmus)


def cross_check_job(fmus: dict[str, str], order: str) -> dict[str, Any]:
    """The cross-check of our master against ``fmucontainer`` (as in ``verify_robot``)."""
    import importlib.util

    if importlib.util.find_spec("fmu_manipulation_toolbox") is None:
        return {"skipped": "fmu-manipulation-toolbox is not installed"}
    from bgmodelica.cosim.xcheck import cross_check
    from library.robots.subsystems import robot_system

    system = robot_system({k: Path(v) for k, v in fmus.items()}, coupling="lumped")
    tol = {el: {"solver.tolerance": 1e-10} for el in system.element_names}
    return cross_check(system, stop_time=10.0, step=VERIFY_STEP, order=order,
                       parameters=tol).to_dict()


def write_setups(fmus: dict[str, str], out: Path) -> dict[str, str]:
    """The SSP set-ups and the ``fmucontainer`` description of the split robot (as
    :func:`library.robots.subsystems.export_robot_setup`, from FMUs already built)."""
    from bgmodelica.cosim.ssp import write_ssp
    from bgmodelica.cosim.xcheck import container_description
    from library.robots.subsystems import robot_system

    paths = {k: Path(v) for k, v in fmus.items()}
    return {
        "ssp": str(write_ssp(robot_system(paths, None, "lumped"), out / "robot.ssp")),
        "container_json": str(container_description(
            robot_system(paths, None, "lumped"), out / "cosim" / "robot_container.json",
            step_size=1e-3, order="gauss-seidel")),
        "ssp_plain": str(write_ssp(robot_system(paths, None, "plain", name="robot_plain"),
                                   out / "robot_plain.ssp")),
    }


class Stages:
    """Prints one line per finished stage: ``[elapsed] stage: what (its own seconds)``."""

    def __init__(self) -> None:
        self.start = time.perf_counter()
        self.seconds: dict[str, float] = {}
        self._lock = threading.Lock()

    def done(self, stage: str, seconds: float, what: str = "") -> None:
        with self._lock:
            self.seconds[stage] = round(seconds, 2)
            elapsed = time.perf_counter() - self.start
            print(f"[{elapsed:6.1f} s] {stage}: {what + ' ' if what else ''}({seconds:.1f} s)",
                  flush=True)


def _workers() -> int:
    return max(1, min(2, os.cpu_count() or 1))


def main(argv: list[str]) -> int:
    import multiprocessing

    outdir = Path(argv[0] if argv else "results")
    outdir.mkdir(parents=True, exist_ok=True)
    stages = Stages()
    print(f"main job -> {outdir.resolve()} ({_workers()} worker processes for FMU builds and "
          "co-simulations)", flush=True)
    pool = ProcessPoolExecutor(max_workers=_workers(),
                               mp_context=multiprocessing.get_context("spawn"),
                               initializer=use_build_cache,
                               initargs=(str(outdir.resolve() / ".build-cache"),))
    try:
        return _run(outdir, outdir / "fmus", stages, pool)
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _run(outdir: Path, fmu_dir: Path, stages: Stages, pool: ProcessPoolExecutor) -> int:
    from library.robots.main_job import run

    t_sub = time.perf_counter()
    # critical path: subsystem FMUs -> set-ups -> co-simulations; the monolithic FMUs fill in
    sub_jobs = [pool.submit(subsystem_fmu_job, n, str(fmu_dir / "cosim")) for n in SUBSYSTEMS]
    sim: dict[str, Any] = {}

    def simulations() -> None:
        try:
            sim["summary"] = run(outdir, stage=stages.done)
        except BaseException as err:  # noqa: BLE001 -- re-raised in the main thread
            sim["error"] = err

    thread = threading.Thread(target=simulations, name="simulations")
    thread.start()
    try:
        fmus = dict(job.result()[:2] for job in sub_jobs)
        stages.done("subsystem FMUs", time.perf_counter() - t_sub,
                    f"{len(fmus)} FMUs -> {fmu_dir / 'cosim'}")
        t0 = time.perf_counter()
        setup = write_setups(fmus, fmu_dir)
        stages.done("co-simulation set-ups", time.perf_counter() - t0,
                    f"{setup['ssp']}, {setup['ssp_plain']}")
        lumped = {k: fmus[k] for k in ("Arm", "Motor", "Controller")}
        t_ver = time.perf_counter()
        orders = ("jacobi", "gauss-seidel")
        ver_jobs = [pool.submit(verify_job, lumped, o) for o in orders]
        xcheck_jobs = [pool.submit(cross_check_job, lumped, o) for o in orders]
        t_mono = time.perf_counter()
        mono_jobs: dict[str, Future] = {
            f"fmi{v}/{name}.fmu": pool.submit(export_fmu_job, name, str(fmu_dir), v)
            for name in MONOLITHIC for v in (2, 3)}

        parts = [job.result() for job in ver_jobs]
        report = replace(parts[0], rows=[r for p in parts for r in p.rows],
                         cross_checks=[job.result() for job in xcheck_jobs],
                         fmus=dict(lumped))
        thread.join()                       # its figures use pyplot too (not thread-safe)
        report.plot(outdir / "verify.png")
        worst = max(max(r.error) for r in report.rows)
        stages.done("verification", time.perf_counter() - t_ver,
                    f"co-simulation vs monolithic at {VERIFY_STEP * 1e3:g} ms: max |dq| "
                    f"{worst:.2e} rad over {len(report.rows)} schemes, cross-checked with "
                    f"fmucontainer -> {outdir / 'verify.png'}")
        print(report.to_text(), flush=True)

        report_fmus = {key: job.result() for key, job in mono_jobs.items()}
        failed = [n for n, r in report_fmus.items() if not r["valid"]]
        stages.done("FMU export", time.perf_counter() - t_mono,
                    f"{len(report_fmus)} FMUs (FMI 2.0 and 3.0, ME + CS) -> {fmu_dir}, fmpy "
                    "validate_fmu " + ("OK" if not failed else "FAILED: " + "; ".join(
                        f"{n}: {'; '.join(report_fmus[n]['problems'])}" for n in failed)))
    finally:
        thread.join()
    if "error" in sim:
        raise sim["error"]
    summary = sim["summary"]
    summary["fmus"] = report_fmus
    summary["cosimulation_setups"] = {**setup, **fmus}
    summary["verification"] = report.to_dict()
    summary["stage_seconds"] = dict(stages.seconds)
    total = time.perf_counter() - stages.start
    summary["total_seconds"] = round(total, 2)
    (outdir / "summary.json").write_text(json.dumps(summary, indent=2, default=str))
    print(f"[{total:6.1f} s] done: summary -> {outdir / 'summary.json'}", flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
