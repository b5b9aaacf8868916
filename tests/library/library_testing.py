"""Shared helpers for the component-library tests."""

from __future__ import annotations

import numpy as np

#: Integrator tolerances for comparisons against analytic solutions.
TIGHT = {"rtol": 1e-10, "atol": 1e-12}


def rel_error(actual: np.ndarray, expected: np.ndarray) -> float:
    """Largest deviation relative to the largest magnitude of the expected trajectory."""
    expected = np.asarray(expected, dtype=float)
    return float(np.max(np.abs(np.asarray(actual) - expected)) / np.max(np.abs(expected)))
