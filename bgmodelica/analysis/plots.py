"""Figures of a linear model: Bode plot, step response, pole-zero map (matplotlib, Agg)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .linearize import Linearization

__all__ = ["bode_plot", "step_plot", "pzmap_plot", "frequency_grid", "invariant_zeros"]


def _plt():
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def frequency_grid(lin: Linearization, n: int = 400) -> np.ndarray:
    """Log-spaced frequencies [rad/s] two decades around the poles' magnitudes."""
    mags = np.abs(lin.eigenvalues)
    mags = mags[mags > 1e-9]
    lo = 0.01 * mags.min() if mags.size else 0.01
    hi = 100.0 * mags.max() if mags.size else 100.0
    return np.logspace(np.log10(lo), np.log10(hi), n)


def bode_plot(lin: Linearization, path: str | Path, omega: np.ndarray | None = None,
              title: str | None = None) -> Path:
    """Magnitude [dB] and phase [deg] of every input -> output pair."""
    plt = _plt()
    omega = frequency_grid(lin) if omega is None else np.asarray(omega, float)
    G = lin.frequency_response(omega)
    fig, (ax_m, ax_p) = plt.subplots(2, 1, figsize=(8, 6.5), sharex=True)
    styles = ["-", "--", ":", "-."]
    k = 0
    for i, y in enumerate(lin.outputs):
        for j, u in enumerate(lin.inputs):
            g = G[:, i, j]
            if not np.any(np.abs(g) > 0):
                continue
            label = f"{u} -> {y}"
            ls = styles[k % len(styles)]
            k += 1
            ax_m.semilogx(omega, 20 * np.log10(np.maximum(np.abs(g), 1e-300)), ls, label=label)
            ax_p.semilogx(omega, np.degrees(np.unwrap(np.angle(g))), ls, label=label)
    ax_m.set_ylabel("magnitude [dB]")
    ax_p.set_ylabel("phase [deg]")
    ax_p.set_xlabel("frequency [rad/s]")
    for ax in (ax_m, ax_p):
        ax.grid(True, which="both", alpha=0.3)
    ax_m.legend(fontsize=8)
    ax_m.set_title(title or f"{lin.name}: Bode plot at the {lin.point.kind}")
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def step_plot(lin: Linearization, path: str | Path, t_final: float | None = None,
              title: str | None = None) -> Path:
    """Unit-step responses of the outputs (deviations from the operating point)."""
    import control

    plt = _plt()
    if t_final is None:
        re = -np.real(lin.eigenvalues)
        slow = re[re > 1e-9]
        t_final = float(min(max(5.0 / slow.min(), 1e-3), 1e4)) if slow.size else 10.0
    T = np.linspace(0.0, t_final, 1000)
    resp = control.step_response(lin.ss(), T)
    Y = np.asarray(resp.outputs).reshape(len(lin.outputs), len(lin.inputs), -1)
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for i, y in enumerate(lin.outputs):
        for j, u in enumerate(lin.inputs):
            ax.plot(resp.time, Y[i, j], label=f"{u} -> {y}")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("output change per unit input step")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title or f"{lin.name}: step responses at the {lin.point.kind}")
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def invariant_zeros(lin: Linearization) -> np.ndarray:
    """Invariant zeros of a square system: finite generalized eigenvalues of the Rosenbrock
    pencil ``[[A, B], [C, D]] - s [[I, 0], [0, 0]]``; empty for non-square systems."""
    import scipy.linalg as sla

    n, m, p = lin.A.shape[0], lin.B.shape[1], lin.C.shape[0]
    if m != p or m == 0:
        return np.zeros(0, complex)
    M = np.block([[lin.A, lin.B], [lin.C, lin.D]])
    N = np.zeros_like(M)
    N[:n, :n] = np.eye(n)
    with np.errstate(all="ignore"):
        ev = sla.eigvals(M, N)
    return ev[np.isfinite(ev) & (np.abs(ev) < 1e12)]


def pzmap_plot(lin: Linearization, path: str | Path, title: str | None = None) -> Path:
    """Poles (x) and invariant zeros (o) in the complex plane."""
    plt = _plt()
    poles = lin.eigenvalues
    zeros = invariant_zeros(lin)
    fig, ax = plt.subplots(figsize=(6.5, 5))
    ax.scatter(poles.real, poles.imag, marker="x", s=60, label=f"poles ({len(poles)})")
    if zeros.size:
        ax.scatter(zeros.real, zeros.imag, marker="o", s=50, facecolors="none",
                   edgecolors="C1", label=f"zeros ({len(zeros)})")
    ax.axhline(0, color="k", lw=0.5)
    ax.axvline(0, color="k", lw=0.5)
    if poles.size and np.max(np.abs(poles)) > 100 * max(np.min(np.abs(poles)), 1e-9):
        ax.set_xscale("symlog", linthresh=max(np.min(np.abs(poles[np.abs(poles) > 0])), 1e-3)
                      if np.any(np.abs(poles) > 0) else 1.0)
    ax.set_xlabel("real [1/s]")
    ax.set_ylabel("imaginary [rad/s]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title or f"{lin.name}: poles and zeros at the {lin.point.kind}")
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
