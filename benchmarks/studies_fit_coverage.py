"""Are the 95 % intervals of ``bgmodelica.fit`` honest? Fit R, k and J of the DC motor to
many noisy step responses (1 % Gaussian noise, a new seed each time) and count how often each
interval contains the truth (about 95 % expected), with the mean standard error and the
spread of the estimates (they should agree).

    .venv/bin/python benchmarks/studies_fit_coverage.py [--fits 100]
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))

TRUTH = {"resistor.R": 1.0, "emf.k": 0.1, "rotor.J": 0.002}
COLS = ["rotor.w", "inductor.i"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fits", type=int, default=100)
    args = ap.parse_args()

    import bgmodelica as bg
    from bgmodelica.loader import load_model

    compiled = bg.compile(load_model("library.examples.motors:DCMotor"))
    truth = bg.simulate(compiled, 2.0, 0.01, outputs=COLS, rtol=1e-10, atol=1e-12)
    sigma = {c: 0.01 * float(np.max(np.abs(truth[c]))) for c in COLS}
    hits = {n: 0 for n in TRUTH}
    est = {n: [] for n in TRUTH}
    se = {n: [] for n in TRUTH}
    t0 = time.perf_counter()
    for seed in range(args.fits):
        rng = np.random.default_rng(1000 + seed)
        data = {"time": truth.time}
        for c in COLS:
            data[c] = truth[c] + sigma[c] * rng.standard_normal(len(truth.time))
        res = bg.fit(compiled, data, {"resistor.R": 1.5, "emf.k": 0.07, "rotor.J": 0.004},
                     weights={c: 1 / s for c, s in sigma.items()})
        for n, v in TRUTH.items():
            lo, hi = res.ci95[n]
            hits[n] += lo <= v <= hi
            est[n].append(res.estimates[n])
            se[n].append(res.std_errors[n])
    wall = time.perf_counter() - t0
    print(f"{args.fits} fits in {wall:.1f} s ({wall / args.fits:.2f} s each)")
    for n in TRUTH:
        print(f"  {n:<11} coverage of the 95 % interval {hits[n] / args.fits:6.1%}; "
              f"mean std error {np.mean(se[n]):.3g} vs spread of the estimates "
              f"{np.std(est[n], ddof=1):.3g}; mean bias {np.mean(est[n]) - TRUTH[n]:+.2g}")


if __name__ == "__main__":
    main()
