"""Zero crossings for the event loop: the state-event indicators, the relation values at
an event, the next crossing of relations on time alone, and the location of a state event
by the Illinois method on re-integrations from the bracket's start."""

from __future__ import annotations

import math

import numpy as np

from .fast import Fast


class CrossingMixin:
    """The event loop's zero-crossing methods; they read the simulator's functions (``fn``),
    parameter vector ``p``, options and integrate with ``_integrate_one``."""

    def _locate(self, lo_t, lo_x, lo_z, g_lo, hi_t, hi_x, hi_z, g_hi, frozen):
        """Illinois iteration on the earliest crossing indicator in [lo_t, hi_t]."""
        fn = self.fn
        tol = self.opts.event_tol * max(1.0, abs(hi_t))
        shift = np.where(frozen, 1.0, -1.0) * self._hysteresis()
        raw_hi = np.array(g_hi, dtype=float)
        s_lo = np.array(g_lo, dtype=float) + shift      # zero where the relation leaves
        s_hi = raw_hi + shift
        side = 0
        widths = [hi_t - lo_t]
        for _ in range(400):
            if hi_t - lo_t <= tol:
                break
            cand = hi_t
            for k in np.nonzero(self._crossed(raw_hi[:, None], frozen)[:, 0])[0]:
                a, b = s_lo[k], s_hi[k]
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
            if self._crossed(gc[:, None], frozen)[:, 0].any():
                hi_t, hi_x, hi_z, raw_hi, s_hi = cand, xc, zc, gc, gc + shift
                if side == 1:
                    s_lo = s_lo * 0.5
                side = 1
            else:
                lo_t, lo_x, lo_z, s_lo = cand, xc, zc, gc + shift
                if side == -1:
                    s_hi = s_hi * 0.5
                side = -1
            widths.append(hi_t - lo_t)
        changed = self._crossed(raw_hi[:, None], frozen)[:, 0]
        cause = " and ".join(self.fn.relations[fn.state_rel[k]].text
                             for k in np.nonzero(changed)[0][:3])
        return hi_t, hi_x, hi_z, f"state:{cause}"

    def _hysteresis(self) -> np.ndarray:
        """Per state relation: how far past zero its indicator must go to change it (0, or
        the tolerance of a value kept against rounding-level indicators, see .mixed)."""
        return self.hysteresis[self.fn.state_rel]

    def _crossed(self, g: np.ndarray, frozen: np.ndarray) -> np.ndarray:
        """Per state relation and column of ``g``: the relation left its frozen value."""
        strict = self.fn.strict[self.fn.state_rel][:, None]
        values = np.where(strict, g > 0, g >= 0)
        return (values != frozen[:, None]) & (np.abs(g) >= self._hysteresis()[:, None])

    def _ind(self, t, x, z) -> np.ndarray:
        return self._ind_fast(t, x, z, self.p)[0].copy()

    def _first_crossing(self, ts: np.ndarray, X: np.ndarray, Z: np.ndarray,
                        frozen: np.ndarray) -> tuple[int, np.ndarray | None, np.ndarray] | None:
        """The first column of a stretch where a state relation left its frozen value: its
        index, the indicators at the column before (None for the first) and at it; None
        without one. The columns are read in chunks that double (64, 128, ...): a stretch
        that ends at an early crossing costs the indicators of its first columns only."""
        start, chunk, before = 0, 64, None
        n = len(ts)
        while start < n:
            stop = min(n, start + chunk)
            g = self._ind_columns(ts[start:stop], X[:, start:stop], Z[:, start:stop])
            hit = np.flatnonzero(self._crossed(g, frozen).any(axis=0))
            if hit.size:
                k = int(hit[0])
                return start + k, (g[:, k - 1] if k else before), g[:, k]
            before = g[:, -1]
            start, chunk = stop, 2 * chunk
        return None

    def _ind_columns(self, ts: np.ndarray, X: np.ndarray, Z: np.ndarray) -> np.ndarray:
        """The state indicators at the columns of a stretch (times ``ts``, states ``X``,
        algebraic variables ``Z``), one column each: one buffered call of the indicators
        mapped over a power of two of columns (made once per size; the last column repeated
        to fill it), as a call through CasADi's interface costs milliseconds here."""
        m = len(ts)
        size = 1 << max(0, (m - 1).bit_length())
        key = ("ind_columns", size)
        f = self.dae.cache.get(key)
        if f is None:
            f = self.dae.cache[key] = Fast(self.fn.indicators.map(size))
        fill = size - m

        def padded(a: np.ndarray) -> np.ndarray:
            return np.concatenate([a, np.repeat(a[:, -1:], fill, axis=1)], axis=1) \
                if fill and a.shape[0] else a

        cols = lambda a: padded(a).ravel(order="F") if a.shape[0] else 0.0  # noqa: E731
        g = f(cols(ts.reshape(1, -1)), cols(X), cols(Z), np.tile(self.p, size))[0]
        return g.reshape(size, -1).T[:, :m].copy()

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
