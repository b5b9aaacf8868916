"""Fixtures for the structural-algorithm tests: small hand-made DAE graphs."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

_ROOT = str(Path(__file__).resolve().parents[2])
if _ROOT not in sys.path:
    sys.path.insert(0, _ROOT)

from bgmodelica.structure import EquationGraph  # noqa: E402

# Cartesian pendulum variable indices.
X, Y, VX, VY, T, DX, DY, DVX, DVY = range(9)


@pytest.fixture
def pendulum() -> EquationGraph:
    """x'=vx, y'=vy, m vx'=-T x/L, m vy'=-T y/L - m g, x^2+y^2=L^2."""
    eqs = [
        [DX, VX],
        [DY, VY],
        [DVX, T, X],
        [DVY, T, Y],
        [X, Y],
    ]
    return EquationGraph(eqs, 9, [DX, DY, DVX, DVY, -1, -1, -1, -1, -1])


# Two inertias with a rigid speed coupling.
PHI1, W1, PHI2, W2, TAU, DPHI1, DW1, DPHI2, DW2 = range(9)


@pytest.fixture
def inertias() -> EquationGraph:
    """phi1'=w1, phi2'=w2, J1 w1'=tau, J2 w2'=-tau, w1=w2."""
    eqs = [
        [DPHI1, W1],
        [DPHI2, W2],
        [DW1, TAU],
        [DW2, TAU],
        [W1, W2],
    ]
    return EquationGraph(eqs, 9, [DPHI1, DW1, DPHI2, DW2, -1, -1, -1, -1, -1])


@pytest.fixture
def rc_circuit() -> EquationGraph:
    """Index 1: C u' = i, u + R i = u0 (vars u=0, i=1, du=2)."""
    return EquationGraph([[2, 1], [0, 1]], 3, [2, -1, -1])
