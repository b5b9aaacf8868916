"""RC ladder benchmark (the SciML "RC Circuit" model).

A 10 Hz, 1 V sine source drives a chain of n resistors R_i = 1/i; a capacitor C_i = 1/i^2 from
each chain node to ground starts at v = i. Simulated 0..10 s with the default solver (CVODES:
the model reduces to an ODE; sparse direct linear solver). Prints build (flatten + compile)
and solve seconds per n, and the stage split.

    python benchmarks/rc_ladder.py [n ...]
    python benchmarks/rc_ladder.py --units [n]     # compile time with and without the unit check
    python benchmarks/rc_ladder.py --forms [n]     # the four forms against the hand-written floor
"""

from __future__ import annotations

import sys
import time

import bgmodelica as bg
from bgmodelica import Component
from library.examples.circuits import RCLadder


def rc_ladder(n: int) -> Component:
    """The ladder as a component network, one resistor and one capacitor per section
    (:class:`library.examples.circuits.RCLadder`)."""
    return RCLadder(n)


def run(n: int) -> dict[str, float]:
    t0 = time.perf_counter()
    model = rc_ladder(n)
    t1 = time.perf_counter()
    compiled = bg.compile(model)
    t2 = time.perf_counter()
    result = bg.simulate(compiled, stop_time=10.0, interval=0.01, rtol=1e-6, atol=1e-6,
                         outputs=[f"C{n}.v", "C1.v"])
    t3 = time.perf_counter()
    return {"n": n, "construct": t1 - t0, "compile": t2 - t1, "build": t2 - t0,
            "solve": t3 - t2, "total": t3 - t0, "states": len(compiled.dae.state_names),
            "steps": result.meta["stats"].get("n_step", float("nan")),
            "first_final": float(result["C1.v"][-1]), "last_final": float(result[f"C{n}.v"][-1]),
            **{f"stage_{k}": v for k, v in compiled.timings.items()}}


def units_overhead(n: int, reps: int = 3) -> None:
    """Compile the ladder with ``units="off"`` and ``"error"`` alternately in this process
    (pint and its registry loaded beforehand) and print the best time of each."""
    import gc

    from bgmodelica.core.units import parse

    t0 = time.perf_counter()
    parse("V")
    print(f"unit registry ready in {time.perf_counter() - t0:.3f} s (once per process; "
          "nothing when the units were seen before)")
    best = {"off": float("inf"), "error": float("inf")}
    stage = {"off": float("inf"), "error": float("inf")}
    for rep in range(reps):
        for mode in ("off", "error") if rep % 2 == 0 else ("error", "off"):
            model = rc_ladder(n)
            gc.collect()
            t1 = time.perf_counter()
            compiled = bg.compile(model, units=mode)
            best[mode] = min(best[mode], time.perf_counter() - t1)
            stage[mode] = min(stage[mode], compiled.timings["units"])
            del compiled, model
    extra = best["error"] - best["off"]
    check = stage["error"] - stage["off"]       # the "units" lap also frees the equation trees
    print(f"n={n}: compile {best['off']:.3f} s without the unit check, {best['error']:.3f} s "
          f"with it ({extra:+.3f} s, {100 * extra / best['off']:+.1f}%); the check itself "
          f"{check:.3f} s ({100 * check / best['off']:.1f}%)")


def forms(n: int, reps: int = 2) -> None:
    """The four forms of the ladder (array equations, arrays of components, a component per
    section, a ``Section`` component per section) and the hand-written CasADi/CVODES floor,
    alternating, best of ``reps`` each: construct, compile and 10-s simulation seconds."""
    import gc

    from run_all import ladder_by_hand

    from library.examples.circuits import RCLadderArrays, RCLadderSections, RCLadderVector

    best: dict[str, tuple[float, ...]] = {}
    floor = float("inf")
    for _ in range(reps):
        for cls in (RCLadderVector, RCLadderArrays, RCLadder, RCLadderSections):
            gc.collect()
            t0 = time.perf_counter()
            model = cls(n)
            t1 = time.perf_counter()
            compiled = bg.compile(model)
            t2 = time.perf_counter()
            bg.simulate(compiled, stop_time=10.0, interval=0.01, rtol=1e-6, atol=1e-6,
                        outputs=[compiled.dae.state_names[0]])
            t3 = time.perf_counter()
            row = (t1 - t0, t2 - t1, t3 - t2, t3 - t0)
            if cls.__name__ not in best or row[3] < best[cls.__name__][3]:
                best[cls.__name__] = row
            del compiled, model
        gc.collect()
        floor = min(floor, ladder_by_hand(n)["total"])
    print(f"n={n}, CasADi/CVODES by hand {floor:.3f} s")
    print(f"{'form':>16} {'construct':>10} {'compile':>8} {'simulate':>9} {'total':>7}  ratio")
    for name, (a, b, c, d) in best.items():
        print(f"{name:>16} {a:>10.3f} {b:>8.3f} {c:>9.3f} {d:>7.3f}  {d / floor:.2f}x")


def main(argv: list[str]) -> None:
    if argv[:1] == ["--units"]:
        units_overhead(int(argv[1]) if len(argv) > 1 else 10000)
        return
    if argv[:1] == ["--forms"]:
        forms(int(argv[1]) if len(argv) > 1 else 10000)
        return
    sizes = [int(a) for a in argv] or [10, 100, 1000, 10000]
    print(f"{'n':>6} {'build[s]':>9} {'solve[s]':>9} {'total[s]':>9}  stages")
    for n in sizes:
        r = run(n)
        stages = ", ".join(f"{k[6:]} {v:.2f}" for k, v in r.items() if k.startswith("stage_"))
        print(f"{n:>6} {r['build']:>9.3f} {r['solve']:>9.3f} {r['total']:>9.3f}  "
              f"construct {r['construct']:.2f}, {stages}")
    print("targets on 2 cores: n=1000 total < 1 s, n=10000 total < 10 s")


if __name__ == "__main__":
    main(sys.argv[1:])
