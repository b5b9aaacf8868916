"""Dynamic state selection inside the event loop: the pivot checks between events, the
initial choice, and the switch to another variant of the model (with ``dynamic=False``, the
check that the fixed choice stays regular). See :mod:`bgmodelica.dynamic_selection`."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..core.flatmodel import HybridPart
from ..errors import SimulationError
from .fast import Fast
from .functions import build


@dataclass
class Selection:
    """Dynamic state selection inside the event loop (see :mod:`bgmodelica.dynamic_selection`).

    selector: the model's StateSelector; current: the variant in use; mode: "switch" (change
    the states when the pivot test says so) or "check" (keep the states; raise when their
    pivots degenerate below ``fail_ratio`` times the best); prepare: applies start-value
    overrides to a variant's DAE; spacing: largest time between two pivot checks [s]."""

    selector: Any
    current: Any
    mode: str = "switch"
    prepare: Any = None
    spacing: float = math.inf
    fail_ratio: float = 1e-3

    @property
    def stretch(self) -> float:
        """Longest integration between restarts [s] (100 pivot checks)."""
        return 100.0 * self.spacing


class StateSelectionMixin:
    """The event loop's state-selection methods; they read and replace the simulator's
    model (``dae``, ``fn``, its fast functions) and ``selection``."""

    def _selection_column(self, ts, X, Z, z, cols) -> int | None:
        """First pivot-check column among ``cols`` where the state choice must change."""
        sel = self.selection
        nz = self.dae.z.numel()
        nv = self.dae.n_variables
        for c in cols:
            t = float(ts[c])
            values = self._step_fast(t, X[:, c], Z[:, c] if nz else z, self.p)[6][:nv]
            if sel.mode == "check":
                now, best, _, _ = sel.selector.assess(sel.current, values, self.p, t)
                if not now >= sel.fail_ratio * best:
                    raise SimulationError(
                        f"the state choice ({', '.join(self.dae.state_names)}) degenerates at "
                        f"t = {t:.6g} s (pivot {now:.2g}, best {best:.2g}): with dynamic=False "
                        "the states cannot change; simulate with dynamic=True (the default) or "
                        "choose other states with state_select", t)
                continue
            nxt = sel.selector.check(sel.current, values, self.p, t)
            if nxt is not sel.current:
                self._pending = nxt
                return c
        return None

    def _initial_selection(self, t: float, x, z):
        sel = self.selection
        nv = self.dae.n_variables
        values = self._step_fast(t, x, z, self.p)[6][:nv].copy()
        bad = ~np.isfinite(values)
        if bad.any():
            starts = [float(getattr(v.decl, "start", 0.0))
                      for v in sel.current.reduced.model.variables]
            values[bad] = np.asarray(starts)[bad]
        if sel.mode == "check":
            return x, z
        nxt = sel.selector.check(sel.current, values, self.p, t)
        if nxt is sel.current:
            return x, z
        self._use_variant(nxt)
        x, z = self._consistent(t, None)
        return x, z

    def _use_variant(self, compiled) -> None:
        sel = self.selection
        dae = compiled.dae
        if sel.prepare is not None:
            dae = sel.prepare(dae)
        if dae.hybrid is None:
            dae = replace(dae, hybrid=HybridPart())
        sel.current = compiled
        self.dae = dae
        self.fn = build(dae)
        self._step_fast = Fast(self.fn.step)
        self._ind_fast = Fast(self.fn.indicators)
        self._one = None
        self._z_guess = None

    def _switch(self, t: float, x, z):
        """Continue with the variant chosen by the pivot test, from the current values."""
        old = self.dae
        values = self._step_fast(t, x, z, self.p)[6].copy()
        self._use_variant(self._pending)
        idx = old.observed_index
        x_new = np.array([values[idx[n]] for n in self.dae.state_names])
        self._z_guess = np.array([values[idx[n]] for n in self.dae.algebraic_names])
        z_new = self._solve_z(t, x_new) if self.fn.alg_solver is not None else np.zeros(0)
        self.log.causes["state selection"] = self.log.causes.get("state selection", 0) + 1
        return x_new, z_new
