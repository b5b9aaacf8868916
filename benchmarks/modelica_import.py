"""RC ladder from Modelica text against the same ladder built in Python, in the same run.

The Modelica form is ``Circuits.RCLadder`` of ``tests/modelica/models/circuits.mo``: its own
MSL-style components (``extends OnePort``), component arrays ``Resistor R[n]``,
``Capacitor C[n]`` with array modifiers and ``for`` loops of ``connect``. The Python form is
``benchmarks/rc_ladder.py``'s imperative construction (the SciML benchmark). Both are
simulated 0..10 s with IDAS (rtol = atol = 1e-6, as rc_ladder.py). Each form is timed
``--repeat`` times, alternating, after one warm-up of each (the first Modelica load of a
machine also builds lark's parser tables, cached afterwards: reported separately); the
figure is the ratio of the best load + compile + simulate times. Target: <= 1.5.

    python benchmarks/modelica_import.py [--n 1000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import gc
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from rc_ladder import rc_ladder  # noqa: E402

import bgmodelica as bg  # noqa: E402

MO = ROOT / "tests" / "modelica" / "models" / "circuits.mo"


def run_modelica(n: int) -> tuple[dict[str, float], object]:
    t0 = time.perf_counter()
    model = bg.load_modelica(MO, "Circuits.RCLadder", n=n)
    t1 = time.perf_counter()
    compiled = bg.compile(model)
    t2 = time.perf_counter()
    res = bg.simulate(compiled, stop_time=10.0, interval=0.01, rtol=1e-6, atol=1e-6,
                      outputs=[f"C[{n}].v", "C[1].v"])
    t3 = time.perf_counter()
    return {"load": t1 - t0, "compile": t2 - t1, "simulate": t3 - t2, "total": t3 - t0}, res


def run_python(n: int) -> tuple[dict[str, float], object]:
    t0 = time.perf_counter()
    model = rc_ladder(n)
    t1 = time.perf_counter()
    compiled = bg.compile(model)
    t2 = time.perf_counter()
    res = bg.simulate(compiled, stop_time=10.0, interval=0.01, rtol=1e-6, atol=1e-6,
                      outputs=[f"C{n}.v", "C1.v"])
    t3 = time.perf_counter()
    return {"load": t1 - t0, "compile": t2 - t1, "simulate": t3 - t2, "total": t3 - t0}, res


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1000)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    n = args.n

    t0 = time.perf_counter()
    from bgmodelica.modelica import msl, parser

    parser._lark()
    msl.stub_scope()
    setup = time.perf_counter() - t0

    first_mo, res_mo = run_modelica(n)
    first_py, res_py = run_python(n)
    diff = max(float(np.max(np.abs(np.asarray(res_mo[f"C[{k}].v"])
                                   - np.asarray(res_py[f"C{k}.v"])))) for k in (1, n))
    best: dict[str, dict[str, float]] = {}
    for _ in range(args.repeat):
        for label, fn in (("modelica", run_modelica), ("python", run_python)):
            gc.collect()
            t, _ = fn(n)
            if label not in best or t["total"] < best[label]["total"]:
                best[label] = t
    print(f"RC ladder n = {n}: load + compile + simulate (0..10 s), best of {args.repeat}")
    print(f"{'form':>10} {'load[s]':>9} {'compile[s]':>11} {'simulate[s]':>12} {'total[s]':>9}")
    for label in ("modelica", "python"):
        t = best[label]
        print(f"{label:>10} {t['load']:>9.3f} {t['compile']:>11.3f} {t['simulate']:>12.3f} "
              f"{t['total']:>9.3f}")
    ratio = best["modelica"]["total"] / best["python"]["total"]
    print(f"ratio Modelica / Python: {ratio:.2f} (target <= 1.5)")
    print(f"first runs: Modelica {first_mo['total']:.3f} s, Python {first_py['total']:.3f} s; "
          f"parser tables + MSL stub once per process: {setup:.3f} s")
    print(f"max |C[k].v - Ck.v| (k = 1, n): {diff:.3g}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
