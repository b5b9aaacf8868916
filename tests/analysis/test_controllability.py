"""Numeric controllability / observability by the scaled staircase form."""

from __future__ import annotations

import numpy as np

from bgmodelica.analysis import controllability, observability
from bgmodelica.analysis.controllability import minimal_realization


def test_uncontrollable_mode_found():
    # two decoupled first-order lags, only the first driven
    A = np.diag([-1.0, -3.0])
    B = np.array([[1.0], [0.0]])
    r = controllability(A, B, states=["a", "b"])
    assert (r.rank, r.n, r.ok) == (1, 2, False)
    assert np.allclose(r.modes, [-3.0])
    assert r.weakest_states() == ["b"]
    o = observability(A, np.array([[1.0, 1.0]]))
    assert o.rank == 2 and o.ok


def test_repeated_eigenvalue_needs_two_inputs():
    # two identical integrators with one input: the PBH test fails at s = 0
    A = np.zeros((2, 2))
    assert controllability(A, np.array([[1.0], [1.0]])).rank == 1
    assert controllability(A, np.eye(2)).rank == 2


def test_stiff_system_where_powers_of_A_fail():
    """Eight lags from 1e-2 to 1e4 1/s, all driven by one input: controllable (distinct
    eigenvalues), but [B, AB, ..., A^7 B] is a Vandermonde matrix spanning 10^48 and numpy
    gives it rank 2; the staircase finds 8 with a wide margin."""
    rates = np.logspace(-2, 4, 8)
    n = len(rates)
    A = np.diag(-rates)
    B = np.ones((n, 1))
    ctrb = np.hstack([np.linalg.matrix_power(A, k) @ B for k in range(n)])
    assert np.linalg.matrix_rank(ctrb) < n
    r = controllability(A, B)
    assert r.rank == n and r.margin == float("inf")
    assert min(min(s) for s in r.steps) > 1e3 * r.threshold
    # one lag not driven: its mode is found
    B2 = B.copy()
    B2[5, 0] = 0.0
    r2 = controllability(A, B2)
    assert r2.rank == n - 1
    assert np.allclose(np.real(r2.modes), [-rates[5]], rtol=1e-9)


def test_units_do_not_change_the_rank():
    A = np.array([[0.0, 1.0], [-2.0, -0.5]])
    B = np.array([[0.0], [1.0]])
    S = np.diag([1e-6, 1e6])                    # states in very different units
    As, Bs = np.linalg.solve(S, A @ S), np.linalg.solve(S, B)
    assert controllability(As, Bs).rank == 2


def test_minimal_realization_keeps_the_transfer_function():
    A = np.array([[-1.0, 0.0, 0.0], [0.0, -2.0, 0.0], [0.0, 0.0, 0.0]])
    B = np.array([[1.0], [1.0], [1.0]])
    C = np.array([[1.0, 1.0, 0.0]])              # the integrator is unobservable
    Am, Bm, Cm = minimal_realization(A, B, C)
    assert Am.shape == (2, 2)
    for s in (0.0, 0.5j, 3.0j):
        full = C @ np.linalg.solve(s * np.eye(3) - A, B) if s else np.array([[1.5]])
        red = Cm @ np.linalg.solve(s * np.eye(2) - Am, Bm)
        assert np.allclose(red, full, rtol=1e-12)
