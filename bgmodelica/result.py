"""Simulation results: time vector, every variable by dotted name, CSV and plots."""

from __future__ import annotations

import csv
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np


@dataclass
class Result:
    """Trajectories of a simulation.

    time: [s], shape (N,). ``result["motor.R.i"]`` gives a variable (aliases and parameters
    included). ``meta`` holds solver statistics and compile/run times [s]. The variables
    other than the states are computed from the trajectory when first asked for.
    """

    time: np.ndarray
    data: np.ndarray | Callable[[], np.ndarray]   # (N, len(names)), or computes it on demand
    names: list[str]
    aliases: dict[str, tuple[str, float]] = field(default_factory=dict)
    parameters: dict[str, float] = field(default_factory=dict)
    units: dict[str, str] = field(default_factory=dict)
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self._index = {n: k for k, n in enumerate(self.names)}

    @property
    def values(self) -> np.ndarray:
        """All recorded variables, shape (N, len(names)); evaluated on first use."""
        if callable(self.data):
            self.data = self.data()
        return self.data

    def __contains__(self, name: str) -> bool:
        return name in self._index or name in self.aliases or name in self.parameters

    def __getitem__(self, name: str) -> np.ndarray:
        if name in ("time", "t"):
            return self.time
        if name in self._index:
            return self.values[:, self._index[name]]
        if name in self.aliases:
            rep, sign = self.aliases[name]
            return sign * self[rep]
        if name in self.parameters:
            return np.full_like(self.time, self.parameters[name])
        close = [n for n in self.all_names() if n.endswith(name.split(".")[-1])][:6]
        raise KeyError(f"no variable {name!r} in the result"
                       + (f"; similar: {', '.join(close)}" if close else ""))

    def all_names(self) -> list[str]:
        """Every name the result answers to, computed variables first, then aliases."""
        return list(self.names) + sorted(self.aliases)

    def final(self, name: str) -> float:
        return float(self[name][-1])

    def to_csv(self, path: str | Path, names: Sequence[str] | None = None) -> Path:
        """Write ``time,<names>`` (default: every variable incl. aliases) to a CSV file."""
        names = list(names) if names is not None else self.all_names()
        cols = np.column_stack([self.time] + [self[n] for n in names])
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        with path.open("w", newline="") as fh:
            writer = csv.writer(fh)
            writer.writerow(["time", *names])
            writer.writerows(np.char.mod("%.12g", cols).tolist())
        return path

    def plot(self, names: Iterable[str], path: str | Path | None = None,
             title: str | None = None, ax: Any = None) -> Any:
        """Plot variables against time; save to ``path`` if given. Returns the figure."""
        import matplotlib

        if path is not None:
            matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        names = list(names)
        fig = None
        if ax is None:
            fig, ax = plt.subplots(figsize=(8, 4.5))
        for n in names:
            unit = self.units.get(n, "")
            ax.plot(self.time, self[n], label=f"{n} [{unit}]" if unit else n)
        ax.set_xlabel("time [s]")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize=8)
        if title:
            ax.set_title(title)
        if path is not None and fig is not None:
            fig.tight_layout()
            fig.savefig(path, dpi=120)
            plt.close(fig)
        return fig
