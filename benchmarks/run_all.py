"""Run the benchmarks and write one JSON with the figures and the ratios against baselines
measured in the same run; optionally rewrite the README's performance table from it.

    python benchmarks/run_all.py [--full] [--json perf.json] [--readme]
    python benchmarks/run_all.py --table-from perf.json      # README table, no run

Quick mode (default, a few minutes): RC ladder n = 100, 1000 (a component per section) and
n = 1000, 10,000 (array equations); the disk cache's second compile; JIT; the robot's CS FMU
under fmpy against native; compile scaling of the ladder at about 1.4e3 and 1.4e4 equations;
the robot; the co-simulation master against ``fmucontainer``. ``--full`` adds the ladder at
n = 10,000 and 100,000 in both forms and compile scaling at 1.4e5 equations (the acceptance
sizes; much longer).

Baselines: the RC ladder written by hand as a CasADi SX ODE and integrated with CVODES (the
"floor"), and scipy's BDF with a sparse Jacobian (quick sizes); the robot's hand-written
CasADi/CVODES ODE and scipy BDF (``robot_speed.py``); ``fmucontainer`` for the master.
"""

from __future__ import annotations

import argparse
import gc
import json
import math
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import casadi as ca
import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent))

MARK_START, MARK_END = "<!-- perf-table:start -->", "<!-- perf-table:end -->"
_METHOD = ("one run; ratios against baselines measured in the same run; the ladder's floor "
           "returns the same two trajectories (C1.v, Cn.v) as ours; the component "
           "ladder and its floor alternate, best of two each up to n = 10,000; the robot's "
           "`simulate` and its hand-written CasADi/CVODES run (which builds its integrator, "
           "about 2 ms, each time) alternate, best of 10; the CS FMU and native runs "
           "alternate, best of 10 (they take milliseconds); the master and fmucontainer "
           "alternate, best of 5; the compile-scaling sizes are compiled 3 times each, best kept, "
           "in a fresh interpreter")
#: repetitions of the short comparisons, whatever --repeat says: a 30-ms run is cheap to
#: repeat, and its minimum is what the shared machine's noise leaves alone
FMU_REPEAT, MASTER_REPEAT = 10, 5
#: compilations per compile-scaling size (seconds each; the best is kept)
COMPILE_REPEAT = 3
STOP, DT, RTOL, ATOL = 10.0, 0.01, 1e-6, 1e-6


def best_time(fn, repeat: int) -> float:
    """Smallest wall time of ``repeat`` calls of ``fn`` [s]."""
    b = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        b = min(b, time.perf_counter() - t0)
    return b


def ladder_by_hand(n: int) -> dict[str, float]:
    """The RC ladder as one CasADi SX vector ODE, CVODES, same grid and tolerances. Like our
    run (``outputs=["C<n>.v", "C1.v"]``) it hands back two trajectories: the rows are taken
    from the CasADi result before it becomes numpy (converting all n x 1001 values would
    cost about 1.5 s at n = 10,000, which no careful hand-written code pays)."""
    t0 = time.perf_counter()
    v = ca.SX.sym("v", n)
    t = ca.SX.sym("t")
    i = np.arange(1, n + 1, dtype=float)
    src = ca.sin(2 * math.pi * 10.0 * t)
    prev = ca.vertcat(src, v[:-1])
    current = i * (prev - v)                                 # through R_i = 1/i
    nxt = ca.vertcat(current[1:], 0.0)
    ode = (i ** 2) * (current - nxt)                         # C_i = 1/i^2
    grid = np.linspace(0.0, STOP, int(round(STOP / DT)) + 1)
    F = ca.integrator("ladder", "cvodes", {"x": v, "t": t, "ode": ode}, 0.0, list(grid[1:]),
                      {"abstol": ATOL, "reltol": RTOL})
    t1 = time.perf_counter()
    xf = np.asarray(F(x0=i)["xf"][[0, n - 1], :])       # C1.v and Cn.v
    t2 = time.perf_counter()
    return {"build": t1 - t0, "solve": t2 - t1, "total": t2 - t0,
            "last_final": float(xf[1, -1]), "first_final": float(xf[0, -1])}


def ladder_scipy(n: int) -> float:
    """scipy BDF with the sparse (tridiagonal) Jacobian; seconds."""
    from scipy.integrate import solve_ivp
    from scipy.sparse import diags

    i = np.arange(1, n + 1, dtype=float)

    def rhs(t, v):
        prev = np.concatenate([[math.sin(2 * math.pi * 10.0 * t)], v[:-1]])
        cur = i * (prev - v)
        return i ** 2 * (cur - np.concatenate([cur[1:], [0.0]]))

    main = -(i ** 2) * (i + np.concatenate([i[1:], [0.0]]))
    upper = (i[:-1] ** 2) * i[1:]
    lower = (i[1:] ** 2) * i[1:]
    jac = diags([lower, main, upper], [-1, 0, 1], format="csc")
    t0 = time.perf_counter()
    solve_ivp(rhs, (0.0, STOP), i, method="BDF", rtol=RTOL, atol=ATOL, jac=jac,
              t_eval=np.linspace(0.0, STOP, int(round(STOP / DT)) + 1))
    return time.perf_counter() - t0


def rc_ladder_rows(sizes: list[int], scipy_up_to: int, pairs_up_to: int = 10000) -> list[dict]:
    """Ours and the hand-written floor, interleaved; up to ``pairs_up_to`` sections each is
    run twice and its best total kept (a noisy spell on the shared machine then hits both)."""
    from rc_ladder import run

    rows = []
    for n in sizes:
        ours: dict | None = None
        hand: dict | None = None
        for _ in range(2 if n <= pairs_up_to else 1):
            gc.collect()             # the previous run's garbage is not this run's time
            mine = run(n)
            ours = mine if ours is None or mine["total"] < ours["total"] else ours
            gc.collect()
            floor = ladder_by_hand(n)
            hand = floor if hand is None or floor["total"] < hand["total"] else hand
        deviation = max(abs(ours[k] - hand[k]) for k in ("first_final", "last_final"))
        row = {"n": n, "bgmodelica_build": ours["build"], "bgmodelica_solve": ours["solve"],
               "bgmodelica_total": ours["total"], "casadi_cvodes_total": hand["total"],
               "ratio_vs_casadi": ours["total"] / hand["total"], "final_deviation": deviation}
        if n <= scipy_up_to:
            row["scipy_bdf_total"] = ladder_scipy(n)
            row["ratio_scipy_vs_bgmodelica"] = row["scipy_bdf_total"] / ours["total"]
        rows.append(row)
        print(f"  RC ladder n={n}: bgmodelica {ours['total']:.3f} s (build "
              f"{ours['build']:.3f}), CasADi/CVODES by hand {hand['total']:.3f} s, ratio "
              f"{row['ratio_vs_casadi']:.2f}; C1.v, C{n}.v at 10 s agree to {deviation:.1e} V",
              flush=True)
    return rows


def vector_ladder_rows(sizes: list[int], hand: dict[int, float]) -> list[dict]:
    """The ladder written with array equations (``RCLadderVector``): construct + compile +
    10-s solve against the hand-written floor of the same size (measured here if not yet)."""
    from bgmodelica import compile, simulate
    from library.examples import RCLadderVector

    rows = []
    for n in sizes:
        gc.collect()
        t0 = time.perf_counter()
        model = RCLadderVector(n)
        t1 = time.perf_counter()
        compiled = compile(model)
        t2 = time.perf_counter()
        simulate(compiled, stop_time=STOP, interval=DT, rtol=RTOL, atol=ATOL,
                 outputs=[f"v[{n}]", "v[1]"])
        t3 = time.perf_counter()
        floor = hand.get(n) or ladder_by_hand(n)["total"]
        rows.append({"n": n, "construct": t1 - t0, "compile": t2 - t1, "solve": t3 - t2,
                     "total": t3 - t0, "casadi_cvodes_total": floor,
                     "ratio_vs_casadi": (t3 - t0) / floor})
        print(f"  RC ladder (array equations) n={n}: {t3 - t0:.3f} s (construct "
              f"{t1 - t0:.3f}, compile {t2 - t1:.3f}, solve {t3 - t2:.3f}), ratio "
              f"{rows[-1]['ratio_vs_casadi']:.2f}", flush=True)
    return rows


#: the component ladder compiled with ``array_path=False`` (what the cache saves there)
SCALAR_FORM = "component per section, scalar pipeline"


def cache_rows(cases: list[tuple[str, int]]) -> list[dict]:
    """Compile, then compile again from the disk cache (a fresh temporary folder); if that
    load cost more than compiling (the entry is then dropped), a third compile shows what
    the cache costs from then on (making the key)."""
    from rc_ladder import rc_ladder

    from bgmodelica import compile
    from library.examples import RCLadderVector

    make = {"component per section": rc_ladder, "array equations": RCLadderVector,
            SCALAR_FORM: rc_ladder}
    rows = []
    with tempfile.TemporaryDirectory(prefix="bgm_cache_") as folder:
        for form, n in cases:
            model = make[form](n)                   # constructed outside the timings
            how = {"cache": folder, "array_path": form != SCALAR_FORM}
            gc.collect()                            # not the garbage of the runs before
            t0 = time.perf_counter()
            first = compile(model, **how)            # key + compile (+ store, taken out)
            if "cache_store" not in first.timings:   # the array path: nothing cached
                build = time.perf_counter() - t0
                rows.append({"form": form, "n": n, "compile": build, "array_path": True})
                print(f"  cache, {form} n={n}: not used (array path, compile {build:.3f} s)",
                      flush=True)
                continue
            build = time.perf_counter() - t0 - first.timings["cache_store"]
            model = make[form](n)
            t0 = time.perf_counter()
            again = compile(model, **how)
            load = time.perf_counter() - t0
            row = {"form": form, "n": n, "compile": build, "cached_compile": load,
                   "hit": "cache_load" in again.timings,
                   "dropped": any(Path(folder).glob("*/*.nocache"))}
            if row["dropped"]:
                model = make[form](n)
                t0 = time.perf_counter()
                third = compile(model, **how)
                row["third_compile"] = time.perf_counter() - t0
                row["key_seconds"] = third.timings["cache_skipped"]
            rows.append(row)
            print(f"  cache, {form} n={n}: compile {build:.3f} s, second compile "
                  f"{load:.3f} s" + (f", entry dropped; third compile "
                                     f"{row['third_compile']:.3f} s" if row["dropped"] else ""),
                  flush=True)
            for note in Path(folder).glob("*/*.nocache"):
                note.unlink()
    return rows


def jit_rows(repeat: int) -> dict:
    from jit_crossover import main as jit_main

    from bgmodelica.solver_options import compiler

    if compiler() is None:
        return {}
    return jit_main([100], repeat)


def fmu_cs_vs_native(repeat: int) -> dict:
    """The robot exported as a Co-Simulation FMU and run by fmpy (10 s, 10 ms communication
    step) against ``simulate`` of the same compiled model (its default solver choice, same
    tolerance). ``simulate_fmu`` unzips the FMU, parses its model description and loads the
    library at every call (a fixed cost of about 20 ms here). Also reported: the run on the
    extracted folder; fmpy's own pattern for repeated runs ("reused": extracted once, model
    description read once, one instance reset before each ``simulate_fmu``), which is what
    native ``simulate`` of an already compiled model compares with; and a loop over fmpy's
    low-level ``FMU2Slave`` (reset, initialize, 1000 ``doStep`` + ``getReal`` per run)."""
    from fmpy import extract, instantiate_fmu, read_model_description, simulate_fmu
    from fmpy.fmi2 import FMU2Slave

    from bgmodelica import compile, simulate
    from bgmodelica.fmi.from_model import export_model
    from library.robots.robot import RobotPID

    compiled = compile(RobotPID())
    with tempfile.TemporaryDirectory(prefix="bgm_fmu_cs_") as tmp:
        fmu = export_model(compiled, tmp, fmi_version=2, fmu_type="cs", stop_time=STOP)
        folder = extract(str(fmu), unzipdir=str(Path(tmp) / "unzipped"))
        md = read_model_description(folder)
        refs = [v.valueReference for v in md.modelVariables if v.name in ("arm.q1", "arm.q2")]
        slave = FMU2Slave(guid=md.guid, unzipDirectory=folder, instanceName="robot",
                          modelIdentifier=md.coSimulation.modelIdentifier)
        slave.instantiate()
        reused = instantiate_fmu(folder, md, "CoSimulation")

        def reuse():
            reused.reset()
            return simulate_fmu(folder, stop_time=STOP, output_interval=DT,
                                output=["arm.q1", "arm.q2"], model_description=md,
                                fmu_instance=reused)
        steps = int(round(STOP / DT))

        def loop() -> np.ndarray:
            slave.reset()
            slave.setupExperiment(startTime=0.0, stopTime=STOP)
            slave.enterInitializationMode()
            slave.exitInitializationMode()
            out = np.empty((steps + 1, len(refs)))
            out[0] = slave.getReal(refs)
            for k in range(steps):
                slave.doStep(currentCommunicationPoint=k * DT, communicationStepSize=DT)
                out[k + 1] = slave.getReal(refs)
            return out

        runs = {
            "fmu": lambda: simulate_fmu(str(fmu), stop_time=STOP, output_interval=DT,
                                        output=["arm.q1", "arm.q2"]),
            "dir": lambda: simulate_fmu(folder, stop_time=STOP, output_interval=DT,
                                        output=["arm.q1", "arm.q2"]),
            "reused": reuse,
            "loop": loop,
            "native": lambda: simulate(compiled, stop_time=STOP, interval=DT, rtol=1e-6,
                                       atol=1e-6)}
        best = {name: math.inf for name in runs}
        for _ in range(repeat):              # interleaved: a noisy spell hits all of them
            for name, run in runs.items():
                best[name] = min(best[name], best_time(run, 1))
        one_shot, again = runs["fmu"](), reuse()      # the reused instance starts afresh
        agree = max(float(np.max(np.abs(one_shot[v] - again[v]))) for v in ("arm.q1", "arm.q2"))
        slave.terminate()
        slave.freeInstance()
        reused.freeInstance()
    t_fmu, t_dir, t_reused, t_loop, t_native = (
        best[k] for k in ("fmu", "dir", "reused", "loop", "native"))
    print(f"  robot CS FMU under fmpy {t_fmu:.4f} s ({t_dir:.4f} s extracted, {t_reused:.4f} s "
          f"reused, {t_loop:.4f} s FMU2Slave loop), native simulate {t_native:.4f} s; reused "
          f"and one-shot runs differ by {agree:.1e} rad", flush=True)
    if agree > 1e-12:
        raise AssertionError(f"the reused FMU instance gives other results ({agree:.1e} rad)")
    return {"fmu_cs_fmpy": t_fmu, "fmu_cs_fmpy_extracted": t_dir,
            "fmu_cs_fmpy_reused": t_reused, "fmu_cs_fmpy_loop": t_loop,
            "native": t_native, "ratio": t_fmu / t_native,
            "ratio_reused": t_reused / t_native, "ratio_loop": t_loop / t_native,
            "reused_vs_one_shot_max_diff": agree}


def compile_rows(sizes: list[int], array_path: bool = True) -> dict:
    """Compile-scaling rows measured in a fresh interpreter: after the 10^5-section runs
    above this process holds gigabytes of freed, fragmented memory, which slows compiling
    by about 8 %, and a model is usually compiled in a new session. ``array_path=False``:
    through the scalar pipeline."""
    flag = "--json" if array_path else "--json-scalar"
    out = subprocess.run([sys.executable, str(HERE / "compile_scaling.py"), flag,
                          str(COMPILE_REPEAT), *map(str, sizes)],
                         capture_output=True, text=True, cwd=HERE.parent)
    if out.returncode:
        raise RuntimeError(f"compile_scaling.py --json failed:\n{out.stderr[-3000:]}")
    rows = json.loads(out.stdout.strip().splitlines()[-1])
    for r in rows:
        print(f"  compile{'' if array_path else ' (scalar pipeline)'}: {r['equations']} "
              f"equations in {r['seconds']:.3f} s "
              f"({r['us_per_equation']:.1f} us/eq)", flush=True)
    k = float(np.polyfit(np.log([r["equations"] for r in rows]),
                         np.log([r["seconds"] for r in rows]), 1)[0]) if len(rows) > 1 else None
    return {"rows": rows, "growth_exponent": k}


def robot(repeat: int) -> dict:
    from robot_speed import main as robot_main

    r = robot_main(repeat)
    out = dict(r)
    out["ratio_idas_vs_casadi"] = r["idas"] / r["casadi"]
    out["ratio_cvodes_vs_casadi"] = r["cvodes"] / r["casadi"]
    out["ratio_auto_vs_casadi"] = r["dynamic"] / r["casadi"]
    return out


def master_vs_container(stop_time: float, repeat: int) -> dict:
    from bgmodelica.cosim.master import Master
    from bgmodelica.cosim.xcheck import build_container, run_container
    from library.robots.subsystems import build_robot_fmus, robot_system

    with tempfile.TemporaryDirectory(prefix="bgm_run_all_") as tmp:
        system = robot_system(dict(build_robot_fmus(Path(tmp) / "fmu")))
        master = Master(system)
        try:
            container = build_container(system, Path(tmp) / "container", step_size=1e-3)
        except Exception as err:  # noqa: BLE001 - fmu-manipulation-toolbox is optional
            print(f"  fmucontainer unavailable: {err}")
            container = None
        runs = {"jacobi": lambda: master.simulate(stop_time, 1e-3),
                "gauss-seidel": lambda: master.simulate(stop_time, 1e-3, order="gauss-seidel")}
        if container is not None:
            runs["container"] = lambda: run_container(container, stop_time, 1e-3)
        best = {name: math.inf for name in runs}
        for _ in range(repeat):              # interleaved: a noisy spell hits all of them
            for name, run in runs.items():
                best[name] = min(best[name], best_time(run, 1))
        jac, gs = best["jacobi"] / stop_time, best["gauss-seidel"] / stop_time
        cont = best["container"] / stop_time if container is not None else None
    out = {"master_jacobi_s_per_s": jac, "master_gauss_seidel_s_per_s": gs,
           "fmucontainer_s_per_s": cont,
           "ratio_jacobi_vs_container": jac / cont if cont else None}
    print(f"  master {jac:.4f} s/s (Jacobi), {gs:.4f} (Gauss-Seidel); fmucontainer "
          f"{cont if cont is None else round(cont, 4)} s/s", flush=True)
    return out


#: the acceptance figures the array form of the ladder is held to (the ladder's, whatever form)
_VECTOR_TARGETS = {1000: "< 0.5 s", 10000: "<= 2.5x", 100000: "compile < 1 s"}


def table(report: dict) -> str:
    """The README's performance table (Markdown) from a report."""
    lines = ["| benchmark | bgmodelica | baseline (same run) | ratio | target |",
             "|---|---:|---:|---:|---|"]
    for r in report["rc_ladder"]:
        lines.append(f"| RC ladder, component per section, n = {r['n']:,}, build + 10-s solve | "
                     f"{r['bgmodelica_total']:.3f} s | CasADi/CVODES by hand "
                     f"{r['casadi_cvodes_total']:.3f} s | {r['ratio_vs_casadi']:.2f}x | "
                     f"{'<= 2.0x' if r['n'] == 10000 else ('< 0.5 s' if r['n'] == 1000 else '')}"
                     " |")
    for key, how in (("compile", "RC ladder, component per section"),
                     ("compile_scalar", "the same, through the scalar pipeline")):
        comp = report.get(key)
        if comp is None:
            continue
        for r in comp["rows"]:
            lines.append(f"| compile ({how}), {r['equations']:,} equations | "
                         f"{r['seconds']:.3f} s | | {r['us_per_equation']:.1f} us/eq | "
                         "<= 20 us/eq at 1e5 |")
        if comp["growth_exponent"] is not None:
            lines.append(f"| compile growth exponent ({how}) | "
                         f"{comp['growth_exponent']:.2f} | | | <= 1.1 |")
    rb = report["robot"]
    lines.append(f"| robot 10 s, `simulate` (default: `solver=\"auto\"` picks CVODES) | "
                 f"{rb['dynamic'] * 1e3:.1f} ms | CasADi/CVODES by hand "
                 f"{rb['casadi'] * 1e3:.1f} ms | "
                 f"{rb['ratio_auto_vs_casadi']:.2f}x | <= 1.1x |")
    lines.append(f"| robot 10 s, `simulate(solver=\"idas\")` | {rb['idas'] * 1e3:.1f} ms | "
                 f"CasADi/CVODES by hand {rb['casadi'] * 1e3:.1f} ms | "
                 f"{rb['ratio_idas_vs_casadi']:.2f}x | |")
    lines.append(f"| robot compile | {rb['build'] * 1e3:.0f} ms | | | < 300 ms |")
    for r in report.get("rc_ladder_vector", []):
        lines.append(f"| RC ladder, array equations, n = {r['n']:,}, build + 10-s solve | "
                     f"{r['total']:.3f} s (compile {r['compile']:.3f} s) | CasADi/CVODES by "
                     f"hand {r['casadi_cvodes_total']:.3f} s | {r['ratio_vs_casadi']:.2f}x | "
                     f"{_VECTOR_TARGETS.get(r['n'], '')} |")
    for r in report.get("cache", []):
        if r.get("array_path"):
            lines.append(f"| disk cache, RC ladder ({r['form']}), n = {r['n']:,} | not used "
                         f"| the array path compiles in {r['compile']:.3f} s | | |")
            continue
        gain = r["compile"] / r["cached_compile"]
        said = f"{gain:.1f}x faster" if gain >= 1 else \
            f"{1 / gain:.1f}x slower (loading costs more than compiling)"
        if r.get("dropped"):
            said += "; the entry is dropped"
        lines.append(f"| second compile from the disk cache, RC ladder ({r['form']}), "
                     f"n = {r['n']:,} | {r['cached_compile']:.3f} s | first compile (key + "
                     f"compile) {r['compile']:.3f} s | {said} | |")
        if "third_compile" in r:
            lines.append(f"| third compile after the entry was dropped, RC ladder "
                         f"({r['form']}), n = {r['n']:,} | {r['third_compile']:.3f} s (key "
                         f"{r['key_seconds']:.3f} s) | first compile (key + compile) "
                         f"{r['compile']:.3f} s | "
                         f"{r['third_compile'] / r['compile']:.2f}x | |")
    for name, r in report.get("jit", {}).items():
        pays = (f"{r['speedup']:.2f}x faster; pays off after {r['crossover_runs']} runs"
                if r["speedup"] > 1
                else f"{1 / r['speedup']:.2f}x slower in this run; never pays off")
        lines.append(f"| `simulate(jit=True)`, {name}, per 10-s run | {r['run_jit'] * 1e3:.1f} ms"
                     f" | without JIT {r['run_plain'] * 1e3:.1f} ms | {pays} | |")
    fc = report.get("fmu_cs")
    if fc:
        if "fmu_cs_fmpy_reused" in fc:
            lines.append(f"| robot CS FMU, fmpy `simulate_fmu`, reused (extracted, model "
                         f"description and instance kept, as fmpy advises for repeated runs), "
                         f"10 s | {fc['fmu_cs_fmpy_reused'] * 1e3:.1f} ms | native `simulate` "
                         f"{fc['native'] * 1e3:.1f} ms | {fc['ratio_reused']:.2f}x | <= 1.5x |")
        lines.append(f"| robot CS FMU, fmpy `simulate_fmu` of the .fmu file (unzip, XML parse "
                     f"and validation, load each call), 10 s | {fc['fmu_cs_fmpy'] * 1e3:.1f} ms"
                     f" | native `simulate` {fc['native'] * 1e3:.1f} ms | {fc['ratio']:.2f}x | "
                     "<= 1.5x |")
        if "fmu_cs_fmpy_loop" in fc:
            lines.append(f"| robot CS FMU, fmpy `FMU2Slave` loop (no unzip/XML), 10 s | "
                         f"{fc['fmu_cs_fmpy_loop'] * 1e3:.1f} ms | native `simulate` "
                         f"{fc['native'] * 1e3:.1f} ms | {fc['ratio_loop']:.2f}x | |")
    mc = report.get("cosim")
    if mc and mc.get("fmucontainer_s_per_s"):
        lines.append(f"| co-simulation master, robot split, 1 ms (Jacobi) | "
                     f"{mc['master_jacobi_s_per_s']:.3f} s/s | fmucontainer "
                     f"{mc['fmucontainer_s_per_s']:.3f} s/s | "
                     f"{mc['ratio_jacobi_vs_container']:.2f}x | <= 2x |")
    return "\n".join(lines)


def rewrite_readme(path: Path, text: str, stamp: str) -> None:
    doc = path.read_text()
    if MARK_START not in doc or MARK_END not in doc:
        raise SystemExit(f"{path} has no {MARK_START} ... {MARK_END} section")
    head, rest = doc.split(MARK_START, 1)
    _, tail = rest.split(MARK_END, 1)
    path.write_text(f"{head}{MARK_START}\n{stamp}\n\n{text}\n{MARK_END}{tail}")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--full", action="store_true", help="the acceptance sizes (long)")
    ap.add_argument("--json", default="perf.json", help="where to write the report")
    ap.add_argument("--readme", action="store_true",
                    help="rewrite the README's performance table from this run")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--table-from", metavar="JSON",
                    help="no run: rewrite the README's table from a report written earlier")
    args = ap.parse_args()
    if args.table_from:
        report = json.loads(Path(args.table_from).read_text())
        full = report.get("mode") == "full"
        stamp = (f"Generated by `python benchmarks/run_all.py{' --full' if full else ''}` "
                 f"({_METHOD}).")
        rewrite_readme(HERE.parent / "README.md", table(report), stamp)
        print("README performance table rewritten from", args.table_from)
        return 0
    sizes = [100, 1000, 10000, 100000] if args.full else [100, 1000]
    cells = [120, 1200, 12000] if args.full else [120, 1200]
    t0 = time.perf_counter()
    print("RC ladder", flush=True)
    report: dict = {"mode": "full" if args.full else "quick",
                    "machine": {"python": platform.python_version(),
                                "processor": platform.machine()},
                    "rc_ladder": rc_ladder_rows(sizes, scipy_up_to=1000)}
    hand = {r["n"]: r["casadi_cvodes_total"] for r in report["rc_ladder"]}
    vec_sizes = [100, 1000, 10000, 100000] if args.full else [1000, 10000]
    report["rc_ladder_vector"] = vector_ladder_rows(vec_sizes, hand)
    print("disk cache", flush=True)
    report["cache"] = cache_rows([("component per section", 1000), ("array equations", 10000),
                                  (SCALAR_FORM, 1000)]
                                 + ([("component per section", 10000), (SCALAR_FORM, 10000)]
                                    if args.full else []))
    print("JIT", flush=True)
    report["jit"] = jit_rows(args.repeat)
    print("robot CS FMU", flush=True)
    report["fmu_cs"] = fmu_cs_vs_native(max(args.repeat, FMU_REPEAT))
    print("compile scaling", flush=True)
    report["compile"] = compile_rows(cells)
    report["compile_scalar"] = compile_rows(cells, array_path=False)
    print("robot", flush=True)
    report["robot"] = robot(max(args.repeat, FMU_REPEAT))     # runs of milliseconds
    print("co-simulation master", flush=True)
    report["cosim"] = master_vs_container(2.0, max(args.repeat, MASTER_REPEAT))
    report["seconds"] = time.perf_counter() - t0
    Path(args.json).write_text(json.dumps(report, indent=2) + "\n")
    text = table(report)
    print(text)
    print(f"-> {args.json} ({report['seconds']:.0f} s)")
    if args.readme:
        stamp = (f"Generated by `python benchmarks/run_all.py{' --full' if args.full else ''} "
                 f"--readme` ({_METHOD}).")
        rewrite_readme(HERE.parent / "README.md", text, stamp)
        print("README performance table rewritten")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
