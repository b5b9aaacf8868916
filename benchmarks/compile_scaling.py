"""Compile-time scaling: flatten + alias + balance + index reduction + sorting + backend for
models of about 10^3, 10^4 and 10^5 flat equations (the RC ladder, which takes the array path,
and again through the scalar pipeline; a chain of rigidly coupled inertia pairs, which needs
index reduction in every cell). Prints seconds per stage and the fitted growth exponent
(time ~ equations^k).

    python benchmarks/compile_scaling.py
    python benchmarks/compile_scaling.py --json 3 120 1200   # ladder rows, best of 3, as JSON
    python benchmarks/compile_scaling.py --json-scalar 3 120 1200   # the same, scalar pipeline
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from rc_ladder import rc_ladder  # noqa: E402

import bgmodelica as bg  # noqa: E402
from bgmodelica import Component  # noqa: E402
from library.rotational import Damper, Fixed, Inertia, Spring  # noqa: E402


def inertia_chain(n: int) -> Component:
    """n cells of two rigidly coupled inertias, cells joined by spring-dampers (index 2)."""
    m = Component(name=f"InertiaChain{n}")
    fixed = m.add("fixed", Fixed())
    prev = fixed.flange
    for i in range(n):
        a = m.add(f"a{i}", Inertia(J=1.0, phi=dict(start=0.01 * i, fixed=True),
                                   w=dict(start=0.0, fixed=True)))
        b = m.add(f"b{i}", Inertia(J=2.0))
        s = m.add(f"s{i}", Spring(c=100.0))
        d = m.add(f"d{i}", Damper(d=1.0))
        m.connect(prev, s.flange_a)
        m.connect(prev, d.flange_a)
        m.connect(s.flange_b, a.flange_a)
        m.connect(d.flange_b, a.flange_a)
        m.connect(a.flange_b, b.flange_a)
        prev = b.flange_b
    return m


def measure(factory, n: int, array_path: bool = True) -> tuple[int, float, dict[str, float]]:
    model = factory(n)
    t0 = time.perf_counter()
    compiled = bg.compile(model, array_path=array_path)
    return compiled.n_flat_equations, time.perf_counter() - t0, compiled.timings


def ladder_rows(sizes: list[int], repeat: int, array_path: bool = True) -> list[dict]:
    """Compile the RC ladder of each size ``repeat`` times (best kept): equations, seconds
    and microseconds per equation (``array_path=False``: through the scalar pipeline)."""
    import gc

    measure(rc_ladder, 10)                                   # warm: unit registry, imports
    rows = []
    for n in sizes:
        best = float("inf")
        for _ in range(repeat):
            gc.collect()
            n_eq, secs, _ = measure(rc_ladder, n, array_path)
            best = min(best, secs)
        rows.append({"cells": n, "equations": n_eq, "seconds": best,
                     "us_per_equation": 1e6 * best / n_eq})
    return rows


def main() -> None:
    if len(sys.argv) > 1 and sys.argv[1] in ("--json", "--json-scalar"):   # REPEAT N...
        print(json.dumps(ladder_rows([int(a) for a in sys.argv[3:]], int(sys.argv[2]),
                                     sys.argv[1] == "--json")))
        return
    for label, factory, sizes, arrays in (
            ("RC ladder", rc_ladder, (120, 1200, 12000), True),
            ("RC ladder, scalar pipeline", rc_ladder, (120, 1200, 12000), False),
            ("inertia chain (index 2)", inertia_chain, (40, 400, 4000), True)):
        print(f"{label}:")
        print(f"{'equations':>10} {'compile[s]':>11}  stages")
        eqs, secs = [], []
        for n in sizes:
            n_eq, total, stages = measure(factory, n, arrays)
            eqs.append(n_eq)
            secs.append(total)
            print(f"{n_eq:>10} {total:>11.3f}  "
                  + ", ".join(f"{k} {v:.2f}" for k, v in stages.items()))
        k = np.polyfit(np.log(eqs), np.log(secs), 1)[0]
        print(f"  growth exponent k (compile time ~ equations^k): {k:.2f}\n")


if __name__ == "__main__":
    main()
