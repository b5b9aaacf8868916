"""Draw a bond graph with matplotlib (no graphviz): element labels, bonds with half-arrows
(power direction), causal strokes (at the end that receives the effort) and bond numbers.

``draw(model, "arm.svg")`` or ``"arm.png"`` (format from the extension). Positions come from
the elements' ``pos`` hints (``BondGraph.add(name, elem, at=(x, y))``, offsets of nested
subsystems added); elements without a hint are placed by a small force-directed layout.
Storage elements in derivative causality are drawn in red, sources in blue, detectors in
green, switches (Sw) in purple; bonds of a causal conflict in red.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from .causality import BGI, Causality, assign_causality
from .graph import DETECTORS, JUNCTIONS, SOURCES, SWITCHES, Graph
from .report import as_graph

__all__ = ["draw", "layout"]

UNIT_IN = 0.95          # inches per layout unit
FONT = 9.0              # points
GAP = 0.1               # space between a label and its bonds, in layout units


def layout(graph: Graph, seed: int = 0, iterations: int = 400) -> dict[str, tuple[float, float]]:
    """Positions of every node: the given hints, the others by a force-directed layout
    (Fruchterman-Reingold, hinted nodes pinned), in bond lengths."""
    names = list(graph.nodes)
    fixed = {n: graph.nodes[n].pos for n in names if graph.nodes[n].pos is not None}
    if len(fixed) == len(names):
        return {n: (float(p[0]), float(p[1])) for n, p in fixed.items()}
    rng = np.random.default_rng(seed)
    idx = {n: k for k, n in enumerate(names)}
    pos = rng.uniform(-1, 1, (len(names), 2)) * max(1.0, math.sqrt(len(names)))
    pinned = np.zeros(len(names), dtype=bool)
    for n, p in fixed.items():
        pos[idx[n]] = p
        pinned[idx[n]] = True
    # place free nodes near their hinted neighbours first
    inc = graph.incidence()
    for n in names:
        if not pinned[idx[n]]:
            near = [idx[b.other(n)] for b in inc[n] if pinned[idx[b.other(n)]]]
            if near:
                pos[idx[n]] = pos[near].mean(axis=0) + rng.uniform(-0.7, 0.7, 2)
    edges = np.array([(idx[b.tail], idx[b.head]) for b in graph.bonds], dtype=int)
    k = 1.4
    temp = 1.0
    for _ in range(iterations):
        delta = pos[:, None, :] - pos[None, :, :]
        dist = np.linalg.norm(delta, axis=2) + 1e-9
        disp = (delta / dist[..., None] * (k * k / dist)[..., None]).sum(axis=1)
        if len(edges):
            d = pos[edges[:, 0]] - pos[edges[:, 1]]
            ln = np.linalg.norm(d, axis=1, keepdims=True) + 1e-9
            f = d / ln * (ln * ln / k)
            np.add.at(disp, edges[:, 0], -f)
            np.add.at(disp, edges[:, 1], f)
        length = np.linalg.norm(disp, axis=1, keepdims=True) + 1e-9
        step = disp / length * np.minimum(length, temp)
        step[pinned] = 0.0
        pos += step
        temp = max(0.02, temp * 0.985)
    return {n: (float(pos[idx[n]][0]), float(pos[idx[n]][1])) for n in names}


def _half_size(text: str) -> tuple[float, float]:
    char = 0.62 * FONT / 72.0 / UNIT_IN
    return 0.5 * len(text) * char + 0.07, 0.5 * FONT * 1.25 / 72.0 / UNIT_IN + 0.05


def _clip(center, half, direction) -> np.ndarray:
    dx, dy = direction
    t = min(half[0] / abs(dx) if abs(dx) > 1e-12 else math.inf,
            half[1] / abs(dy) if abs(dy) > 1e-12 else math.inf)
    return np.asarray(center) + t * np.asarray(direction)


def draw(model: Any, path: str | Path, *, view: str = BGI, causality: Causality | None = None,
         causal: bool = True, numbers: bool = True, title: str | None = None,
         dpi: int = 150) -> Path:
    """Render ``model`` (Graph, BondGraph or component) to ``path`` (.svg, .png, .pdf).

    view: "BGI" or "BGD" (which causality to draw); causal=False draws the acausal graph.
    Returns the path written.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    graph = as_graph(model)
    graph.validate()
    c = causality if causality is not None else (
        assign_causality(graph, view, check=False) if causal else None)
    pos = layout(graph)
    titles = {n: node.title for n, node in graph.nodes.items()}
    xs = [p[0] for p in pos.values()] or [0.0]
    ys = [p[1] for p in pos.values()] or [0.0]
    pad = 0.9
    x0, x1 = min(xs) - pad - 0.4, max(xs) + pad + 0.4
    y0, y1 = min(ys) - pad, max(ys) + pad + 0.3
    fig = plt.figure(figsize=((x1 - x0) * UNIT_IN, (y1 - y0) * UNIT_IN))
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.axis("off")
    conflict_nodes = {x.at for x in c.conflicts} | {x.element for x in c.conflicts} if c else set()
    derivative = set(c.derivative) if c else set()

    for b in graph.bonds:
        pa, pb = np.array(pos[b.tail]), np.array(pos[b.head])
        d = pb - pa
        ln = float(np.linalg.norm(d))
        if ln < 1e-9:
            continue
        u = d / ln
        a = _clip(pa, _half_size(titles[b.tail]), u) + GAP * u
        z = _clip(pb, _half_size(titles[b.head]), -u) - GAP * u
        if float(np.dot(z - a, u)) <= 0.05:
            a, z = pa + 0.3 * d, pb - 0.3 * d
        color = "#c00000" if (b.tail in conflict_nodes and b.head in conflict_nodes) else "black"
        ax.plot([a[0], z[0]], [a[1], z[1]], color=color, lw=1.2, solid_capstyle="butt")
        left = np.array([-u[1], u[0]])
        barb = z - 0.2 * u + 0.13 * left                       # half-arrow at the head
        ax.plot([z[0], barb[0]], [z[1], barb[1]], color=color, lw=1.2)
        if c is not None and b.number in c.effort_to:
            end = z if c.effort_to[b.number] == b.head else a
            s0, s1 = end - 0.14 * left, end + 0.14 * left
            ax.plot([s0[0], s1[0]], [s0[1], s1[1]], color=color, lw=2.0,
                    solid_capstyle="butt")
        if numbers:
            mid = 0.5 * (a + z) - 0.13 * left
            ax.text(mid[0], mid[1], str(b.number), fontsize=FONT - 2.5, color="#555555",
                    ha="center", va="center")

    for n, node in graph.nodes.items():
        x, y = pos[n]
        color = "black"
        if node.kind in SOURCES:
            color = "#1f4fbf"
        elif node.kind in DETECTORS:
            color = "#1a7f37"
        elif node.kind in SWITCHES:
            color = "#7b2fbe"
        if n in derivative or n in conflict_nodes:
            color = "#c00000"
        weight = "bold" if node.kind in JUNCTIONS else "normal"
        ax.text(x, y, titles[n], fontsize=FONT + (1 if node.kind in JUNCTIONS else 0),
                color=color, ha="center", va="center", fontweight=weight,
                bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.9})
    label = title if title is not None else graph.name
    if c is not None:
        label += f"  [{c.view}: stroke = end receiving the effort"
        if c.derivative:
            label += "; red = derivative causality"
        label += "]"
    ax.text(x0 + 0.15, y1 - 0.2, label, fontsize=FONT, ha="left", va="top", color="#333333")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path

