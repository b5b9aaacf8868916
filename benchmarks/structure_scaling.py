"""Scaling of the structural pipeline on synthetic sparse DAEs.

The model is a chain of K drive-line cells. Cell k has two inertias rigidly coupled through
their speeds (w1 = w2, index 2) and a spring-damper to the previous cell whose torque f is an
algebraic variable:

    phi1' = w1,  phi2' = w2,  J1 w1' = tau + f_k,  J2 w2' = -tau - f_{k+1},  w1 = w2,
    f_k = c (phi2_{k-1} - phi1_k) + d (w2_{k-1} - w1_k)

Incidence lists and equation order are shuffled so greedy matching is not enough. Timed:
Hopcroft-Karp on the original system, Pantelides, dummy derivatives, and BLT (with its own
matching) of the reduced system with states removed. Prints a table and the fitted exponent
of total time versus the number of equations, next to the exponent of a bare pass over the
incidence: Python's memory and cache effects alone make that one grow faster than linearly.

Run: .venv/bin/python benchmarks/structure_scaling.py
"""

from __future__ import annotations

import math
import random
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bgmodelica.structure import (  # noqa: E402
    EquationGraph,
    block_lower_triangular,
    dummy_derivatives,
    maximum_matching,
    pantelides,
)

NV = 10  # variables per cell: phi1 w1 phi2 w2 tau f dphi1 dw1 dphi2 dw2


def build(cells: int, seed: int = 0) -> EquationGraph:
    rng = random.Random(seed)
    eqs: list[list[int]] = []
    var_der = [-1] * (NV * cells)
    for k in range(cells):
        o = NV * k
        phi1, w1, phi2, w2, tau, f, dphi1, dw1, dphi2, dw2 = range(o, o + NV)
        var_der[phi1], var_der[w1], var_der[phi2], var_der[w2] = dphi1, dw1, dphi2, dw2
        nxt_f = f + NV if k + 1 < cells else None
        eqs.append([dphi1, w1])
        eqs.append([dphi2, w2])
        eqs.append([dw1, tau, f])
        eqs.append([dw2, tau] + ([nxt_f] if nxt_f is not None else []))
        eqs.append([w1, w2])
        if k == 0:
            eqs.append([f, phi1, w1])
        else:
            eqs.append([f, phi1, w1, phi2 - NV, w2 - NV])
    for vs in eqs:
        rng.shuffle(vs)
    order = list(range(len(eqs)))
    rng.shuffle(order)
    return EquationGraph([eqs[i] for i in order], NV * cells, var_der)


def run(cells: int) -> dict[str, float]:
    g = build(cells)
    times: dict[str, float] = {"eqs": g.n_eqs}
    t0 = time.perf_counter()
    mark = [0] * g.n_vars  # baseline: one pure-Python pass over the incidence
    for vs in g.eq_vars:
        for v in vs:
            mark[v] += 1
    times["scan"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    highest = [d == -1 for d in g.var_derivative]
    m = maximum_matching(g.eq_vars, g.n_vars, highest)
    times["matching"] = time.perf_counter() - t0
    assert m.size == g.n_eqs - cells  # one w1 = w2 constraint per cell is structurally singular

    t0 = time.perf_counter()
    pr = pantelides(g)
    times["pantelides"] = time.perf_counter() - t0
    assert pr.index == 2 and len(pr.new_equations) == cells

    t0 = time.perf_counter()
    dd = dummy_derivatives(pr.graph)
    times["dummy"] = time.perf_counter() - t0
    assert len(dd.dummies) == cells

    t0 = time.perf_counter()
    states = set(dd.states)
    unknown_id = [-1] * pr.graph.n_vars
    n_unknowns = 0
    for v in range(pr.graph.n_vars):
        if v not in states:
            unknown_id[v] = n_unknowns
            n_unknowns += 1
    sys_eqs = [[unknown_id[v] for v in vs if unknown_id[v] != -1] for vs in pr.graph.eq_vars]
    blocks = block_lower_triangular(sys_eqs, n_unknowns)
    times["blt"] = time.perf_counter() - t0
    times["blocks"] = len(blocks)
    times["largest"] = max(b.size for b in blocks)
    times["total"] = times["matching"] + times["pantelides"] + times["dummy"] + times["blt"]
    return times


def main() -> None:
    rows = []
    print(f"{'equations':>10} {'scan':>7} {'matching':>9} {'pantelides':>11} {'dummy':>8} "
          f"{'blt':>8} {'total':>8} {'blocks':>8} {'largest':>8}")
    for n in (1_000, 10_000, 100_000):
        r = run(n // 6)
        rows.append(r)
        print(f"{int(r['eqs']):>10} {r['scan']:>7.4f} {r['matching']:>9.3f} "
              f"{r['pantelides']:>11.3f} {r['dummy']:>8.3f} {r['blt']:>8.3f} {r['total']:>8.3f} "
              f"{int(r['blocks']):>8} {int(r['largest']):>8}")
    xs = [math.log(r["eqs"]) for r in rows]
    print(f"fitted growth exponent (total time ~ n^k): k = {_slope(xs, rows, 'total'):.2f}")
    print(f"same for one bare pass over the incidence (memory/cache effects): "
          f"k = {_slope(xs, rows, 'scan'):.2f}")


def _slope(xs: list[float], rows: list[dict[str, float]], key: str) -> float:
    ys = [math.log(r[key]) for r in rows]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys, strict=True)) / sum(
        (x - mx) ** 2 for x in xs)


if __name__ == "__main__":
    main()
