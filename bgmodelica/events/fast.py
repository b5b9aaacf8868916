"""Low-overhead evaluation of CasADi functions from the event loop.

A call through CasADi's Python interface costs tens of microseconds (argument conversion,
DM results); the event loop makes several calls per event. :class:`Fast` binds numpy arrays
to a function's inputs and outputs once (``Function.buffer``), so a call costs about a
microsecond plus the function's own work. Results are views, overwritten by the next call.
"""

from __future__ import annotations

from typing import Any

import casadi as ca
import numpy as np


class Fast:
    """``Fast(f)(a, b, ...)`` evaluates ``f`` and returns its outputs as flat numpy arrays
    (column-major, as CasADi stores them); missing trailing inputs stay zero."""

    def __init__(self, f: ca.Function, res: dict[int, np.ndarray] | None = None) -> None:
        """``res``: caller-owned output buffers by output index (flat, contiguous float64 of
        the output's size), which the function then writes in place."""
        self.f = f
        self.args = [np.zeros(f.nnz_in(i)) for i in range(f.n_in())]
        res = res or {}
        for i, r in res.items():
            if r.dtype != np.float64 or r.ndim != 1 or r.size != f.nnz_out(i) \
                    or not r.flags.c_contiguous:
                raise ValueError(f"output buffer {i} of {f.name()} must be a contiguous "
                                 f"float64 vector of {f.nnz_out(i)} values")
        self.res = [res[i] if i in res else np.zeros(f.nnz_out(i)) for i in range(f.n_out())]
        self._buf, self._eval = f.buffer()
        for i, a in enumerate(self.args):
            self._buf.set_arg(i, memoryview(a))
        for i, r in enumerate(self.res):
            self._buf.set_res(i, memoryview(r))

    def __call__(self, *args: Any) -> list[np.ndarray]:
        for a, v in zip(self.args, args, strict=False):
            a[:] = v
        self._eval()
        return self.res

    def stats(self) -> dict:
        """The function's statistics of the last call (e.g. an integrator's step counts)."""
        return self._buf.stats()
