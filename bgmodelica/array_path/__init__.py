"""The array path: large models compiled without a Python object per scalar.

Two kinds of model take it: a leaf model of array equations (:mod:`.collect`), and a model
of components, flat or hierarchical, joined by ``connect`` (:mod:`.components`, its
identical leaves written once across their parents, its connection sets as
linear rows: :mod:`.connections`). ``compile`` sends a model here first
(:func:`compile_arrays`). A model it takes is lowered to MX blocks (:mod:`.lowering`), its
aliases eliminated (:mod:`.aliases`), ordered on its integer incidence
(:mod:`bgmodelica.structure.explicit_order`), solved block by block and assembled into the
same :class:`~bgmodelica.backends.casadi_dae.CasadiDAE` the scalar pipeline builds: the same
variable names and order, states, parameters, start values and ODE. A model it does not take,
or whose blocks do not solve explicitly (an algebraic loop, a higher index, an unbalanced or
singular system), goes through the scalar pipeline, which also gives the precise errors.

What simulation needs is ready at once. The scalar structures (``flat``, ``balance``,
``reduced``, ``sorted``), which FMU export, ``check`` and the analyses read, are built by
the scalar pipeline on first use (:class:`ArrayCompiledModel`), and their time is added to
``timings`` as ``scalar_structures``.
"""

from __future__ import annotations

import time as _time
from collections.abc import Iterator, Sequence
from itertools import repeat
from operator import attrgetter, is_not
from typing import Any, NamedTuple

import numpy as np

from ..compiler import CompiledModel, Laps
from ..errors import ModelError
from ..structure.explicit_order import explicit_order
from .aliases import find_aliases
from .build import assemble, solve_blocks
from .collect import ARRAY_PATH_FROM, collect
from .lowering import Lowered
from .scalars import group_scalars

__all__ = ["ARRAY_PATH_FROM", "ArrayCompiledModel", "compile_arrays", "why_not"]

_DEFERRED = ("flat", "balance", "reduced", "sorted")


def why_not(model: Any, minimum: int | None = None) -> str | None:
    """Why ``model`` does not take the array path (None when it does)."""
    found = _build(model, "off", minimum)
    return found if isinstance(found, str) else None


def compile_arrays(model: Any, units: str = "error",
                   minimum: int | None = None) -> ArrayCompiledModel | None:
    """``model`` compiled by the array path, or None when it goes the scalar way."""
    found = _build(model, units, minimum)
    return None if isinstance(found, str) else found


def _build(model: Any, units: str, minimum: int | None) -> ArrayCompiledModel | str:
    from ..errors import UnitError
    from ..passes.units import check_equations, check_sources

    timings: dict[str, float] = {}
    lap = Laps(timings)
    col = collect(model, minimum)
    if isinstance(col, str):
        return col
    lap("collect")
    if col.sources is None:
        check_equations(col.equations, col.where, units)
    elif units != "off":
        try:
            check_sources(col.sources, "error")
        except UnitError:
            return "a unit error (the scalar pipeline names it)"
    lap("units")
    try:
        found = _compile_blocks(col, lap)
    except Exception as err:  # noqa: BLE001 -- the scalar pipeline gives the precise error
        return f"{type(err).__name__}: {err}"
    if isinstance(found, str):
        return found
    dae, kept = found
    variables = list(map(col.order.__getitem__, kept))
    names = list(map(col.names.__getitem__, kept)) if col.scoped else None
    return ArrayCompiledModel.made(col.name, dae, col.n_rows, timings, model, units,
                                   variables, names)


def _compile_blocks(col: Any, lap: Any) -> Any:
    """The :class:`~bgmodelica.backends.casadi_dae.CasadiDAE` of a collected model, or why
    its equations do not solve explicitly block by block."""
    col.equations = group_scalars(col.equations)
    aliases = find_aliases(col)
    if isinstance(aliases, str):
        return aliases
    low = Lowered(col, aliases)
    n = len(col.order)
    kept = np.ones(n, dtype=bool)
    if aliases is not None:
        kept[:] = False
        kept[aliases.keep] = True
    lap("lowering")
    is_state = col.traits.has_der.astype(bool) if col.traits is not None else \
        np.fromiter(map(is_not, map(_DER, col.order), repeat(None)), bool, n)
    unknown = np.flatnonzero(~is_state & kept)
    n_rows = int(sum(low.sizes))
    if unknown.size != n_rows:
        return f"{n_rows} equations for {unknown.size} unknowns"
    as_unknown = np.full(low.n + low.n_p + 1, -1, dtype=np.int64)
    as_unknown[unknown] = np.arange(unknown.size)
    cols = as_unknown[low.cols]
    used = cols >= 0
    order = explicit_order(unknown.size, low.rows[used], cols[used], low.sizes)
    if isinstance(order, str):
        return order
    lap("structure")
    solved = solve_blocks(low, order, unknown)
    if isinstance(solved, str):
        return solved
    lap("solve")
    dae = assemble(col, low, solved, np.flatnonzero(is_state), aliases)
    lap("backend")
    return dae, np.flatnonzero(kept).tolist()


class ArrayCompiledModel(CompiledModel):
    """A :class:`~bgmodelica.compiler.CompiledModel` made by the array path: ``dae`` is
    ready; ``flat``, ``balance``, ``reduced`` and ``sorted`` are made by the scalar pipeline
    when first read (and ``dae`` is then the scalar pipeline's, which is the same model)."""

    @classmethod
    def made(cls, name: str, dae: Any, n_equations: int, timings: dict[str, float],
             source: Any, units: str, variables: list[Any],
             names: list[str] | None = None) -> ArrayCompiledModel:
        """``variables``: the symbols of the variables left, ``names`` their dotted names
        (None: the symbols' own names are)."""
        self = object.__new__(cls)
        self.__dict__.update(name=name, dae=dae, n_flat_equations=n_equations,
                             timings=timings, source=source, _units=units,
                             _variables=variables, _names=names, evaluated={})
        return self

    def __getattr__(self, attr: str) -> Any:
        if attr in _DEFERRED and "source" in self.__dict__:
            self._complete()
            return self.__dict__[attr]
        raise AttributeError(attr)

    def _complete(self) -> None:
        """Build the scalar structures (and their DAE) by the scalar pipeline."""
        from ..compiler import _compile
        from ..structure.graph import gc_paused

        if self.source is None:
            raise RuntimeError(f"{self.name}: the scalar structures of a model compiled by "
                               "the array path need its source component")
        t0 = _time.perf_counter()
        with gc_paused():
            full = _compile(self.source, None, self.__dict__.get("_units", "error"),
                            zero_terms=False)    # the array path keeps every parameter
        mine, theirs = self.dae, full.dae
        if (mine.names != theirs.names or mine.state_names != theirs.state_names
                or [q.name for q in mine.parameters] != [q.name for q in theirs.parameters]
                or not np.array_equal(mine.p_default, theirs.p_default)
                or not np.array_equal(mine.x_start, theirs.x_start)):
            raise ModelError(f"{self.name}: its component no longer gives the model that was "
                             "compiled (was it modified after compile()?); compile it again")
        for attr in _DEFERRED:
            self.__dict__[attr] = getattr(full, attr)
        self.__dict__["dae"] = theirs
        self.timings["scalar_structures"] = _time.perf_counter() - t0

    @property
    def declarations(self) -> Any:
        """What simulation reads of the flat model (see :class:`Declarations`)."""
        if "reduced" in self.__dict__:
            return self.reduced.model
        found = self.__dict__.get("_declarations")
        if found is None:
            found = self.__dict__["_declarations"] = Declarations(self)
        return found

    @property
    def has_state_choice(self) -> bool:
        return False

    def summary(self) -> dict[str, Any]:
        """:meth:`CompiledModel.summary` read off the array path's result (the scalar
        structures are not needed): an explicit ODE, every algebraic variable solved."""
        if "reduced" in self.__dict__:
            return super().summary()
        dae = self.dae
        n = len(dae.names) - len(dae.state_names)       # unknowns: derivatives, algebraics
        algebraic = any(v.der is None and v.der_of is None
                        for v in self.__dict__["_variables"])
        return {
            "model": self.name, "equations": n, "unknowns": n, "balanced": True,
            "flat_equations_before_alias_elimination": self.n_flat_equations,
            "aliases_eliminated": len(dae.aliases),
            "structural_index": 1 if algebraic else 0,   # Pryce's: algebraic variables add 1
            "differentiated_equations": [], "states": list(dae.state_names),
            "dummy_derivatives": [], "algebraic_variables": [], "algebraic_loops": [],
            "dynamic_state_selection": False, "parameters": len(dae.parameters),
            "inputs": [u.name for u in dae.inputs], "events": None,
            "compile_seconds": dict(self.timings),
        }


_DECL, _DER, _UNIT = attrgetter("decl"), attrgetter("der"), attrgetter("unit")


class Declared(NamedTuple):
    """A variable as simulation reads it: dotted name and declaration."""

    name: str
    decl: Any


class _Variables(Sequence):
    """The variables of a model of components as :class:`Declared` items, made as they are
    read (a list of them would be one more object per variable for the collector to scan)."""

    def __init__(self, names: list[str], symbols: list[Any]) -> None:
        self.names, self.symbols = names, symbols

    def __len__(self) -> int:
        return len(self.names)

    def __getitem__(self, k: Any) -> Any:
        if isinstance(k, slice):
            return list(map(Declared, self.names[k], map(_DECL, self.symbols[k])))
        return Declared(self.names[k], self.symbols[k].decl)

    def __iter__(self) -> Iterator[Declared]:
        return map(Declared, self.names, map(_DECL, self.symbols))

    def units(self) -> dict[str, str]:
        """Name -> declared unit, without an item per variable."""
        return dict(zip(self.names, map(_UNIT, map(_DECL, self.symbols)), strict=True))

    def declarations(self, names: set[str]) -> dict[str, Any]:
        """The declarations of these names (name -> declaration; names not found are left
        out), without an item per variable."""
        index = self._index_of()
        symbols = self.symbols
        return {name: symbols[index[name]].decl for name in names if name in index}

    def declarations_at(self, positions: list[int]) -> list[Any]:
        """The declarations of the variables at these positions."""
        symbols = self.symbols
        return [symbols[k].decl for k in positions]

    def _index_of(self) -> dict[str, int]:
        index = self.__dict__.get("_index")
        if index is None:
            index = self._index = dict(zip(self.names, range(len(self.names)), strict=True))
        return index

    def lookup(self, names: set[str]) -> dict[str, Declared]:
        """The variables of these names (name -> item; names not found are left out)."""
        index = self._index_of()
        return {name: self[index[name]] for name in names if name in index}


class Declarations:
    """The variables, parameters and inputs of a model compiled by the array path, and its
    aliases, as simulation reads them from a flat model (names, declarations; no
    discretes)."""

    def __init__(self, compiled: ArrayCompiledModel) -> None:
        self.name = compiled.name
        self.variables = compiled.__dict__["_variables"]
        names = compiled.__dict__.get("_names")
        if names is not None:
            self.variables = _Variables(names, self.variables)
        self.parameters = compiled.dae.parameters
        self.inputs = compiled.dae.inputs
        self.discretes: list[Any] = []
        self.aliases: dict[str, tuple[str, float]] = compiled.dae.aliases
