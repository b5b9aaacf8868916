"""Zero crossings for the event loop: the state-event indicators, the relation values at
an event, the next crossing of relations on time alone, and the location of a state event
by the Illinois method on re-integrations from the bracket's start."""

from __future__ import annotations

import math

import casadi as ca
import numpy as np


class CrossingMixin:
    """The event loop's zero-crossing methods; they read the simulator's functions (``fn``),
    parameter vector ``p``, options and integrate with ``_integrate_one``."""

    def _locate(self, lo_t, lo_x, lo_z, g_lo, hi_t, hi_x, hi_z, g_hi, frozen):
        """Illinois iteration on the earliest crossing indicator in [lo_t, hi_t]."""
        fn = self.fn
        strict = fn.strict[fn.state_rel]
        tol = self.opts.event_tol * max(1.0, abs(hi_t))
        g_lo = np.array(g_lo, dtype=float)
        g_hi = np.array(g_hi, dtype=float)
        side = 0
        widths = [hi_t - lo_t]
        for _ in range(400):
            if hi_t - lo_t <= tol:
                break
            changed = self._values(g_hi[:, None], strict)[:, 0] != frozen
            cand = hi_t
            for k in np.nonzero(changed)[0]:
                a, b = g_lo[k], g_hi[k]
                if a != b:
                    tc = lo_t + (hi_t - lo_t) * a / (a - b)
                    cand = min(cand, tc)
            margin = 0.1 * tol
            cand = min(max(cand, lo_t + margin), hi_t - margin)
            # safeguard: bisect when the bracket did not halve over the last three steps
            # (an indicator that is exactly 0 at lo_t stalls the secant at lo_t)
            if not (lo_t < cand < hi_t) or (len(widths) > 3 and widths[-1] > 0.5 * widths[-4]):
                cand = 0.5 * (lo_t + hi_t)
            xc, zc = self._integrate_one(lo_t, cand, lo_x, lo_z)
            gc = self._ind(cand, xc, zc)
            if (self._values(gc[:, None], strict)[:, 0] != frozen).any():
                hi_t, hi_x, hi_z, g_hi = cand, xc, zc, gc
                if side == 1:
                    g_lo = g_lo * 0.5
                side = 1
            else:
                lo_t, lo_x, lo_z, g_lo = cand, xc, zc, gc
                if side == -1:
                    g_hi = g_hi * 0.5
                side = -1
            widths.append(hi_t - lo_t)
        changed = self._values(g_hi[:, None], strict)[:, 0] != frozen
        cause = " and ".join(self.fn.relations[fn.state_rel[k]].text
                             for k in np.nonzero(changed)[0][:3])
        return hi_t, hi_x, hi_z, f"state:{cause}"

    def _ind(self, t, x, z) -> np.ndarray:
        return self._ind_fast(t, x, z, self.p)[0].copy()

    def _ind_map(self, m: int) -> ca.Function:
        key = ("ind_map", m)
        if key not in self.dae.cache:
            self.dae.cache[key] = self.fn.indicators.map(m)
        return self.dae.cache[key]

    @staticmethod
    def _values(g: np.ndarray, strict: np.ndarray) -> np.ndarray:
        return np.where(strict[:, None], g > 0, g >= 0)

    def _schedule_time_relations(self, t: float, g: np.ndarray, dgdt: np.ndarray) -> None:
        """Next instant where a relation on time alone changes value."""
        fn = self.fn
        self._time_next = math.inf
        for k in fn.time_rel:
            a = dgdt[k]
            if a == 0.0 or not math.isfinite(a):
                continue
            value = bool(self.p[fn.rel_slot[k]])
            if value == (a > 0):
                continue
            ts = t - g[k] / a
            if ts > t:
                self._time_next = min(self._time_next, ts)
                self._time_cause = fn.relations[k].text

    def _relation_values(self, t: float, g: np.ndarray, dgdt: np.ndarray) -> np.ndarray:
        """Relation values at an event instant: the sign of the indicator; for relations on
        time alone at their crossing, the right limit (the sign of the slope)."""
        fn = self.fn
        vals = np.where(fn.strict, g > 0, g >= 0).astype(float)
        for k in fn.time_rel:
            a = dgdt[k]
            if a != 0.0 and abs(g[k]) <= 1e-12 * abs(a) * max(1.0, abs(t)):
                vals[k] = float(a > 0)
        return vals
