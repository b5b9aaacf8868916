"""Plots of results: one stacked subplot per unit, labelled axes, events marked, paper style.

:func:`plot_result` is :meth:`bgmodelica.result.Result.plot`. Variables are grouped by unit
(in the order given): ``["motor.v", "motor.i", "arm.q1"]`` gives three subplots sharing the
time axis, labelled ``[V]``, ``[A]``, ``[rad]``. Event instants
(``result.meta["event_times"]``) are dotted vertical lines. The default ``style="paper"`` is
a compact, print-friendly look (serif font, thin lines, light grid, no top/right spines);
``style=None`` keeps matplotlib's current settings.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from cycler import cycler

if TYPE_CHECKING:  # pragma: no cover
    from .result import Result

#: matplotlib settings of ``style="paper"``
PAPER_STYLE: dict[str, Any] = {
    "font.family": "serif",
    "font.serif": ["DejaVu Serif", "Times New Roman", "Times", "serif"],
    "mathtext.fontset": "dejavuserif",
    "font.size": 9,
    "axes.labelsize": 9,
    "axes.titlesize": 10,
    "legend.fontsize": 8,
    "xtick.labelsize": 8,
    "ytick.labelsize": 8,
    "lines.linewidth": 1.2,
    "axes.linewidth": 0.6,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "axes.grid": True,
    "grid.linestyle": ":",
    "grid.linewidth": 0.5,
    "grid.alpha": 0.6,
    "legend.frameon": False,
    "axes.prop_cycle": cycler(
        color=["#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000"]),
    "savefig.dpi": 200,
    "savefig.bbox": "tight",
}

#: above this many events the markers are short ticks at the top of each subplot
MANY_EVENTS = 200


def group_by_unit(result: Result, names: Iterable[str]) -> list[tuple[str, list[str]]]:
    """``[(unit, [names...]), ...]`` in order of first appearance ("" = dimensionless)."""
    from .dataio import unit_of

    groups: dict[str, list[str]] = {}
    for n in names:
        unit = unit_of(result, n)
        groups.setdefault("" if unit in ("1", "") else unit, []).append(n)
    return list(groups.items())


def _new_figure(n_axes: int, figsize: tuple[float, float] | None, detached: bool) -> Any:
    """A figure for ``n_axes`` stacked subplots. A pyplot figure is made *before* the style
    context is entered: making the first one loads the backend (in Jupyter the inline
    backend switches interactive mode on), and the context would undo that on exit."""
    size = figsize or (6.4, 1.0 + 1.6 * n_axes)
    if detached:
        from matplotlib.figure import Figure

        return Figure(figsize=size)
    import matplotlib.pyplot as plt

    return plt.figure(figsize=size)


def _mark_events(ax: Any, events: np.ndarray, label: bool) -> None:
    if not len(events):
        return
    if len(events) <= MANY_EVENTS:
        ax.vlines(events, 0, 1, transform=ax.get_xaxis_transform(), colors="0.55",
                  linestyles=":", linewidth=0.7, label="event" if label else None, zorder=0)
    else:
        ax.vlines(events, 0.97, 1, transform=ax.get_xaxis_transform(), colors="0.45",
                  linewidth=0.4, label=f"events ({len(events)})" if label else None)


def plot_result(result: Result, names: Iterable[str] | None = None,
                path: str | Path | None = None, title: str | None = None, ax: Any = None, *,
                style: str | None = "paper", events: bool = True,
                figsize: tuple[float, float] | None = None, detached: bool | None = None
                ) -> Any:
    """Plot ``names`` (default: the states, at most 6) against time, one subplot per unit.

    path: save the figure there (PNG, SVG, PDF: by suffix); the figure is then not kept by
    pyplot (nothing to close). ax: draw every variable on this one matplotlib axes instead
    (no grouping). events: mark event instants. detached: make the figure without pyplot
    (default: when saving to ``path``). Returns the matplotlib figure; in Jupyter write
    ``fig = result.plot(...)`` (or end the line with ``;``) to see it once.
    """
    import matplotlib

    if detached is None:
        detached = path is not None and ax is None
    names = list(names) if names is not None else (
        list(result.meta.get("states", []))[:6] or list(result.names)[:6])
    ev = np.asarray(result.meta.get("event_times", []) if events else [], dtype=float)
    rc = PAPER_STYLE if style == "paper" else {}
    groups = group_by_unit(result, names)
    fig = _new_figure(max(1, len(groups)), figsize, detached) if ax is None else ax.figure
    with matplotlib.rc_context(rc):
        if ax is not None:
            for n in names:
                from .dataio import unit_of

                unit = unit_of(result, n)
                ax.plot(result.time, result[n], label=f"{n} [{unit}]" if unit else n)
            _mark_events(ax, ev, True)
            ax.set_xlabel("time [s]")
            ax.legend(loc="best")
            if title:
                ax.set_title(title)
            return fig
        axes = list(fig.subplots(max(1, len(groups)), 1, sharex=True, squeeze=False)[:, 0])
        for k, (axis, (unit, members)) in enumerate(zip(axes, groups, strict=False)):
            for n in members:
                axis.plot(result.time, result[n], label=n)
            _mark_events(axis, ev, k == 0)
            shown = unit or "1"
            axis.set_ylabel(f"{members[0]} [{shown}]" if len(members) == 1 else f"[{shown}]")
            if len(members) > 1 or (k == 0 and len(ev)):
                axis.legend(loc="best")
        axes[-1].set_xlabel("time [s]")
        if len(result.time):
            axes[-1].set_xlim(float(result.time[0]), float(result.time[-1]))
        if title:
            axes[0].set_title(title)
        fig.align_ylabels(axes)
        fig.tight_layout()
        if path is not None:
            path = Path(path)
            path.parent.mkdir(parents=True, exist_ok=True)
            fig.savefig(path, dpi=200 if style == "paper" else 120)
            if not detached:
                import matplotlib.pyplot as plt

                plt.close(fig)
    return fig
