"""Drawings: SVG and PNG files with labels, half-arrows and causal strokes."""

from __future__ import annotations

from pathlib import Path

import pytest

from bgmodelica.bondgraph import Graph, draw, layout
from library.bondgraph import DCMotorDrive, TwoLinkArm, TwoLinkManipulator

OUT = Path(__file__).resolve().parent / "_drawings"


@pytest.mark.parametrize("model", [DCMotorDrive, TwoLinkArm, TwoLinkManipulator])
def test_draw_svg_and_png(model):
    for ext in ("svg", "png"):
        path = draw(model(), OUT / f"{model.__name__}.{ext}")
        assert path.exists() and path.stat().st_size > 5000
    svg = (OUT / f"{model.__name__}.svg").read_text()
    assert "<svg" in svg


def test_draw_bgd_view_and_auto_layout(tmp_path):
    g = Graph("rc")
    for name, kind in (("U", "Se"), ("j", "0"), ("R", "R"), ("C", "C")):
        g.add(name, kind, label=name)
    g.bond("U", "j")
    g.bond("j", "R")
    g.bond("j", "C")
    pos = layout(g)
    assert len(pos) == 4 and len({tuple(round(v, 3) for v in p) for p in pos.values()}) == 4
    assert draw(g, tmp_path / "rc.png", view="BGD").stat().st_size > 1000
    assert draw(g, tmp_path / "rc_acausal.svg", causal=False).exists()
