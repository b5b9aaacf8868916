"""Identifiability of fitted parameters: the rank of the column-normalized sensitivity
matrix (:func:`check_identifiable`); :class:`IdentifiabilityError` names the combination of
parameters that leaves the data unchanged."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import ModelError


class IdentifiabilityError(ModelError):
    """The free parameters cannot be determined from the data (rank-deficient sensitivity
    matrix): ``rank``, ``singular_values`` and the unidentifiable ``direction``."""

    def __init__(self, message: str, rank: int = 0, singular_values: Any = None,
                 direction: dict[str, float] | None = None) -> None:
        super().__init__(message)
        self.rank = rank
        self.singular_values = singular_values
        self.direction = direction or {}


def check_identifiable(J: np.ndarray, names: list[str], tol: float, where: str) -> np.ndarray:
    """Singular values of the column-normalized Jacobian; IdentifiabilityError if its rank is
    below the number of free parameters."""
    norms = np.linalg.norm(J, axis=0)
    dead = [n for n, v in zip(names, norms, strict=True) if not v > 0]
    if dead:
        raise IdentifiabilityError(
            f"not identifiable {where}: the data do not depend on {', '.join(dead)} (zero "
            "sensitivity of every fitted column); fix it or measure something it affects",
            rank=len(names) - len(dead), direction={d: 1.0 for d in dead})
    Jn = J / norms
    _U, S, Vt = np.linalg.svd(Jn, full_matrices=False)
    rank = int(np.sum(S > tol * S[0]))
    if rank < len(names):
        v = Vt[-1]
        v = v / np.max(np.abs(v))
        parts = sorted(((n, float(c)) for n, c in zip(names, v, strict=True)
                        if abs(c) > 0.05), key=lambda x: -abs(x[1]))
        if parts and parts[0][1] < 0:
            parts = [(n, -c) for n, c in parts]
        combo = " ".join(f"{'+' if c >= 0 else '-'} {abs(c):.3g}*{n}" for n, c in parts)
        raise IdentifiabilityError(
            f"not identifiable {where}: the sensitivity matrix of {len(names)} free parameters "
            f"has rank {rank} (relative singular values "
            + ", ".join(f"{s / S[0]:.2g}" for s in S)
            + f"; tolerance {tol:g}). Changing the parameters along ({combo.lstrip('+ ')}) "
            "(relative to their scale) leaves the data unchanged: fix one of "
            + ", ".join(n for n, _ in parts) + " or add measurements that separate them",
            rank=rank, singular_values=S.tolist(), direction=dict(parts))
    return S
