from __future__ import annotations

import pytest

from bgmodelica.structure import EquationGraph


def test_helpers(pendulum: EquationGraph) -> None:
    g = pendulum
    assert g.n_eqs == 5
    assert g.var_eqs()[4] == [2, 3]
    assert g.derivative_order(5) == 1 and g.derivative_order(0) == 0
    assert g.highest_derivative(0) == 5
    assert g.var_orders() == [0, 0, 0, 0, 0, 1, 1, 1, 1]
    assert g.base_vars()[7] == 2
    assert g.active_equations() == [0, 1, 2, 3, 4]
    h = g.copy()
    h.eq_vars[0].append(4)
    h.var_derivative[4] = 8
    assert g.eq_vars[0] == [5, 2] and g.var_derivative[4] == -1


def test_defaults_and_validation() -> None:
    g = EquationGraph([[0, 1]], 2)
    assert g.var_derivative == [-1, -1] and g.eq_derivative == [-1]
    with pytest.raises(ValueError):
        EquationGraph([[0, 5]], 2).validate()
    with pytest.raises(ValueError):
        EquationGraph([[0]], 2, [1, 0]).validate()  # cycle
    with pytest.raises(ValueError):
        EquationGraph([[0]], 3, [2, 2, -1]).validate()  # not injective


def test_derivative_chains_orders_roots_and_errors() -> None:
    from bgmodelica.structure.graph import derivative_chains

    # x0 -> x2 -> x4 (x'' chain), x1 -> x3, x5 alone
    inv, order, root = derivative_chains([2, 3, 4, -1, -1, -1])
    assert inv == [-1, -1, 0, 1, 2, -1]
    assert order == [0, 0, 1, 1, 2, 0]
    assert root == [0, 1, 0, 1, 0, 5]
    assert derivative_chains([]) == ([], [], [])
    with pytest.raises(ValueError, match="variable 1 has derivative 7 out of range"):
        derivative_chains([-1, 7])
    with pytest.raises(ValueError, match="equation 1 is the derivative of more than one"):
        derivative_chains([1, 1, -1], "equation")
    with pytest.raises(ValueError, match="variable 0 is the derivative of more than one"):
        derivative_chains([0, -1])                  # its own derivative
    with pytest.raises(ValueError, match="cyclic variable derivative links"):
        derivative_chains([1, 2, 0, -1])
