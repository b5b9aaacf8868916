"""Re-implementation of ``ModelicaFFT_kiss_fftr`` (real FFT of ModelicaExternalC) with numpy.

``kiss_fftr(u, nu, work, nwork, amplitudes, phases) -> (info, amplitudes, phases)`` as
called by ``Modelica.Math.FastFourierTransform.Internal.rawRealFFT``: for the ``nu`` samples
``u`` (nu even) and ``nf = nu/2 + 1`` frequencies ``k/(nu*dt)``, amplitudes
``2*|X[k]|/nu`` (``|X[0]|/nu``, the mean, at k = 0) and phases ``arg(X[k])`` [rad], so that
``u(t) = sum A[k]*cos(2*pi*f[k]*t + phi[k])``; ``X`` is the discrete Fourier transform.
info: 0 computed, 1 ``nu`` odd, 2 ``nwork`` is not ``3*nu + 2*nf``, 3 other error. The
``work``, ``amplitudes`` and ``phases`` arguments are placeholders (ignored, may be None).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np


def kiss_fftr(u: Any, nu: int | None = None, work: Any = None, nwork: int | None = None,
              amplitudes: Any = None, phases: Any = None) -> tuple[int, np.ndarray, np.ndarray]:
    """Amplitudes and phases [rad] of the real FFT of ``u`` (see the module docstring)."""
    x = np.asarray(u, dtype=float).ravel()
    n = x.size if nu is None else int(nu)
    nf = n // 2 + 1
    zeros = np.zeros(nf)
    if n % 2:
        return 1, zeros, zeros.copy()
    if nwork is not None and int(nwork) != 3 * n + 2 * nf:
        return 2, zeros, zeros.copy()
    if x.size != n or not np.all(np.isfinite(x)):
        return 3, zeros, zeros.copy()
    spec = np.fft.rfft(x)
    amp = 2.0 * np.abs(spec) / n
    amp[0] *= 0.5
    return 0, amp, np.angle(spec)


REGISTRY: dict[str, Callable[..., Any]] = {"ModelicaFFT_kiss_fftr": kiss_fftr}
