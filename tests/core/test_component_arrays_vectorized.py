"""Arrays of components, and many sibling components of one class: their equations written
once for the whole group (one array equation per equation of the class, each scalar keeping
its element's origin) where that is exact, element by element otherwise."""

from __future__ import annotations

import math
from collections import Counter

import casadi as ca
import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica import Component, Parameter, Variable, array_of, der, time
from bgmodelica.core.flatten import flatten
from bgmodelica.core.flatten_vectorized import GROUP_FROM
from bgmodelica.core.variables import TIME
from library.examples import RCLadder, RCLadderArrays, RCLadderVector

TIGHT = {"rtol": 1e-10, "atol": 1e-12}


def blocks(model: Component) -> set[str]:
    """Origins of the groups whose equations were written once."""
    return {entry[1] for entry in flatten(model).sources.arrays}


def test_library_component_arrays_are_written_once():
    assert {"R[1] .. R[6] (6 Resistor components)",
            "C[1] .. C[6] (6 Capacitor components)"} <= blocks(RCLadderArrays(6))


def test_many_siblings_of_one_class_are_written_once():
    n = GROUP_FROM + 4
    assert {f"R1 .. R{n} ({n} Resistor components)",
            f"C1 .. C{n} ({n} Capacitor components)"} <= blocks(RCLadder(n))
    assert not blocks(RCLadder(GROUP_FROM - 1))
    a = bg.simulate(RCLadder(n), stop_time=0.2, interval=0.02, **TIGHT)
    b = bg.simulate(RCLadderVector(n), stop_time=0.2, interval=0.02, **TIGHT)
    assert np.max(np.abs(a[f"C{n}.v"] - b[f"v[{n}]"])) < 1e-12
    assert np.max(np.abs(a["R7.i"] - b["i[7]"])) < 1e-9


@pytest.mark.parametrize("make", [lambda: RCLadderArrays(5), lambda: RCLadder(GROUP_FROM)])
def test_same_scalar_equations_as_element_by_element(make, monkeypatch):
    """The flat model has the same variables, the same equation origins and, equation by
    equation, the same residuals (compared numerically at a random point) as without
    writing the groups once."""
    from bgmodelica.core import flatten as flatten_module

    fast = flatten(make())
    assert fast.sources.arrays
    monkeypatch.setattr(flatten_module, "array_equations", lambda items: None)
    slow = flatten(make())
    assert not slow.sources.arrays
    assert [v.name for v in fast.variables] == [v.name for v in slow.variables]
    assert Counter(e.origin for e in fast.equations) == Counter(e.origin for e in slow.equations)
    rng = np.random.default_rng(1)
    values: dict[str, float] = {}

    def residuals(flat) -> list[float]:
        syms = [v.sx for v in flat.variables] + [p.sx for p in flat.parameters]
        names = [v.name for v in flat.variables] + [p.name for p in flat.parameters]
        vals = [values.setdefault(n, float(rng.normal())) for n in names]
        f = ca.Function("r", [ca.vertcat(*syms), TIME.sx], [flat.stacked_residuals()])
        return sorted(np.round(np.asarray(f(vals, 0.3)).ravel(), 12).tolist())

    assert residuals(fast) == residuals(slow)


def test_results_equal_the_component_per_section_ladder():
    a = bg.simulate(RCLadderArrays(7), stop_time=0.3, interval=0.03, **TIGHT)
    b = bg.simulate(RCLadder(7), stop_time=0.3, interval=0.03, **TIGHT)
    for k in (1, 4, 7):
        assert np.max(np.abs(a[f"C[{k}].v"] - b[f"C{k}.v"])) < 1e-12
        assert np.max(np.abs(a[f"R[{k}].i"] - b[f"R{k}.i"])) < 1e-9


class Scaled(Component):
    """y = gain * time, with ``gain`` a plain Python attribute set per instance."""

    y = Variable()

    def __init__(self, gain: float = 1.0, **modifiers):
        self.gain = gain
        super().__init__(**modifiers)

    def equations(self):
        yield self.y == self.gain * time


class Switched(Component):
    """A Python ``if`` on a plain attribute picks the equation."""

    x = Variable(start=1.0, fixed=True)
    k = Parameter(2.0)

    def __init__(self, decay: bool = True, **modifiers):
        self.decay = decay
        super().__init__(**modifiers)

    def equations(self):
        if self.decay:
            yield der(self.x) == -self.k * self.x
        else:
            yield der(self.x) == self.k


class Helped(Component):
    """Equations built by a method, a static method and a property of the class."""

    x = Variable(start=1.0, fixed=True)
    a = Parameter(0.5)
    FACTOR = 2.0

    @staticmethod
    def twice(e):
        return Helped.FACTOR * e

    @property
    def rate(self):
        return self.twice(self.a)

    def rhs(self):
        return -self.rate * self.x * self.FACTOR / 2.0

    def equations(self):
        yield der(self.x) == self.rhs()


class Bank(Component):
    def __init__(self, gains, decays):
        super().__init__()
        self.s = array_of(Scaled, len(gains), gain=list(gains))
        self.w = array_of(Switched, len(decays), decay=list(decays))


def test_a_plain_attribute_that_differs_falls_back_to_element_by_element():
    model = Bank([1.0, -2.0, 3.0], [True, False, True])
    assert not blocks(Bank([1.0, -2.0, 3.0], [True, False, True]))
    res = bg.simulate(model, stop_time=1.0, interval=0.5, **TIGHT)
    assert np.allclose(res["s[2].y"], -2.0 * res.time)
    assert math.isclose(res["w[1].x"][-1], math.exp(-2.0), rel_tol=1e-8)
    assert math.isclose(res["w[2].x"][-1], 3.0, rel_tol=1e-8)


def test_a_plain_attribute_equal_in_every_element_is_used_as_is():
    assert blocks(Bank([2.0, 2.0], [False, False, False])) == {
        "s[1] .. s[2] (2 Scaled components)", "w[1] .. w[3] (3 Switched components)"}
    res = bg.simulate(Bank([2.0, 2.0], [False, False, False]), stop_time=1.0, interval=0.5,
                      **TIGHT)
    assert np.allclose(res["s[2].y"], 2.0 * res.time)
    assert math.isclose(res["w[3].x"][-1], 3.0, rel_tol=1e-8)


def test_an_element_with_an_added_equation_is_not_vectorized():
    model = Bank([1.0, 1.0], [True, True])
    model.s[0].declare("z", Variable())
    model.s[0].equation(model.s[0].z == 5.0)
    assert blocks(model) == {"w[1] .. w[2] (2 Switched components)"}
    res = bg.simulate(model, stop_time=0.5, interval=0.5, **TIGHT)
    assert res["s[1].z"][-1] == 5.0


class Helpers(Component):
    def __init__(self, n=3):
        super().__init__()
        self.h = array_of(Helped, n, a=[0.5, 1.0, 1.5])


def test_methods_static_methods_properties_and_constants_work_on_the_array():
    assert blocks(Helpers()) == {"h[1] .. h[3] (3 Helped components)"}
    res = bg.simulate(Helpers(), stop_time=1.0, interval=0.5, **TIGHT)
    for k, a in enumerate((0.5, 1.0, 1.5), start=1):
        assert math.isclose(res[f"h[{k}].x"][-1], math.exp(-2.0 * a), rel_tol=1e-8)


class Ohm(Component):
    """``v = R*i`` with ``v`` in V, ``R`` in Ohm, ``i = I`` in A."""

    v = Variable(unit="V")
    i = Variable(unit="A")
    R = Parameter(1.0, unit="Ohm")
    I = Parameter(2.0, unit="A")  # noqa: E741

    def equations(self):
        yield self.i == self.I
        yield self.v == self.R * self.i


class OhmBank(Component):
    def __init__(self, n: int, odd: dict | None = None):
        super().__init__()
        for k in range(n):
            self.add(f"r{k}", Ohm(**({"v": odd} if odd is not None and k == n - 1 else {})))


def test_a_unit_changed_on_one_element_of_a_group_is_checked_there():
    from bgmodelica.errors import UnitError

    bg.compile(OhmBank(GROUP_FROM + 2))                   # one unit: fine
    with pytest.raises(UnitError, match=r"r65 \(Ohm\): v == \(R\*i\)"):
        bg.compile(OhmBank(GROUP_FROM + 2, odd={"unit": "A"}))


def test_a_unit_error_of_a_whole_group_reads_like_the_class_equation():
    from bgmodelica.errors import UnitError

    class Wrong(Component):
        v = Variable(unit="V")
        i = Variable(unit="A")
        I = Parameter(2.0, unit="A")  # noqa: E741

        def equations(self):
            yield self.i == self.I
            yield self.v == self.i                            # A where V is declared

    class WrongBank(Component):
        def __init__(self, n):
            super().__init__()
            for k in range(n):
                self.add(f"r{k}", Wrong())

    with pytest.raises(UnitError) as err:
        bg.compile(WrongBank(GROUP_FROM))
    assert f"r0 .. r{GROUP_FROM - 1} ({GROUP_FROM} Wrong components): v == i" in str(err.value)
