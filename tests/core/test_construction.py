"""Components built from a description of a first instance are as the constructor makes them."""

import pytest

from bgmodelica import Component, Parameter, Variable, connect
from bgmodelica.errors import DeclarationError
from library.electrical import Pin, Resistor
from library.examples.circuits import RCLadderSections, Section


def _general(make, monkeypatch):
    """``make()`` by the general constructor alone (no descriptions made or used)."""
    from bgmodelica.core import children

    with monkeypatch.context() as m:
        m.setattr(children, "_plain_class", lambda cls: False)
        m.setattr(children, "_CLASS_BLUEPRINTS", {})
        m.setattr(children, "_KEY", "_test_general")
        return make()


def _shape(elem):
    """Everything an element holds, down its subcomponents (identity aside)."""
    attrs = vars(elem)
    return (type(elem).__name__, elem._name, elem._init_call, list(attrs),
            [(k, s.name, s.decl, s.owner is elem, attrs[k] is s.leaf, s.leaf.sym is s)
             for k, s in elem._symbols.items()],
            [(k, attrs[k] is c, _shape(c)) for k, c in elem._children.items()])


@pytest.mark.parametrize("mods", [{}, {"R.R": 0.5, "C.C": 0.25, "C.v": 2.0},
                                  {"R": {"R": 3.0}, "C.v": {"start": 1.0, "fixed": False}}])
def test_described_instances_are_as_the_constructor_makes_them(mods, monkeypatch):
    general = _shape(_general(lambda: Section(**mods), monkeypatch))
    for _ in range(3):                          # first instance, then from descriptions
        assert _shape(Section(**mods)) == general


def test_a_ladder_of_sections_is_as_the_constructor_makes_it(monkeypatch):
    general = _general(lambda: RCLadderSections(4), monkeypatch)
    fast = RCLadderSections(4)
    assert _shape(fast) == _shape(general)
    assert [(c.a.name, c.b.name) for c in fast._equations] \
        == [(c.a.name, c.b.name) for c in general._equations]


def test_instances_share_no_mutable_state():
    a, b = Section(), Section()
    a.modify(**{"R.R": 7.0})
    assert b.R._symbols["R"].decl.value == 1.0 == Section.R._symbols["R"].decl.value
    assert a.p is not b.p and a.p._symbols["v"] is not b.p._symbols["v"]
    assert a.R.p._symbols["v"].owner is a.R.p and a.R._name == "R" and a.R.p._name == "p"
    a.connect(a.p, a.n)
    assert b._equations == () and len(a._equations) == 1


def test_modifier_errors_are_unchanged():
    class _General(Section):
        def __init__(self, **modifiers):
            super().__init__(**modifiers)

    for make in (Section, _General):
        with pytest.raises(DeclarationError, match="has no parameter, variable or subcomponent"):
            make(X=1.0)
        with pytest.raises(DeclarationError, match="has no subcomponent 'Q'"):
            make(**{"Q.R": 1.0})
        with pytest.raises(DeclarationError, match="must be a dict of values"):
            make(R=1.0)


def test_a_constructor_of_the_users_runs_once_per_instance():
    calls = []

    class Counted(Resistor):
        def __init__(self, **modifiers):
            calls.append(1)
            super().__init__(**modifiers)

    class Holder(Component):
        r = Counted(R=2.0)
        p = Pin()

    n = len(calls)
    Holder(), Holder()
    assert len(calls) - n == 2


def test_plain_classes_with_modifiers_and_connections():
    class Cell(Component):
        k = Parameter(2.0, unit="1")
        x = Variable(unit="V")
        a = Pin()
        b = Pin()

        def equations(self):
            yield connect(self.a, self.b)
            yield self.x == self.k * self.a.v

    cells = [Cell(k=float(i), x=float(i)) for i in range(3)]
    assert [c.k.sym.decl.value for c in cells] == [0.0, 1.0, 2.0]
    assert [(c.x.sym.decl.start, c.x.sym.decl.fixed) for c in cells] == [
        (0.0, True), (1.0, True), (2.0, True)]
    assert Cell().k.sym.decl is Cell._declarations["k"]
