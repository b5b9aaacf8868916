from __future__ import annotations

import pytest

from bgmodelica.structure import (
    StructurallySingular,
    check_structurally_nonsingular,
    dulmage_mendelsohn,
)


def test_overdetermined() -> None:
    # e0: f(x0)=0, e1: g(x0)=0, e2: h(x0, x1)=0, e3: k(x1, x2)=0 -> e0, e1, x0 clash.
    eq_vars = [[0], [0], [0, 1], [1, 2]]
    dm = dulmage_mendelsohn(eq_vars, 3)
    assert dm.overdetermined_eqs == [0, 1] and dm.overdetermined_vars == [0]
    assert dm.underdetermined_vars == [] and dm.well_eqs == [2, 3]
    assert not dm.is_nonsingular
    with pytest.raises(StructurallySingular) as info:
        check_structurally_nonsingular(eq_vars[:3], 3)
    err = info.value
    assert err.overdetermined_eqs == [0, 1] and err.overdetermined_vars == [0]
    assert err.underdetermined_vars == [2] and err.underdetermined_eqs == []


def test_underdetermined() -> None:
    # e0: f(x0, x1), e1: g(x1), e2: h(x2, x3) -> x2, x3 share one equation.
    eq_vars = [[0, 1], [1], [2, 3]]
    dm = dulmage_mendelsohn(eq_vars, 4)
    assert dm.underdetermined_eqs == [2] and dm.underdetermined_vars == [2, 3]
    assert dm.overdetermined_eqs == [] and dm.well_vars == [0, 1]
    with pytest.raises(StructurallySingular) as info:
        check_structurally_nonsingular(eq_vars, 4)
    assert info.value.underdetermined_vars == [2, 3]
    assert "2 variables" in str(info.value)


def test_nonsingular_returns_perfect_matching() -> None:
    m = check_structurally_nonsingular([[0, 1], [1]], 2)
    assert m.eq_to_var == [0, 1]
