"""Array equations lowered as blocks (lazy whole-array expressions): the same scalar
equations as element by element, broadcasting, aliases, unit checks and errors."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica import Component, Parameter, Variable, der, sin
from bgmodelica.core.arrays import ArrayEquation, ArrayExpr
from bgmodelica.core.expr import to_sx
from bgmodelica.core.flatten import flatten
from bgmodelica.core.variables import TIME
from bgmodelica.errors import EquationError, UnitError

TIGHT = {"rtol": 1e-10, "atol": 1e-12}


class Grid(Component):
    """der(x[i,j]) = -(a[i] + b[j]) * x[i,j] + c*sin(w*time): the (2,1) and (1,3) arrays
    broadcast to (2,3), a scalar expression to every element."""

    x = Variable(shape=(2, 3), start=1.0, fixed=True, unit="V")
    a = Parameter(shape=(2, 1), value=[[1.0], [2.0]], unit="1/s")
    b = Parameter(shape=(1, 3), value=[[0.0, 0.5, 1.0]], unit="1/s")
    c = Parameter(0.3, unit="V/s")
    w = Parameter(2.0, unit="rad/s")

    def equations(self):
        yield der(self.x) == -(self.a + self.b) * self.x + self.c * sin(self.w * bg.time)


def _analytic(k: float, c: float, w: float, t: np.ndarray) -> np.ndarray:
    """x' = -k x + c sin(w t), x(0) = 1."""
    part = c * (k * np.sin(w * t) - w * np.cos(w * t)) / (k * k + w * w)
    return (1.0 + c * w / (k * k + w * w)) * np.exp(-k * t) + part


def test_broadcast_block_matches_the_analytic_solution():
    eq = next(iter(Grid().equations()))
    assert isinstance(eq, ArrayEquation) and eq.is_block() and eq.shape == (2, 3)
    res = bg.simulate(Grid(), stop_time=2.0, interval=0.1, **TIGHT)
    for i, a in enumerate([1.0, 2.0]):
        for j, b in enumerate([0.0, 0.5, 1.0]):
            ref = _analytic(a + b, 0.3, 2.0, res.time)
            assert np.max(np.abs(res[f"x[{i + 1},{j + 1}]"] - ref)) < 1e-8


def test_block_residuals_equal_the_element_by_element_ones():
    """Each scalar residual of the block is the expression the element-wise path builds."""
    model = Grid()
    flat = flatten(model)
    scalar = next(iter(model.equations())).equations()
    assert len(scalar) == 6 == len(flat.equations)
    inputs = [flat.stacked_variables(), *[p.sx for p in flat.parameters], TIME.sx]
    block = ca.Function("block", inputs, [flat.stacked_residuals()])
    one_by_one = ca.Function("scalar", inputs, [ca.vertcat(*[to_sx(e.lhs) - to_sx(e.rhs)
                                                              for e in scalar])])
    rng = np.random.default_rng(3)
    args = [rng.uniform(0.2, 2.0, flat.stacked_variables().numel()),
            *rng.uniform(-1.0, 1.0, len(flat.parameters)), 0.7]
    assert np.array_equal(np.array(block(*args)), np.array(one_by_one(*args)))


def test_lazy_array_elements_equal_the_eager_ones():
    m = Grid()
    lazy = -(m.a + m.b) * m.x
    assert isinstance(lazy, ArrayExpr) and lazy.node is not None and lazy.shape == (2, 3)
    eager = np.empty((2, 3), dtype=object)
    for i in range(2):
        for j in range(3):
            eager[i, j] = -(m.a.items[i, 0] + m.b.items[0, j]) * m.x.items[i, j]
    assert [repr(e) for e in lazy.items.ravel()] == [repr(e) for e in eager.ravel()]
    assert repr(lazy[1, 2]) == repr(eager[1, 2])
    assert repr(sin(m.x).items[0, 0]) == repr(sin(m.x.items[0, 0]))
    assert len(lazy) == 2 and lazy.size == 6


class Mirror(Component):
    """Alias arrays: y = x, z = -x (removed by alias elimination), der(x) = -x."""

    n = 4
    x = Variable(shape="n", start=[1.0, 2.0, 3.0, 4.0], fixed=True)
    y = Variable(shape="n")
    z = Variable(shape="n")

    def equations(self):
        yield der(self.x) == -self.x
        yield self.y == self.x
        yield self.z + self.x == 0


def test_alias_arrays_are_eliminated_element_by_element():
    compiled = bg.compile(Mirror())
    assert len(compiled.flat.aliases) == 8
    assert compiled.flat.aliases["y[3]"] == ("x[3]", 1.0)
    assert compiled.flat.aliases["z[2]"] == ("x[2]", -1.0)
    res = bg.simulate(compiled, stop_time=1.0, interval=0.5, **TIGHT)
    assert res["z[4]"][-1] == pytest.approx(-4.0 * np.exp(-1.0), rel=1e-8)


class WrongUnits(Component):
    n = 5
    v = Variable(shape="n", unit="V")
    i = Variable(shape="n", unit="A")
    R = Parameter(shape="n", value=2.0, unit="Ohm")

    def equations(self):
        yield self.v == self.R * self.i
        yield self.v[1:] == self.i[:-1]
        yield self.v[0] == 1.0


def test_unit_mismatch_in_a_block_is_reported_once_with_the_count():
    with pytest.raises(UnitError) as err:
        bg.compile(WrongUnits())
    text = str(err.value)
    assert "v[2:5] == i[1:4]" in text
    assert "and 3 more equations" in text
    assert "v[1:5] == (R[1:5]*i[1:5])" not in text


class MixedArray(Component):
    """A stored array whose elements differ in unit: checked element by element."""

    v = Variable(shape=2, unit="V")
    i = Variable(shape=2, unit="A")

    def equations(self):
        mixed = ArrayExpr(np.array([self.v.items[0], self.i.items[0]], dtype=object))
        other = ArrayExpr(np.array([self.v.items[1], self.v.items[1]], dtype=object))
        yield mixed == other
        yield self.i[1] == 1.0
        yield self.v[1] == 2.0


def test_array_of_mixed_units_is_checked_element_by_element():
    with pytest.raises(UnitError, match=r"i\[1\] == v\[2\]"):
        bg.compile(MixedArray())
    assert bg.compile(MixedArray(), units="off").balance.balanced


FOREIGN = Mirror()


class Stranger(Component):
    x = Variable(shape=4)

    def equations(self):
        yield self.x == FOREIGN.x * 2.0


def test_block_using_a_foreign_array_names_it():
    with pytest.raises(EquationError, match=r"uses x\[1\] of Mirror, which is not part of"):
        bg.compile(Stranger())


class Mismatch(Component):
    x = Variable(shape=3)
    y = Variable(shape=2)

    def equations(self):
        yield self.x == self.y


def test_block_of_mismatched_shapes_names_the_component():
    with pytest.raises(EquationError, match=r"top level \(Mismatch\).*shapes \(3,\) and \(2,\)"):
        bg.compile(Mismatch())


class SwitchedDecay(Component):
    """der(x) = -k*x with the gain k switched from 1 to 3 at t = 0.5 (a when-clause beside
    the block equation): x_i(t) = x0_i*exp(-t) before, x0_i*exp(-0.5)*exp(-3(t-0.5)) after."""

    x = Variable(shape=3, start=[1.0, 2.0, 4.0], fixed=True)
    k = bg.Discrete(start=1.0, unit="1/s")

    def equations(self):
        yield der(self.x) == -self.k * self.x
        yield bg.when(bg.time > 0.5, self.k == 3.0)


def test_block_equation_in_a_hybrid_model():
    eq = next(iter(SwitchedDecay().equations()))
    assert isinstance(eq, ArrayEquation) and eq.is_block()
    res = bg.simulate(SwitchedDecay(), stop_time=1.0, interval=0.05, **TIGHT)
    t = res.time
    ref = np.where(t <= 0.5, np.exp(-t), np.exp(-0.5) * np.exp(-3.0 * (t - 0.5)))
    for k, x0 in enumerate([1.0, 2.0, 4.0]):
        assert np.max(np.abs(res[f"x[{k + 1}]"] - x0 * ref)) < 1e-7


def test_der_of_a_stored_array_is_the_elementwise_der():
    g = Grid()
    fast = der(g.x[:, 1:])
    assert isinstance(fast, ArrayExpr) and fast.shape == (2, 2)
    for i in range(2):
        for j in range(2):
            elem = fast.items[i, j]
            assert elem.sym is g.x[i, j + 1].sym.der            # the one derivative symbol
            assert elem.sym is der(g.x[i, j + 1]).sym
    assert [float(d) for d in der(g.a).items.flat] == [0.0, 0.0]   # parameters: constant
    mixed = der(g.x[0, :] * 2.0)                      # not stored leaves: the general rule
    assert isinstance(mixed, ArrayExpr) and mixed.shape == (3,)
    assert str(to_sx(mixed.items[1])) == str(to_sx(2.0 * der(g.x[0, 1])))
