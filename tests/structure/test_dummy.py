from __future__ import annotations

import pytest

from bgmodelica.structure import (
    ALWAYS,
    PREFER,
    EquationGraph,
    StateSelectionError,
    dummy_derivatives,
    pantelides,
)

# Cartesian pendulum and coupled inertias variable indices (see conftest.py).
X, Y, VX, VY, T, DX, DY, DVX, DVY = range(9)
PHI1, W1, PHI2, W2, TAU, DPHI1, DW1, DPHI2, DW2 = range(9)


def prio(n: int, **kw: int) -> list[int]:
    p = [0] * n
    for k, v in kw.items():
        p[int(k[1:])] = v
    return p


def test_pendulum_prefer_x(pendulum: EquationGraph) -> None:
    g = pantelides(pendulum).graph
    d = dummy_derivatives(g, prio(5, v0=PREFER))
    assert d.states == [X, VX]
    assert d.has_choice
    assert sorted(d.dummies) == sorted([DY, DVY, 9, 10])  # y', vy', x'', y''
    assert len(d.dummies) == 4  # one per differentiated equation
    assert [len(rows) for rows, _, _ in d.levels] == [3, 1]
    rows, cands, chosen = d.levels[0]
    assert rows == [6, 7, 8] and len(cands) == 4 and len(chosen) == 3


def test_pendulum_prefer_y(pendulum: EquationGraph) -> None:
    g = pantelides(pendulum).graph
    d = dummy_derivatives(g, prio(5, v1=PREFER))
    assert d.states == [Y, VY]
    assert sorted(d.dummies) == sorted([DX, DVX, 9, 10])
    assert d.has_choice


def test_pendulum_always_and_conflict(pendulum: EquationGraph) -> None:
    g = pantelides(pendulum).graph
    d = dummy_derivatives(g, prio(5, v1=ALWAYS, v0=PREFER))
    assert Y in d.states and X not in d.states
    with pytest.raises(StateSelectionError) as info:
        dummy_derivatives(g, prio(5, v0=ALWAYS, v1=ALWAYS))
    assert info.value.variables == [X, Y]


def test_select_callback_overrides_and_is_validated(pendulum: EquationGraph) -> None:
    g = pantelides(pendulum).graph
    calls = []

    def pick_dx_last(level: int, rows: list[int], cands: list[int], default: list[int]):
        calls.append((level, rows, cands, default))
        return [DX] if level == 2 else default

    d = dummy_derivatives(g, prio(5, v0=PREFER), select=pick_dx_last)
    assert [c[0] for c in calls] == [1, 2]
    assert DX in d.dummies and Y in d.states and X not in d.states

    with pytest.raises(StateSelectionError, match="distinct"):
        dummy_derivatives(g, None, select=lambda lv, rows, cands, default: default[:-1])
    with pytest.raises(StateSelectionError, match="non-candidates"):
        dummy_derivatives(g, None, select=lambda lv, rows, cands, default: [0] * len(rows))
    with pytest.raises(StateSelectionError, match="always"):
        dummy_derivatives(g, prio(5, v0=ALWAYS),
                          select=lambda lv, rows, cands, default: [DX] if lv == 2 else default)


def test_singular_selection_rejected() -> None:
    # base vars 0, 1, 2 with derivatives 3, 4, 5; e2 = der(e0) ~ {3}, e3 = der(e1) ~ {3, 4, 5}
    eq_vars = [[0], [0, 1, 2], [0, 3], [0, 1, 2, 3, 4, 5]]
    g = EquationGraph(eq_vars, 6, [3, 4, 5, -1, -1, -1], [2, 3, -1, -1])
    d = dummy_derivatives(g)
    rows, cands, chosen = d.levels[0]
    assert rows == [2, 3] and sorted(cands) == [3, 4, 5] and 3 in chosen
    with pytest.raises(StateSelectionError, match="singular"):
        dummy_derivatives(g, select=lambda lv, rows, cands, default: [4, 5])
    with pytest.raises(StateSelectionError, match="distinct"):
        dummy_derivatives(g, select=lambda lv, rows, cands, default: [3, 3])


def test_inertias(inertias: EquationGraph) -> None:
    g = pantelides(inertias).graph
    d = dummy_derivatives(g, prio(5, v1=PREFER))
    assert d.dummies == [DW2]
    assert d.states == [PHI1, W1, PHI2]
    assert d.has_choice
    d = dummy_derivatives(g, prio(5, v3=PREFER))
    assert d.dummies == [DW1] and W2 in d.states and W1 not in d.states
    assert DPHI1 not in d.dummies and DPHI2 not in d.dummies


def test_index_1_has_no_dummies(rc_circuit: EquationGraph) -> None:
    d = dummy_derivatives(pantelides(rc_circuit).graph)
    assert d.dummies == [] and d.states == [0] and d.levels == [] and not d.has_choice


def test_second_order_pendulum() -> None:
    # x'' = -T x, y'' = -T y - g, x^2 + y^2 = L^2 with vars x, y, T, x', y', x'', y''
    x, y, t, dx, dy, ddx, ddy = range(7)
    g = EquationGraph([[ddx, t, x], [ddy, t, y], [x, y]], 7, [dx, dy, -1, ddx, ddy, -1, -1])
    r = pantelides(g)
    assert r.index == 3
    d = dummy_derivatives(r.graph, prio(3, v0=PREFER))
    assert d.states == [x, dx]
    d = dummy_derivatives(r.graph, prio(3, v1=PREFER))
    assert d.states == [y, dy]
    # one constraint row per level: a choice at level 1, forced at level 2
    assert sorted(d.levels[0][1]) == [ddx, ddy] and d.levels[1][1] == [dx]
    assert d.has_choice


def test_no_choice_when_constraint_fixes_the_state() -> None:
    # x = f(t) with x' present: x' must be a dummy, no state remains
    g = pantelides(EquationGraph([[0]], 2, [1, -1])).graph
    d = dummy_derivatives(g)
    assert d.dummies == [1] and d.states == [] and not d.has_choice
