"""Dynamic state selection: change the dummy derivatives when the current choice degenerates.

Index reduction may leave a choice between candidate states (the Cartesian pendulum: x or y).
When the Jacobian of the differentiated constraints with respect to the candidates depends on
the variables, no fixed choice is good everywhere: solving ``x^2 + y^2 = L^2`` for ``y`` fails at
``y = 0``. The event loop (:mod:`bgmodelica.events.loop`) therefore checks, at check points
inside the integration (independent of the output grid), the pivots of the current choice
against the best numerical choice (threshold pivoting at each dummy-derivative level) and, when
the current one has fallen below ``threshold`` times the best, recompiles the model with the
better selection (cached) and continues from the current values of all variables: the
integrator restarts only at such switches. This is Mattsson & Söderlind's dynamic pivoting.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np

from .backends.casadi_dae import resolved_bindings
from .compiler import CompiledModel, recompile
from .core.variables import TIME
from .structure import dummy_derivatives
from .structure.errors import StructuralError


@dataclass
class StateSelector:
    """Numerical state selection for a compiled model whose structure leaves a choice."""

    base: CompiledModel
    threshold: float = 0.3
    variants: dict[tuple[int, ...], CompiledModel] = field(default_factory=dict)
    switches: list[tuple[float, list[str]]] = field(default_factory=list)
    last_ratio: float = 1.0        # pivot score of the current choice / the best, last check

    def __post_init__(self) -> None:
        red = self.base.reduced
        model = red.model
        syms = ca.vertcat(*[v.sx for v in model.variables])
        res = ca.vertcat(*[e.residual for e in model.equations])
        jac = ca.jacobian(res, syms)
        bound = [p for p in model.parameters if isinstance(p.decl.value, ca.SX)]
        if bound:
            jac = ca.substitute(jac, *resolved_bindings(bound))
        # the DAE's own parameter vector (p_default's layout: parameters, inputs, then every
        # discrete slot, relations and pre() values of a hybrid model included)
        self._jac = ca.Function("selection_jacobian", [syms, self.base.dae.p, TIME.sx], [jac])
        self.variants[self.key(red.dummies)] = self.base
        self.priority = red.priority

    @staticmethod
    def key(dummies: list[int]) -> tuple[int, ...]:
        return tuple(sorted(dummies))

    def needed(self, samples: int = 3, seed: int = 0) -> bool:
        """True when the pivots of the current choice change with the state, so the choice
        can degrade (the pendulum's 2x or 2y); False when they are constant (a multibody
        chain whose joint coordinates are states: triangular blocks with unit pivots)."""
        red = self.base.reduced
        levels = [lv for lv in red.levels if len(lv[1]) > len(lv[0])]
        if not levels:
            return False
        rng = np.random.default_rng(seed)
        n = len(red.model.variables)
        p = self.base.dae.p_default
        scores = []
        for _ in range(samples):
            jac = np.asarray(ca.DM(self._jac(rng.uniform(-2.0, 2.0, n), p, rng.uniform())))
            scores.append(self._score(jac, levels))
        return bool(max(scores) - min(scores) > 1e-9 * max(1.0, max(abs(v) for v in scores)))

    def _score(self, jac: np.ndarray, levels) -> float:
        score = 1.0
        for rows, _cands, chosen in levels:
            score *= abs(np.linalg.det(jac[np.ix_(rows, chosen)]))
        return score

    def assess(self, current: CompiledModel, values: np.ndarray, p: np.ndarray,
               t: float) -> tuple[float, float, list[int], Any]:
        """Pivot scores at time ``t`` given all variable values: ``(score of the current
        choice, score of the best choice, best dummies, best levels)``."""
        jac = np.asarray(ca.DM(self._jac(values, p, t)))
        red = current.reduced
        now = self._score(jac, red.levels)

        def numeric(level, rows, cands, default):
            return preferred_pivots(jac[np.ix_(rows, cands)], cands)

        try:
            best = dummy_derivatives(red.graph, self.priority, select=numeric)
        except StructuralError:
            return now, now, list(red.dummies), red.levels
        return now, self._score(jac, best.levels), list(best.dummies), best.levels

    def check(self, current: CompiledModel, values: np.ndarray, p: np.ndarray,
              t: float) -> CompiledModel:
        """Return the variant to continue with at time ``t`` given all variable values."""
        now, best_score, dummies, levels = self.assess(current, values, p, t)
        self.last_ratio = now / best_score if best_score > 0 else 1.0
        if now >= self.threshold * best_score:
            return current
        key = self.key(dummies)
        if key not in self.variants:
            choice = {lvl: chosen for lvl, (_, _, chosen) in enumerate(levels, start=1)}
            self.variants[key] = recompile(self.base, lambda lvl, r, c, d: choice.get(lvl, d))
        nxt = self.variants[key]
        if nxt is current:
            return current
        self.switches.append((t, list(nxt.dae.state_names)))
        return nxt


def preferred_pivots(a: np.ndarray, cands: list[int], threshold: float = 0.5) -> list[int]:
    """Choose ``rows`` columns of ``a`` by Gaussian elimination with threshold pivoting: at
    each step take the first column, in the given preference order, whose largest remaining
    entry is at least ``threshold`` times the largest available. State-selection priorities
    (encoded in the candidate order) thus win unless the pivot is numerically poor."""
    a = np.array(a, dtype=float)
    rows_left = list(range(a.shape[0]))
    cols_left = list(range(a.shape[1]))
    chosen: list[int] = []
    for _ in range(a.shape[0]):
        sizes = {j: np.max(np.abs(a[rows_left, j])) for j in cols_left}
        best = max(sizes.values())
        j = next(c for c in cols_left if sizes[c] >= threshold * best)
        i = max(rows_left, key=lambda r: abs(a[r, j]))
        if a[i, j] != 0.0:
            for r in rows_left:
                if r != i:
                    a[r, :] -= a[r, j] / a[i, j] * a[i, :]
        rows_left.remove(i)
        cols_left.remove(j)
        chosen.append(cands[j])
    return chosen
