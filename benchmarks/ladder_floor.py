"""The RC ladder on the user's path against the hand-written floor, in one run.

The floor: the ladder written by hand as one CasADi SX vector ODE (sections k = 1..n,
R_k = 1/k Ohm, C_k = 1/k^2 F, v_k(0) = k V, source sin(2 pi 10 t) V), integrated by CVODES
over 10 s with outputs every 0.01 s, rtol = atol = 1e-6, sparse direct linear solver, all
states returned: build + solve seconds. The user's path, in the same process:
``bg.simulate(Model(n), stop_time=10.0, interval=0.01, rtol=1e-6, atol=1e-6)`` for
``RCLadder`` (a component per section) and ``RCLadderSections`` (a ``Section`` holding R and
C per rung): construct, compile and simulate seconds (default outputs), the ratio to the
floor (best of ``--repeat`` runs each, alternating), and whether both give the same
voltages. Targets: RCLadder <= 2.0x, RCLadderSections <= 2.5x at n = 10,000.

    python benchmarks/ladder_floor.py [n ...] [--repeat R]    # default n = 10000, R = 3
    python benchmarks/ladder_floor.py --memory [n ...]        # each run in a fresh process:
                                                              # seconds and peak memory

With ``--memory``, from n = 50,000 the runs record the capacitor voltages only (the states,
as the floor returns them): every variable at every point would be 600,000 values x 1001
points at n = 100,000, which ``simulate`` refuses as too large to hold.
"""

from __future__ import annotations

import gc
import resource
import subprocess
import sys
import time

import casadi as ca
import numpy as np

import bgmodelica as bg
from library.examples.circuits import RCLadder, RCLadderSections

FORMS = {"RCLadder": RCLadder, "RCLadderSections": RCLadderSections}


def floor(n: int) -> tuple[float, np.ndarray]:
    """(build + solve seconds, final voltages) of the hand-written ladder."""
    t0 = time.perf_counter()
    v = ca.SX.sym("v", n)
    t = ca.SX.sym("t")
    k = np.arange(1, n + 1, dtype=float)
    current = (ca.vertcat(ca.sin(2 * np.pi * 10 * t), v[:-1]) - v) * k      # R_k = 1/k
    ode = (current - ca.vertcat(current[1:], 0)) * k**2                       # C_k = 1/k^2
    grid = np.arange(0.01, 10.0001, 0.01)
    f = ca.integrator("F", "cvodes", {"x": v, "t": t, "ode": ode}, 0, grid,
                      {"reltol": 1e-6, "abstol": 1e-6, "linear_solver": "csparse"})
    xf = f(x0=k)["xf"]
    seconds = time.perf_counter() - t0
    return seconds, np.asarray(xf[:, -1]).ravel()


def ours(form: str, n: int, read: bool = True,
         states_only: bool = False) -> tuple[tuple[float, float, float], np.ndarray]:
    """((construct, compile, simulate) seconds, final voltages) on the user's path; with
    ``read`` False the voltages are not read (reading one variable of a run that records
    all evaluates them all); ``states_only``: record the capacitor voltages only."""
    name = "C{}.v" if form == "RCLadder" else "section{}.C.v"
    outputs = [name.format(k) for k in range(1, n + 1)] if states_only else None
    t0 = time.perf_counter()
    model = FORMS[form](n)
    t1 = time.perf_counter()
    compiled = bg.compile(model)
    t2 = time.perf_counter()
    result = bg.simulate(compiled, stop_time=10.0, interval=0.01, rtol=1e-6, atol=1e-6,
                         outputs=outputs)
    t3 = time.perf_counter()
    if not read:
        return (t1 - t0, t2 - t1, t3 - t2), np.zeros(0)
    final = np.array([result[name.format(k)][-1] for k in (1, n // 2, n)])
    return (t1 - t0, t2 - t1, t3 - t2), final


def compare(n: int, repeat: int) -> None:
    bg.simulate(RCLadder(20), stop_time=0.1)            # imports and first calls, once
    best_floor, best = float("inf"), {form: (float("inf"),) * 3 for form in FORMS}
    finals: dict[str, np.ndarray] = {}
    for _ in range(repeat):
        gc.collect()
        seconds, v_floor = floor(n)
        best_floor = min(best_floor, seconds)
        for form in FORMS:
            gc.collect()
            laps, finals[form] = ours(form, n)
            if sum(laps) < sum(best[form]):
                best[form] = laps
    print(f"n={n}: hand-written CasADi/CVODES floor {best_floor:.3f} s (best of {repeat})")
    print(f"{'form':>17} {'construct':>10} {'compile':>8} {'simulate':>9} {'total':>7}  ratio")
    for form, laps in best.items():
        print(f"{form:>17} {laps[0]:>10.3f} {laps[1]:>8.3f} {laps[2]:>9.3f} {sum(laps):>7.3f}"
              f"  {sum(laps) / best_floor:.2f}x")
    picks = v_floor[[0, n // 2 - 1, n - 1]]
    same = np.array_equal(finals["RCLadder"], finals["RCLadderSections"])
    print(f"final voltages (sections 1, n/2, n): identical forms: {same}; largest difference "
          f"to the floor {np.max(np.abs(finals['RCLadder'] - picks)):.1e} V")


def memory(sizes: list[int]) -> None:
    """Each form and the floor in a fresh process: seconds and peak resident memory."""
    print(f"{'n':>7} {'form':>17} {'seconds':>8} {'peak MB':>8}")
    for n in sizes:
        for form in ("floor", *FORMS):
            out = subprocess.run([sys.executable, __file__, "--one", form, str(n)],
                                 capture_output=True, text=True, check=True).stdout.split()
            print(f"{n:>7} {form:>17} {float(out[0]):>8.2f} {float(out[1]):>8.0f}")


def one(form: str, n: int) -> None:
    bg.simulate(RCLadder(20), stop_time=0.1)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    seconds = floor(n)[0] if form == "floor" else \
        sum(ours(form, n, read=False, states_only=n >= 50_000)[0])
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    print(seconds, max(peak, before) / 1024)


def main(argv: list[str]) -> None:
    if argv[:1] == ["--one"]:
        one(argv[1], int(argv[2]))
        return
    repeat = 3
    if "--repeat" in argv:
        k = argv.index("--repeat")
        repeat = int(argv[k + 1])
        del argv[k:k + 2]
    if argv[:1] == ["--memory"]:
        memory([int(a) for a in argv[1:]] or [100000])
        return
    for n in [int(a) for a in argv] or [10000]:
        compare(n, repeat)


if __name__ == "__main__":
    main(sys.argv[1:])
