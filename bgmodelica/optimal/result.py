"""The answer of ``optimize``: optimal controls and states, the objective, the check by
re-simulation, the solver's report; as JSON, CSV and a figure."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .collocation import Solution
from .problem import Problem


@dataclass
class OptimalControl:
    """Result of :func:`~bgmodelica.optimal.optimize`.

    ``controls[name]`` / ``states[name]``: ``(time [s], value)``; a control is linear between
    its points and jumps where a time repeats (the table ``simulate(inputs=...)`` reads).
    States are at t = 0 and the collocation points. ``resimulation``: the
    :class:`~bgmodelica.Result` of the model simulated with the optimal controls as a table
    (every variable); ``resimulation_error``: the largest state deviation between it and the
    optimal trajectory at the mesh points."""

    problem: Problem
    solution: Solution
    resimulation: Any
    resimulation_error: float
    history: list[dict[str, float]]
    seconds: float

    @property
    def stop_time(self) -> float:
        return self.solution.trajectory.T

    @property
    def objective(self) -> float:
        return self.solution.objective

    @property
    def controls(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        traj = self.solution.trajectory
        return {name: traj.control_table(i) for i, name in enumerate(self.problem.controls)}

    @property
    def states(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        traj = self.solution.trajectory
        t = traj.times()
        return {name: (t, traj.X[:, i]) for i, name in enumerate(self.problem.dae.state_names)}

    def final_values(self) -> dict[str, float]:
        """Re-simulated values at the final time of the variables with a final condition."""
        out = {}
        for c in self.problem.final:
            name = c.name
            out[name] = float(self.resimulation[name][-1])
        return out

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: stop_time, objective, controls, states, resimulation_error, final
        (re-simulated), solver."""
        sol = self.solution
        return {
            "model": self.problem.compiled.name,
            "stop_time": self.stop_time,
            "objective": self.objective,
            "controls": {n: {"time": t.tolist(), "value": v.tolist()}
                         for n, (t, v) in self.controls.items()},
            "states": {n: {"time": t.tolist(), "value": v.tolist()}
                       for n, (t, v) in self.states.items()},
            "resimulation_error": self.resimulation_error,
            "final": self.final_values(),
            "solver": {"name": "ipopt", "method": "Radau IIA collocation (3 points), "
                       "piecewise-linear controls", "status": sol.status,
                       "iterations": sol.iterations, "intervals": len(sol.trajectory.mesh) - 1,
                       "refinements": len(self.history) - 1, "history": self.history,
                       "seconds": self.seconds},
        }

    def to_csv(self, path: str | Path) -> Path:
        """The re-simulated trajectories (every variable, controls included), as
        ``simulate -o`` writes them."""
        return self.resimulation.to_csv(path)

    def plot(self, path: str | Path | None = None) -> Any:
        """States by unit (re-simulated: lines, optimal at the mesh points: dots) and controls
        against time; saved to ``path`` if given. Returns the figure."""
        import matplotlib

        if path is not None:
            matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        from ..plotting import PAPER_STYLE, group_by_unit

        res = self.resimulation
        states = self.states
        groups = group_by_unit(res, list(states))
        units = {u.name: u.decl.unit for u in self.problem.dae.inputs}
        with plt.rc_context(PAPER_STYLE):
            fig, axes = plt.subplots(len(groups) + 1, 1, sharex=True,
                                     figsize=(6.4, 1.9 * (len(groups) + 1)))
            for ax, (unit, names) in zip(axes, groups, strict=False):
                for name in names:
                    t, v = states[name]
                    line, = ax.plot(res.time, res[name], label=name)
                    ax.plot(t[::3], v[::3], ".", color=line.get_color(), markersize=2.5)
                ax.set_ylabel(f"[{unit}]" if unit else "[-]")
                ax.legend(loc="best", ncol=2)
            ax_u = axes[-1]
            for name, (t, v) in self.controls.items():
                ax_u.plot(t, v, label=name)
            unit = units.get(self.problem.controls[0], "")
            ax_u.set_ylabel(f"controls [{unit}]" if unit else "controls")
            ax_u.set_xlabel("time [s]")
            ax_u.legend(loc="best")
            axes[0].set_title(f"{self.problem.compiled.name}: objective "
                              f"{self.objective:.6g}, T = {self.stop_time:.6g} s")
            if path is not None:
                fig.savefig(path)
                plt.close(fig)
        return fig
