"""Numeric controllability and observability of a linear model ``(A, B, C)``.

Ranks come from the *controllability staircase form* (Rosenbrock; Van Dooren 1981), not from
the matrix ``[B, AB, ..., A^(n-1) B]``, whose columns span many orders of magnitude on stiff
systems (the motor's electrical pole at -R/L = -500 1/s beside the arm's poles of a few
rad/s: powers of A up to A^5 differ by 10^13) so that its numerical rank is meaningless.

Method (controllability; observability is the dual, ``(A^T, C^T)``):

1. *Scaling*: the augmented matrix ``[[A, B], [0, 0]]`` is balanced by a diagonal similarity
   (``scipy.linalg.matrix_balance``, powers of 2, no permutation): ``A <- S^-1 A S``,
   ``B <- S^-1 B T``. Ranks are invariant under it; it makes the states' and inputs' units
   comparable (volts, amperes, radians, kg.m2...).
2. *Staircase*: orthogonal transformations compress, block by block, the part of the state
   space reached from the inputs: at step k the block ``B_k`` (``B`` first, then the
   coupling of the newly reached block into the rest of ``A``) is split by an SVD; its
   singular values ``s_i > tol * max(||[A B]||_2, 1e-300)`` count as reached directions.
   The process stops when a block has no such singular value; the number of reached
   directions is the rank.
3. The *uncontrollable modes* are the eigenvalues of the unreached diagonal block of the
   transformed ``A``; the margin is the ratio of the smallest accepted to the largest
   rejected singular value over all steps (a large margin means an unambiguous rank).

Tolerance: ``tol`` defaults to ``1e-10`` (relative to ``||[A B]||_2`` after scaling), about
``10^6`` machine epsilons: above the rounding of the orthogonal steps on systems of a few
hundred states, far below any physical coupling. Pass ``tol=`` to change it; every result
reports the tolerance, the singular values of each step and the margin.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

__all__ = ["RankResult", "controllability", "observability", "staircase", "DEFAULT_TOL"]

#: relative tolerance of the staircase rank decisions (see the module docstring)
DEFAULT_TOL = 1e-10


@dataclass
class RankResult:
    """Numeric controllability (observability) of a linear model.

    rank / n: numeric rank of the controllability (observability) matrix, computed by the
    staircase form; ok: ``rank == n``. modes: the uncontrollable (unobservable) eigenvalues.
    steps: singular values of each staircase step (scaled). margin: smallest accepted /
    largest rejected singular value (``inf`` when nothing was rejected). tol: the relative
    tolerance used; threshold: the absolute one (tol times ``||[A B]||_2`` after scaling).
    subspace: orthonormal basis (columns, in the original, unscaled state coordinates) of
    the controllable (observable) subspace; states: state names when given.
    """

    kind: str
    rank: int
    n: int
    modes: list[complex] = field(default_factory=list)
    steps: list[list[float]] = field(default_factory=list)
    margin: float = float("inf")
    tol: float = DEFAULT_TOL
    threshold: float = 0.0
    subspace: np.ndarray | None = None
    states: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return self.rank == self.n

    def weakest_states(self, k: int = 3) -> list[str]:
        """The states most aligned with the uncontrollable (unobservable) subspace."""
        if self.subspace is None or self.rank in (0, self.n) or not self.states:
            return []
        P = self.subspace @ self.subspace.T if self.rank else np.zeros((self.n, self.n))
        resid = np.sqrt(np.clip(1.0 - np.diag(P), 0.0, None))
        order = np.argsort(-resid)
        return [self.states[i] for i in order[:k] if resid[i] > 1e-6]

    def to_dict(self) -> dict:
        return {"kind": self.kind, "rank": self.rank, "n": self.n, "ok": self.ok,
                "modes": [[float(m.real), float(m.imag)] for m in self.modes],
                "margin": None if not np.isfinite(self.margin) else float(self.margin),
                "tol": self.tol, "threshold": self.threshold,
                "steps": [[float(v) for v in s] for s in self.steps],
                "weakest_states": self.weakest_states()}


def _scaling(A: np.ndarray, B: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    n, m = B.shape
    M = np.zeros((n + m, n + m))
    M[:n, :n] = A
    M[:n, n:] = B
    if not np.any(M):
        return np.ones(n), np.ones(m)
    _, (scale, _perm) = sla.matrix_balance(M, permute=False, separate=True)
    return scale[:n], scale[n:]


def staircase(A: np.ndarray, B: np.ndarray, tol: float | None = None
              ) -> tuple[int, np.ndarray, np.ndarray, list[list[float]], float, float]:
    """Controllability staircase of ``(A, B)`` (no scaling): ``(rank, Q, Q^T A Q, steps,
    margin, threshold)``; the first ``rank`` columns of ``Q`` span the controllable
    subspace."""
    A = np.asarray(A, dtype=float)
    B = np.asarray(B, dtype=float)
    n = A.shape[0]
    tol = DEFAULT_TOL if tol is None else float(tol)
    norm = np.linalg.norm(np.hstack([A, B]), 2) if A.size or B.size else 0.0
    thr = tol * max(norm, 1e-300)
    Q = np.eye(n)
    At = A.copy()
    block = B.copy()
    k = 0
    steps: list[list[float]] = []
    accepted_min, rejected_max = np.inf, 0.0
    while k < n and block.size:
        U, s, _ = np.linalg.svd(block, full_matrices=True)
        steps.append(list(s))
        r = int(np.sum(s > thr))
        if r:
            accepted_min = min(accepted_min, float(s[r - 1]))
        if len(s) > r:
            rejected_max = max(rejected_max, float(s[r]))
        if r == 0:
            break
        T = np.eye(n)
        T[k:, k:] = U
        At = T.T @ At @ T
        Q = Q @ T
        k_new = k + r
        block = At[k_new:, k:k_new]
        k = k_new
    margin = accepted_min / rejected_max if rejected_max > 0 else float("inf")
    return k, Q, At, steps, margin, thr


def controllability(A: np.ndarray, B: np.ndarray, tol: float | None = None,
                    states: Sequence[str] | None = None, kind: str = "controllability"
                    ) -> RankResult:
    """Numeric controllability of ``(A, B)`` by the scaled staircase form (module
    docstring)."""
    A = np.atleast_2d(np.asarray(A, dtype=float))
    n = A.shape[0] if A.size else 0
    B = np.asarray(B, dtype=float).reshape(n, -1) if n else np.zeros((0, 0))
    tol = DEFAULT_TOL if tol is None else float(tol)
    if n == 0:
        return RankResult(kind, 0, 0, tol=tol, states=list(states or []))
    sx, su = _scaling(A, B) if B.size else (np.ones(n), np.ones(0))
    As = A * (1.0 / sx)[:, None] * sx[None, :]
    Bs = B * (1.0 / sx)[:, None] * su[None, :] if B.size else B
    rank, Q, At, steps, margin, thr = staircase(As, Bs, tol)
    modes = list(np.linalg.eigvals(At[rank:, rank:])) if rank < n else []
    basis = None
    if rank:
        V = sx[:, None] * Q[:, :rank]             # back to unscaled coordinates
        basis, _ = np.linalg.qr(V)
    else:
        basis = np.zeros((n, 0))
    return RankResult(kind, rank, n, sorted(modes, key=lambda v: (v.real, v.imag)), steps,
                      margin, tol, thr, basis, list(states or []))


def observability(A: np.ndarray, C: np.ndarray, tol: float | None = None,
                  states: Sequence[str] | None = None) -> RankResult:
    """Numeric observability of ``(A, C)``: the controllability of ``(A^T, C^T)``."""
    A = np.atleast_2d(np.asarray(A, dtype=float))
    n = A.shape[0] if A.size else 0
    C = np.asarray(C, dtype=float).reshape(-1, n) if n else np.zeros((0, 0))
    return controllability(A.T, C.T, tol=tol, states=states, kind="observability")


def _controllable_part(A, B, C, tol):
    """``(A_c, B_c, C_c)``: the controllable subsystem of ``(A, B, C)`` (scaled staircase)."""
    n = A.shape[0]
    if n == 0 or B.size == 0:
        return A[:0, :0], B[:0], C[:, :0]
    sx, su = _scaling(A, B)
    As = A * (1.0 / sx)[:, None] * sx[None, :]
    Bs = B * (1.0 / sx)[:, None]
    rank, Q, At, *_ = staircase(As, Bs * su[None, :], tol)
    Bt = Q.T @ Bs
    Ct = (C * sx[None, :]) @ Q
    return At[:rank, :rank], Bt[:rank], Ct[:, :rank]


def minimal_realization(A: np.ndarray, B: np.ndarray, C: np.ndarray,
                        tol: float | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(A_m, B_m, C_m)``: the controllable and observable part of ``(A, B, C)`` (same
    transfer function, D unchanged), by the scaled staircase form on (A, B) then on the dual
    of the result."""
    A = np.asarray(A, dtype=float)
    B = np.asarray(B, dtype=float).reshape(A.shape[0], -1)
    C = np.asarray(C, dtype=float).reshape(-1, A.shape[0])
    tol = DEFAULT_TOL if tol is None else tol
    Ac, Bc, Cc = _controllable_part(A, B, C, tol)
    Ao, Co, Bo = _controllable_part(Ac.T, Cc.T, Bc.T, tol)      # dual: observable part
    return Ao.T, Bo.T, Co.T
