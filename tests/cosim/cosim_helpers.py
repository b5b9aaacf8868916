"""Shared constants and helpers of the co-simulation tests."""

from __future__ import annotations

import numpy as np

HORIZON = 1.0          # [s] co-simulation horizon of the tests (``verify`` uses 10 s)
GRID = 5e-4            # output grid of the monolithic reference [s]
TIGHT = 1e-10          # solver.tolerance of the CS FMUs in convergence tests


def joint_errors(result, reference) -> list[float]:
    """max |q_j cosim - q_j mono| over the communication points, j = 1, 2."""
    idx = np.round(result.time / GRID).astype(int)
    return [float(np.max(np.abs(result[f"arm.q{j}"] - reference[f"arm.q{j}"][idx])))
            for j in (1, 2)]


def tight(system) -> dict[str, dict[str, float]]:
    return {el: {"solver.tolerance": TIGHT} for el in system.element_names}
