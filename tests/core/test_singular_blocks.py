"""A linear block is reported singular only when it is singular for every value of the other
symbols; discrete symbols (modes) are tried at 0/1, not at values they never take."""

from __future__ import annotations

import casadi as ca

from bgmodelica.diagnose import singular_linear_block


def test_dependent_equations_are_singular():
    x, y, p = ca.SX.sym("x"), ca.SX.sym("y"), ca.SX.sym("p")
    assert singular_linear_block([x + y - p, 2 * x + 2 * y], [x, y])
    assert not singular_linear_block([x + y - p, x - y], [x, y])


def test_singular_in_one_combination_of_modes_only():
    # like a lossy gear: a = (locked ? 0 : s - loss), loss = (ideal ? 0 : (locked ? s : 1))
    a, s, loss = ca.SX.sym("a"), ca.SX.sym("s"), ca.SX.sym("loss")
    locked, ideal = ca.SX.sym("locked"), ca.SX.sym("ideal")
    res = [a - ca.if_else(locked, 0, s - loss),
           loss - ca.if_else(ideal, 0, ca.if_else(locked, s, 1)),
           a - 1]
    modes = frozenset(m.element_hash() for m in (locked, ideal))
    assert singular_linear_block(res, [a, s, loss])             # modes read as nonzero
    assert not singular_linear_block(res, [a, s, loss], discrete=modes)
    # singular in every mode: still reported
    res[2] = a - ca.if_else(locked, 0, s - loss)
    assert singular_linear_block(res, [a, s, loss], discrete=modes)
