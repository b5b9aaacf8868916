"""Which models take the array path, and their columns.

The array path (:mod:`bgmodelica.array_path`) compiles a *leaf* model written with array
equations without making a Python object per scalar. It takes a model only when the result
is the one the scalar pipeline gives; anything else goes the usual way:

- one component, without subcomponents, connectors, connections or initial equations (a
  model of leaf components joined by ``connect`` is collected by :mod:`.components`);
- plain :class:`~bgmodelica.core.variables.Variable` and
  :class:`~bgmodelica.core.variables.Output` (state selection at most ``PREFER`` or ``AVOID``),
  :class:`~bgmodelica.core.variables.Parameter` and
  :class:`~bgmodelica.core.variables.Input` declarations, parameters given as numbers;
- equations that are array equations lowered as blocks, or scalar equations (lowered in
  groups of one shape), built from whole-array arithmetic and the smooth math functions
  (no relations, events or ``if_else``); aliases ``a == b`` between variables are
  eliminated as the scalar pipeline eliminates them (:mod:`.aliases`);
- at least :data:`ARRAY_PATH_FROM` scalar equations (below, the scalar pipeline is as fast).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from itertools import chain, compress, repeat
from operator import attrgetter, is_not
from typing import Any

import numpy as np

from ..core.arrays import ArrayEquation, _block_operand
from ..core.component import Component, _own_methods
from ..core.expr import Equation
from ..core.variables import TIME, Input, Output, Parameter, StateSelect, Symbol, Variable

#: state selections the array path takes: they only rank aliases and the choice of dummy
#: derivatives, which a model solved explicitly (index 1, no state choice) does not make;
#: ``ALWAYS`` and ``NEVER`` can contradict the structure, which the scalar pipeline reports
SOFT_STATE_SELECT = frozenset((StateSelect.DEFAULT, StateSelect.PREFER, StateSelect.AVOID))
#: the array path is used from this many scalar equations on
ARRAY_PATH_FROM = 1000

@dataclass
class Traits:
    """What alias elimination reads of each column (variable or derivative), as arrays:
    whether it has a time derivative (``has_der``), is one (``is_der``), its ``fixed``,
    ``state_select`` and ``start``, and the dots and length of its name."""

    has_der: np.ndarray
    is_der: np.ndarray
    fixed: np.ndarray
    state_select: np.ndarray
    start: np.ndarray
    dots: np.ndarray
    length: np.ndarray


@dataclass
class Collected:
    """A model the array path takes: ``order`` holds its variables in the order of the
    scalar pipeline (each variable followed by its time derivative, if used), ``params`` its
    parameters in declaration order; ``equations`` are the equations and ``n_rows`` their
    number of scalar equations; the last ``n_inputs`` of ``params`` are the model's inputs
    (:class:`~bgmodelica.core.variables.Input`, held constant by ``simulate`` unless given
    as tables). ``names`` and ``param_names`` are their dotted names (``scoped``: the
    symbols' own names are not: a model of components), ``param_owners`` the components
    declaring the parameters (None: the top level); ``sources`` the equations as written
    with their origins for the unit check (None: all written at ``where``), ``traits`` the
    columns' :class:`Traits` when known at once (None: read off the symbols). ``pos`` maps
    ``id(symbol)`` to its column (variables and derivatives, then parameters, then time) and
    ``memo`` the declared arrays to their columns (as
    :func:`~bgmodelica.core.flatten_arrays.residual` reads them)."""

    name: str
    where: str
    order: list[Symbol]
    params: list[Symbol]
    equations: list[Any]
    n_rows: int
    pos: dict[int, int]
    memo: dict[int, Any]
    n_inputs: int = 0
    names: list[str] = field(default_factory=list)
    param_names: list[str] = field(default_factory=list)
    param_owners: list[str] | None = None
    sources: Any = None
    scoped: bool = False
    traits: Traits | None = None

    def __post_init__(self) -> None:
        if not self.names:
            self.names = list(map(_NAME, self.order))
            self.param_names = list(map(_NAME, self.params))


_DECL, _NAME = attrgetter("decl"), attrgetter("name")
_NUMBERS = (int, float, np.integer, np.floating)


def collect(model: Any, minimum: int | None = None) -> Collected | str:
    """The model's columns and equations, or why it does not take the array path."""
    if not isinstance(model, Component) or type(model) is Component:
        return "not a component class"
    minimum = ARRAY_PATH_FROM if minimum is None else minimum
    if model._children:
        from .components import collect_components

        return collect_components(model, minimum)
    symbols = list(model._symbols.values())
    names = list(model._symbols)
    runs = _runs(model, names)
    # the elements of a declared array share their declaration's class
    kinds = []
    for start, _, _ in runs:
        kind = type(symbols[start].decl)
        if kind not in (Variable, Output, Parameter, Input):
            return f"{symbols[start].name} is a {kind.__name__}"
        kinds.append(kind)

    def of_kind(*wanted: type) -> list[Symbol]:
        return list(chain.from_iterable(symbols[a:a + n] for (a, n, _), kind in
                                        zip(runs, kinds, strict=True) if kind in wanted))

    variables, params, inputs = of_kind(Variable, Output), of_kind(Parameter), of_kind(Input)
    if set(map(attrgetter("state_select"), map(_DECL, variables))) - SOFT_STATE_SELECT:
        return "a variable has a state selection"
    if not all(issubclass(t, _NUMBERS) and t is not bool
               for t in set(map(type, map(attrgetter("value"), map(_DECL, params))))
               | set(map(type, map(attrgetter("start"), map(_DECL, inputs))))):
        return "a parameter or an input is not given as a number"
    if _own_methods(type(model), "initial_equations") != (Component.initial_equations,) \
            or model.__dict__.get("_initial_equations"):
        return "it has initial equations"        # (not called here: they may make symbols)
    if len(variables) < minimum:       # a balanced model has one equation per variable
        return "small"
    from ..validate import guarded_equations

    name = model.name or type(model).__name__
    where = f"top level ({type(model).__name__})"
    equations = guarded_equations(model, where, "", blocks=True)
    n_rows = 0
    for eq in equations:
        if isinstance(eq, ArrayEquation):
            n_rows += len(eq)
        elif type(eq) is Equation:
            if not (_block_operand(eq.lhs) and _block_operand(eq.rhs)):
                return "a scalar equation is not smooth arithmetic"
            n_rows += 1
        else:
            return f"it has a {type(eq).__name__}"
    if n_rows < minimum:
        return "small"
    # columns: each variable, then its derivative if the equations made one
    ders = list(map(attrgetter("der"), variables))
    has_der = np.fromiter(map(is_not, ders, repeat(None)), bool, len(ders))
    keep = np.ones(2 * len(variables), dtype=bool)
    keep[1::2] = has_der
    order = list(compress(chain.from_iterable(zip(variables, ders, strict=True)),
                          keep.tolist()))
    n = len(order)
    var_col = np.arange(len(variables)) + np.cumsum(has_der) - has_der
    ders = list(compress(ders, has_der))
    sizes = np.array([size for _, size, _ in runs], dtype=np.int64)
    kind_of = np.repeat(np.array([0 if k in (Variable, Output) else 1 if k is Parameter else 2
                                  for k in kinds], dtype=np.int8), sizes)
    column = np.empty(len(symbols), dtype=np.int64)
    column[kind_of == 0] = var_col
    column[kind_of == 1] = n + np.arange(len(params))
    column[kind_of == 2] = n + len(params) + np.arange(len(inputs))
    pos, memo = _Positions(symbols, column), {}
    for start, _, array in runs:
        if not array:
            pos[id(symbols[start])] = int(column[start])
    for key, shape in model.__dict__.get("_arrays", {}).items():
        start = names.index(_first_element(key, shape))
        pos.arrays[key] = (start, shape)
        root = getattr(model, key).items
        while isinstance(root.base, np.ndarray):
            root = root.base
        memo[id(root)] = (root, column[start:start + int(np.prod(shape))])
    pos.update(zip(map(id, ders), (var_col[has_der] + 1).tolist(), strict=True))
    pos[id(TIME)] = n + len(params) + len(inputs)
    return Collected(name, where, order, params + inputs, equations, n_rows, pos, memo,
                     len(inputs))


def _first_element(key: str, shape: tuple[int, ...]) -> str:
    return f"{key}[{','.join(['1'] * len(shape))}]"


def _runs(model: Any, names: list[str]) -> list[tuple[int, int, bool]]:
    """``(start, size, is_array)`` of each declaration in ``names`` (the model's symbols in
    order): a declared array is one run of its elements, a scalar a run of one."""
    arrays = sorted((names.index(_first_element(key, shape)), int(np.prod(shape)))
                    for key, shape in model.__dict__.get("_arrays", {}).items())
    out: list[tuple[int, int, bool]] = []
    k = 0
    for start, size in arrays:
        out.extend((j, 1, False) for j in range(k, start))
        out.append((start, size, True))
        k = start + size
    out.extend((j, 1, False) for j in range(k, len(names)))
    return out


_ELEMENT = re.compile(r"^(.*)\[([0-9,]+)\]$")


class _Positions(dict):
    """``id(symbol)`` -> column; the elements of declared arrays are added on the first
    lookup that misses (most equations read them through ``memo``, by slices, and
    :meth:`of` finds one element by its name)."""

    def __init__(self, symbols: list[Any], column: np.ndarray) -> None:
        super().__init__()
        self.symbols, self.column = symbols, column
        self.all = symbols
        self.arrays: dict[str, tuple[int, tuple[int, ...]]] = {}

    def of(self, sym: Any) -> int:
        """The column of ``sym`` (KeyError for a symbol of another component)."""
        found = self.get(id(sym))
        if found is not None:
            return found
        m = _ELEMENT.match(getattr(sym, "name", ""))
        run = self.arrays.get(m.group(1)) if m else None
        if run is not None:
            start, shape = run
            index = tuple(int(i) - 1 for i in m.group(2).split(","))
            if len(index) == len(shape) and all(0 <= i < d for i, d in zip(index, shape,
                                                                           strict=True)):
                k = start + int(np.ravel_multi_index(index, shape))
                if self.all[k] is sym:
                    return int(self.column[k])
        return self[id(sym)]

    def __missing__(self, key: int) -> int:
        if self.symbols is None:
            raise KeyError(key)
        self.update(zip(map(id, self.symbols), self.column.tolist(), strict=True))
        self.symbols = None
        return self[key]
