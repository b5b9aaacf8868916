"""``compile``: component tree -> flat model -> aliases removed -> balance check -> index
reduction -> BLT/tearing -> CasADi DAE. Each stage is a function of the previous one's output.
"""

from __future__ import annotations

import time as _time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .backends.casadi_dae import CasadiDAE, attach_initial_equations, build_dae
from .core.component import Component
from .core.flatmodel import FlatModel
from .core.flatten import flatten
from .errors import DeclarationError, ModelError, UnbalancedModelError
from .passes.alias import eliminate_aliases
from .passes.balance import BalanceReport, check_balance
from .passes.index_reduction import ReducedModel, Selector, reduce_index
from .passes.reference import check_references
from .passes.sorting import SortedDAE, sort_equations
from .passes.state_select import check_alias_state_select, check_states
from .passes.units import check_units
from .passes.zero_terms import evaluate_zero_terms
from .structure.graph import gc_paused


class Laps:
    """``lap(stage)`` records into ``timings`` the seconds since the previous lap (or since
    it was made) under ``stage``."""

    __slots__ = ("timings", "last")

    def __init__(self, timings: dict[str, float]) -> None:
        self.timings, self.last = timings, _time.perf_counter()

    def __call__(self, stage: str) -> None:
        now = _time.perf_counter()
        self.timings[stage] = now - self.last
        self.last = now


@dataclass
class CompiledModel:
    """Everything the compiler produced, plus stage timings [s] in ``timings``."""

    name: str
    flat: FlatModel            # after alias elimination
    balance: BalanceReport
    reduced: ReducedModel
    sorted: SortedDAE
    dae: CasadiDAE
    n_flat_equations: int      # before alias elimination
    timings: dict[str, float] = field(default_factory=dict)
    source: Any = None         # the component it came from
    #: parameters replaced by their value because it removes a term (see
    #: :mod:`bgmodelica.passes.zero_terms`): name -> value; not tunable
    evaluated: dict[str, float] = field(default_factory=dict)

    @property
    def compile_time(self) -> float:
        return sum(self.timings.values())

    def __repr__(self) -> str:
        """One line: name, counts and compile time (the whole structure is in
        :meth:`summary` and, in a notebook, the rich view)."""
        return (f"CompiledModel({self.name}: {len(self.reduced.states)} states, "
                f"{len(self.sorted.algebraic)} algebraic, {len(self.dae.parameters)} "
                f"parameters, compiled in {self.compile_time:.2g} s)")

    def _repr_html_(self) -> str:
        """Jupyter view: structure and parameters (:func:`bgmodelica.notebook.compiled_html`)."""
        from .notebook import compiled_html

        return compiled_html(self)

    @property
    def declarations(self) -> Any:
        """The flat model simulation reads declarations, units and aliases from (the
        index-reduced one)."""
        return self.reduced.model

    @property
    def has_state_choice(self) -> bool:
        """Whether index reduction left a choice of states (dummy derivatives)."""
        return self.reduced.has_choice

    def needs_dynamic_selection(self) -> bool:
        """Whether simulation must be ready to change the states (their pivots vary)."""
        if not self.reduced.has_choice:
            return False
        from .dynamic_selection import StateSelector

        return StateSelector(self).needed()

    def summary(self) -> dict[str, Any]:
        """Counts and structure, as shown by ``bgmodelica check``."""
        red, srt = self.reduced, self.sorted
        var = red.model.variables
        loops = [b for b in srt.blocks if b.size > 1 or b.kind == "nonlinear"]
        return {
            "model": self.name,
            "equations": self.balance.n_equations,
            "unknowns": self.balance.n_unknowns,
            "balanced": self.balance.balanced,
            "flat_equations_before_alias_elimination": self.n_flat_equations,
            "aliases_eliminated": len(self.flat.aliases),
            "structural_index": red.index,
            "differentiated_equations": [red.model.describe(of)
                                         for _, of in red.differentiated],
            "states": [var[j].name for j in red.states],
            "dummy_derivatives": [var[j].name for j in red.dummies],
            "algebraic_variables": [var[j].name for j in srt.algebraic],
            "algebraic_loops": [{"size": b.size, "kind": b.kind, "tearing": b.tear,
                                 "variables": b.variables[:8]} for b in loops],
            "dynamic_state_selection": self.needs_dynamic_selection(),
            "parameters": len(self.dae.parameters),
            "inputs": [u.name for u in self.dae.inputs],
            "events": self.event_summary(),
            "compile_seconds": dict(self.timings),
        }

    def event_summary(self) -> dict[str, Any] | None:
        """Discrete variables, event conditions (state or time events), when-clauses, clocks
        and tables of a hybrid model; None for a smooth model."""
        hyb = self.dae.hybrid
        if hyb is None:
            return None
        from .events.functions import build

        fn = build(self.dae)
        kind = {k: "time event" for k in fn.time_rel} | {k: "state event"
                                                          for k in fn.state_rel}
        shown = [d for d in self.dae.discretes if not d.name.startswith(("$", "pre(", "initial()",
                                                                        "terminal()"))]
        discrete = [{"name": d.name, "type": getattr(d.decl, "type_name", "Real"),
                     "assigned": "when"} for d in shown]
        decls = {v.name: v.decl for v in self.reduced.model.variables}
        discrete += [{"name": n, "type": getattr(decls.get(n), "type_name", "Real"),
                      "assigned": "equation"}
                     for n in sorted(self.dae.discrete_names) if n not in {d.name for d in shown}]
        import casadi as ca

        clock_f = ca.Function("clocks", [self.dae.p], [ca.vertcat(
            *[ca.vertcat(c.start, c.interval) for c in hyb.samples])] if hyb.samples
            else [ca.SX(0, 1)])
        vals = [float(v) for v in ca.DM(clock_f(self.dae.p_default)).full().ravel()]
        return {
            "discrete_variables": discrete,
            "conditions": [{"relation": r.text, "kind": kind[k], "in": r.origin}
                           for k, r in enumerate(hyb.relations)],
            "when_clauses": [{"in": w.origin, "branches": [
                {"condition": b.text,
                 "assigns": [self.dae.discretes[s].name for s, _ in b.assignments],
                 "reinits": [n for n, _ in b.reinits]} for b in w.branches]}
                for w in hyb.whens],
            "clocks": [{"start": vals[2 * k], "interval": vals[2 * k + 1]}
                       for k in range(len(hyb.samples))],
            "tables": [{"breakpoints": len(t.times), "interpolation": t.interpolation,
                        "extrapolation": t.extrapolation} for t in hyb.tables],
        }


def compile(model: Component | str, *, select: Selector | None = None,  # noqa: A001
            units: str = "error", cache: bool | str | Path = False,
            array_path: bool = True) -> CompiledModel:
    """Compile a component tree into a :class:`CompiledModel`.

    units: dimensional analysis of every equation (:mod:`bgmodelica.passes.units`):
    ``"error"`` raises :class:`~bgmodelica.errors.UnitError` at a mismatch, ``"warn"`` warns,
    ``"off"`` skips it.

    cache: keep the compiled model on disk and load it the next time the same model (same
    structure and code; parameter values may differ) is compiled: True uses
    :func:`bgmodelica.cache.default_dir`, a path another folder (see :mod:`bgmodelica.cache`).
    ``timings`` then holds ``cache_load`` (a hit) or the stages and ``cache_store``, or the
    stages and ``cache_skipped`` (the seconds spent making the key) for a model whose entry
    was dropped because loading it cost more than compiling (see :mod:`bgmodelica.cache`).

    Large leaf models of array equations take the array path (:mod:`bgmodelica.array_path`):
    compiled without a Python object per scalar, into the same DAE, and not cached (the path
    costs less than a cache load). Their scalar structures (``flat``, ``reduced``...) are made
    when first read. ``array_path=False`` sends every model through the scalar pipeline.

    The cyclic garbage collector is paused meanwhile: compilation allocates millions of
    objects that live until the end, and rescanning them costs more than it frees.

    ``model`` may also be a MODEL reference as on the command line (``"library.examples:RC"``,
    ``"path/file.py:Name"``, ``"file.mo:Package.Model"``; see
    :func:`~bgmodelica.load_model`)."""
    if isinstance(model, str):
        from .loader import load_model

        model = load_model(model)
    try:
        if select is None and array_path:
            from .array_path import compile_arrays

            with gc_paused():
                fast = compile_arrays(model, units)
            if fast is not None:
                return fast
        if cache is False or cache is None or select is not None:
            with gc_paused():
                return _compile(model, select, units)
        return _compile_cached(model, units, cache)
    except ModelError as err:
        from .modelica.errors import locate_error

        locate_error(model, err)                  # a model read from Modelica: its class
        raise
    except (RecursionError, RuntimeError, KeyError, IndexError, TypeError, ValueError,
            AttributeError, ZeroDivisionError) as err:
        from .modelica.errors import compile_failure

        located = compile_failure(model, err)    # a model read from Modelica: one line
        if located is None:
            raise
        raise located from None


def _compile_cached(model: Component, units: str, cache: bool | str | Path) -> CompiledModel:
    from . import cache as disk

    if not isinstance(model, Component):
        raise DeclarationError(
            f"compile() expects a Component instance, got {type(model).__name__}")
    folder = disk.default_dir() if cache is True else Path(cache)
    t0 = _time.perf_counter()
    with gc_paused():
        order = disk.walk(model)
        try:
            key = disk.model_key(model, order) + f"-{units}"
        except disk.Uncacheable:
            key = None
    skip = key is not None and disk.skipped(folder, key)
    if key is not None and not skip:
        with gc_paused():
            hit = disk.load(folder, key, model, order)
        if hit is not None:
            built = sum(v for k, v in hit.timings.items() if k != "cache_store")
            hit.timings = {"cache_load": _time.perf_counter() - t0}
            if not disk.pays(built, hit.timings["cache_load"]):
                disk.drop(folder, key, built, hit.timings["cache_load"])
            return hit
    keyed = _time.perf_counter()
    with gc_paused():
        compiled = _compile(model, None, units)
    if skip:
        compiled.timings["cache_skipped"] = keyed - t0
    elif key is not None:
        t1 = _time.perf_counter()
        with gc_paused():
            disk.store(compiled, folder, key)
        compiled.timings["cache_store"] = _time.perf_counter() - t1
    return compiled


def _compile(model: Component, select: Selector | None, units: str = "error",
             zero_terms: bool | None = None) -> CompiledModel:
    if not isinstance(model, Component):
        raise DeclarationError(
            f"compile() expects a Component instance, got {type(model).__name__}")
    timings: dict[str, float] = {}
    lap = Laps(timings)
    flat = flatten(model)
    n_flat = len(flat.equations)
    lap("flatten")
    check_units(flat, units)
    flat.sources = None
    lap("units")
    check_references(flat)             # a floating network (no ground) named, not its symptom
    check_alias_state_select(flat)
    raw = flat
    flat = eliminate_aliases(flat)
    lap("alias")
    if zero_terms is None:   # Modelica models: zero parameters are evaluated, as tools do
        zero_terms = model.__dict__.get("_mo_source") is not None
    flat, evaluated = evaluate_zero_terms(flat) if zero_terms else (flat, {})
    flat.asserts = raw.asserts
    lap("zero_terms")
    try:
        balance = check_balance(flat)
        lap("balance")
        return _reduce_and_build(flat, balance, n_flat, timings, model, select, evaluated)
    except UnbalancedModelError:
        check_references(raw, force=True)  # large models: the likely cause, if it is that
        raise


def recompile(compiled: CompiledModel, select: Selector) -> CompiledModel:
    """The same model with another state selection (index reduction onwards)."""
    return _reduce_and_build(compiled.flat, compiled.balance, compiled.n_flat_equations, {},
                             compiled.source, select, compiled.evaluated)


def _reduce_and_build(flat: FlatModel, balance: BalanceReport, n_flat: int,
                      timings: dict[str, float], source: Any,
                      select: Selector | None,
                      evaluated: dict[str, float] | None = None) -> CompiledModel:
    lap = Laps(timings)
    reduced = reduce_index(flat, select=select)
    if select is None:
        check_states(reduced)
    lap("index_reduction")
    sorted_dae = sort_equations(reduced)
    lap("sorting")
    dae = build_dae(sorted_dae)
    attach_initial_equations(dae, flat)
    dae.evaluated = dict(evaluated or {})
    lap("backend")
    return CompiledModel(flat.name, flat, balance, reduced, sorted_dae, dae, n_flat, timings,
                         source, dict(evaluated or {}))
