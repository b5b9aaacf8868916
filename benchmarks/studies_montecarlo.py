"""Monte Carlo of the PID robot on Dask: throughput with local workers vs serial, per-run cost
vs one plain ``simulate`` of the compiled model, and what shipping the model to a worker costs.

200 runs of ``library.robots:RobotPID`` over 10 s (output every 10 ms), link masses m1, m2 and
motor resistances motor1.R, motor2.R uniform within +-5 % of their values, seed 1.

    .venv/bin/python benchmarks/studies_montecarlo.py [--runs 200] [--workers 2] [--plot PNG]

Prints (in the same run, same machine):

* compile time, pickled model size, unpickle time vs compile time (the worker-side cost of
  receiving the model, once per worker);
* one plain ``simulate(compiled, 10 s)`` (median of 5, default parameters) and a plain loop
  of ``simulate`` over the study's parameter sets, wall and CPU time;
* the study serially in this process (``scheduler="serial"``): runs/s and CPU per run against
  one plain simulate (aim <= 1.2x: compilation amortized) and against the plain loop;
* the study on a LocalCluster of ``--workers`` processes (start-up reported separately), a
  first and a second (warm) study: runs/s, speed-up vs serial (aim >= 1.6x with 2 workers on
  2 cores) and the workers' CPU per run, Dask's overhead included.

The CPU figures do not depend on other load on the machine; the wall-clock ones (throughput,
speed-up) do: the load average is printed at the start and at the end.
"""

from __future__ import annotations

import argparse
import logging
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))

OUTPUTS = ["arm.joint1.q", "arm.joint2.q", "e1", "e2", "motor1.inductor.i",
           "motor2.inductor.i"]
SPREAD = {"m1": "+-5%", "m2": "+-5%", "motor1.R": "+-5%", "motor2.R": "+-5%"}


def _bare_loop(n: int) -> float:
    """Seconds for ``n`` plain simulate runs in a fresh process (the machine's parallelism
    check: no Dask involved)."""
    import bgmodelica as bg
    from bgmodelica.loader import load_model

    compiled = bg.compile(load_model("library.robots:RobotPID"))
    kw = dict(stop_time=10.0, interval=0.01, outputs=OUTPUTS, solver="cvodes")
    bg.simulate(compiled, **kw)
    t = time.perf_counter()
    for i in range(n):
        _ = bg.simulate(compiled, params={"m1": 3.0 + 1e-3 * i}, **kw).values
    return time.perf_counter() - t


def capacity(workers: int, n: int = 100) -> float:
    """How much faster ``workers`` bare processes get through their runs than one: what the
    machine offers right now (other jobs share its cores)."""
    import multiprocessing as mp

    ctx = mp.get_context("spawn")
    with ctx.Pool(1) as pool:
        one = pool.map(_bare_loop, [n])[0]
    with ctx.Pool(workers) as pool:
        many = max(pool.map(_bare_loop, [n] * workers))
    return workers * one / many


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=200)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--stop-time", type=float, default=10.0)
    ap.add_argument("--repeats", type=int, default=3,
                    help="alternating serial / distributed pairs after the first two studies")
    ap.add_argument("--solver", default="cvodes", help="cvodes (default) or idas")
    ap.add_argument("--plot", default=None,
                    help="band plot of the motor-1 current (PNG)")
    args = ap.parse_args()

    import bgmodelica as bg
    from bgmodelica.loader import load_model
    from bgmodelica.studies import sweep
    from bgmodelica.studies.payload import pickle_compiled, unpickle_compiled

    print(f"load average at start: {os.getloadavg()[0]:.2f} ({os.cpu_count()} cores)")
    t = time.perf_counter()
    compiled = bg.compile(load_model("library.robots:RobotPID"))
    t_compile = time.perf_counter() - t
    blob = pickle_compiled(compiled)
    t = time.perf_counter()
    unpickle_compiled(blob)
    t_unpickle = time.perf_counter() - t
    print(f"compile {t_compile:.3f} s; pickled compiled model {len(blob) / 1e3:.0f} kB, "
          f"unpickled in {t_unpickle * 1e3:.1f} ms (what a worker pays once instead of "
          "compiling)")

    kw = dict(stop_time=args.stop_time, interval=0.01, outputs=OUTPUTS, solver=args.solver)
    import xarray  # noqa: F401  -- imported before the clocks run (the study uses it)

    bg.simulate(compiled, **kw)                                   # warm: integrators built
    plain, plain_cpu = [], []
    for _ in range(5):                  # the outputs are read, as the study does (lazy)
        t, c = time.perf_counter(), time.process_time()
        _ = bg.simulate(compiled, **kw).values
        plain.append(time.perf_counter() - t)
        plain_cpu.append(time.process_time() - c)
    t_plain, c_plain = statistics.median(plain), statistics.median(plain_cpu)
    print(f"plain simulate of the compiled model, {args.stop_time:g} s ({args.solver}): "
          f"{t_plain * 1e3:.1f} ms wall, {c_plain * 1e3:.1f} ms CPU (median of 5)")

    study = dict(samples=args.runs, distributions=SPREAD, seed=1, progress=False, **kw)
    sweep(compiled, scheduler="serial", **{**study, "samples": 2})   # one-off imports
    c = time.process_time()
    serial = sweep(compiled, scheduler="serial", **study)
    c_serial = (time.process_time() - c) / args.runs
    w_serial = serial.meta["wall_seconds"]
    names = serial.parameters
    draws = [{n: float(serial[n].values[k]) for n in names} for k in range(args.runs)]
    t, c = time.perf_counter(), time.process_time()
    for d in draws:                              # the same runs as plain simulate calls
        _ = bg.simulate(compiled, params=d, **kw).values
    t_loop = (time.perf_counter() - t) / args.runs
    c_loop = (time.process_time() - c) / args.runs
    print(f"plain simulate loop over the same {args.runs} parameter sets: "
          f"{t_loop * 1e3:.1f} ms wall, {c_loop * 1e3:.1f} ms CPU per run "
          f"({c_loop / c_plain:.2f}x the default-parameter run: the solver's work varies)")
    print(f"serial study: {args.runs} runs in {w_serial:.2f} s = {args.runs / w_serial:.1f} "
          f"runs/s; CPU per run {c_serial * 1e3:.1f} ms = {c_serial / c_plain:.2f}x one plain "
          f"simulate, {c_serial / c_loop:.2f}x the plain loop ({serial.meta['n_failed']} "
          "failed)")

    from distributed import Client, LocalCluster

    t = time.perf_counter()
    cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                           dashboard_address=None, silence_logs=logging.ERROR,
                           preload=["bgmodelica.studies.worker"])
    client = Client(cluster)
    t_start = time.perf_counter() - t

    def worker_cpu() -> float:
        import psutil

        def cpu() -> float:
            ct = psutil.Process().cpu_times()
            return ct.user + ct.system

        return sum(client.run(cpu).values())

    try:
        results = []
        for _label in ("first study", "second study (warm)"):
            c0 = worker_cpu()
            res = sweep(compiled, client=client, **study)
            results.append((res, (worker_cpu() - c0) / args.runs))
        from bgmodelica.studies import payload as payload_mod

        stats = client.run(lambda: dict(payload_mod.STATS))
        pairs = []           # serial and distributed alternately: both see the same load
        for _ in range(args.repeats):
            a = sweep(compiled, scheduler="serial", **study).meta["wall_seconds"]
            b = sweep(compiled, client=client, **study).meta["wall_seconds"]
            pairs.append((a, b, os.getloadavg()[0]))
    finally:
        client.close()
        cluster.close()
    dist = results[0][0]
    same = float(abs(dist["arm.joint1.q"].values - serial["arm.joint1.q"].values).max())
    used = sorted(set(dist["worker"].values))
    print(f"LocalCluster of {args.workers} workers started in {t_start:.2f} s; model on the "
          "workers: " + "; ".join(f"{how['how']} in {how['seconds'] * 1e3:.1f} ms"
                                  for w in stats.values() for how in w.values()))
    for label, (res, cpu) in zip(("first study", "second study (warm)"), results,
                                 strict=True):
        wall = res.meta["wall_seconds"]
        print(f"{args.workers} workers, {label}: {args.runs} runs in {wall:.2f} s = "
              f"{args.runs / wall:.1f} runs/s, speed-up vs serial {w_serial / wall:.2f}x; "
              f"worker CPU per run (runs + Dask) {cpu * 1e3:.1f} ms = {cpu / c_plain:.2f}x one "
              f"plain simulate, {cpu / c_loop:.2f}x the plain loop")
    for a, b, load in pairs:
        print(f"alternating: serial {a:.2f} s, {args.workers} workers {b:.2f} s: speed-up "
              f"{a / b:.2f}x (load average {load:.1f})")
    print(f"median speed-up of the alternating pairs: "
          f"{statistics.median(a / b for a, b, _ in pairs):.2f}x")
    print(f"parallelism check without Dask: {args.workers} bare processes running plain "
          f"simulate loops get {capacity(args.workers):.2f}x the throughput of one right now "
          f"(load average {os.getloadavg()[0]:.1f})")
    print(f"runs spread over {len(used)} worker processes; max |serial - distributed| of "
          f"joint 1 = {same:.1e} rad")
    print(f"load average at the end: {os.getloadavg()[0]:.2f}")
    if args.plot:
        dist.plot_band("motor1.inductor.i", args.plot, show_runs=0)
        print(f"band plot -> {args.plot}")


if __name__ == "__main__":
    main()
