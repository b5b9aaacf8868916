"""Flattening binds a model's symbols and residuals as rows of SX columns and takes a scalar
out only when a pass reads it: the scalars read later are the very rows of the columns the
passes work on, a model compiled twice reuses its first binding, and a pickled compiled
model keeps the rows."""

from __future__ import annotations

import casadi as ca
import numpy as np

import bgmodelica as bg
from bgmodelica.core.flatmodel import Picked
from bgmodelica.studies.payload import pickle_compiled, unpickle_compiled
from library.examples import RCLadder, RCLadderVector


def test_a_large_model_compiles_without_a_scalar_per_row():
    compiled = bg.compile(RCLadderVector(300))
    model = compiled.reduced.model
    assert not any(v._sx is not None for v in model.variables)
    assert not any(e._residual is not None for e in model.equations)


def test_a_scalar_taken_out_is_the_row_of_the_column():
    compiled = bg.compile(RCLadder(40))
    model = compiled.reduced.model
    column = model.stacked_variables()
    for k in (0, 7, len(model.variables) - 1):
        assert model.variables[k].sx.element_hash() == column[k].element_hash()
    residuals = model.stacked_residuals()
    for k in (0, 5, len(model.equations) - 1):
        assert ca.is_equal(model.equations[k].residual, residuals[k], 2)
    taken = model.variables[3].sx
    assert model.variables[3].sx is taken               # taken out once, then kept


def test_a_model_compiled_twice_gives_the_same_dae():
    model = RCLadder(25)
    first, second = bg.compile(model), bg.compile(model)
    assert str(first.dae.ode) == str(second.dae.ode)
    assert first.dae.state_names == second.dae.state_names
    a = bg.simulate(first, stop_time=0.05, interval=0.01)
    b = bg.simulate(second, stop_time=0.05, interval=0.01)
    assert np.array_equal(a["C25.v"], b["C25.v"])


def test_a_pickled_compiled_model_keeps_its_rows_and_results():
    compiled = bg.compile(RCLadderVector(50))
    again = unpickle_compiled(pickle_compiled(compiled))     # as Dask workers get it
    assert again.reduced.model.variables[0].at is not None
    a = bg.simulate(compiled, stop_time=0.05, interval=0.01)
    b = bg.simulate(again, stop_time=0.05, interval=0.01)
    assert np.array_equal(a["v[50]"], b["v[50]"])


def test_picked_reads_the_attribute_of_the_chosen_items_only_when_asked():
    class Item:
        reads = 0

        @property
        def value(self):
            Item.reads += 1
            return 2.0

    items = [Item() for _ in range(5)]
    picked = Picked(items, "value", [4, 1])
    assert len(picked) == 2 and Item.reads == 0
    assert picked[1] == 2.0 and Item.reads == 1
    assert len(Picked(items, "value")) == 5


def test_rows_of_slices_and_transposes_of_a_declared_array_are_read_by_strides():
    from bgmodelica.core.flatten_arrays import _rows

    class Leaf:
        def __init__(self):
            self.sym = object()

    base = np.empty(120, dtype=object)
    base[:] = [Leaf() for _ in range(120)]
    pos = {id(leaf.sym): 1000 + 7 * k for k, leaf in enumerate(base)}
    memo: dict = {}
    grid = base.reshape(12, 10)
    for view in (base, base[1:], base[:-1], base[::-3], base[5:90:4], grid.T, grid[3:, ::2].T,
                 grid[::-1, 2:7]):
        assert _rows(view, pos, memo) == [pos[id(leaf.sym)] for leaf in view.ravel()]
    mixed = base.copy()
    mixed[-1] = 3.0                                   # not all declared scalars: read directly
    assert _rows(mixed[:70], pos, memo) == [pos[id(leaf.sym)] for leaf in mixed[:70]]
    del pos[id(base[4].sym)]
    fresh: dict = {}
    try:
        _rows(base[2:], pos, fresh)
    except KeyError:
        pass
    else:
        raise AssertionError("a symbol outside the model must not get a row")
