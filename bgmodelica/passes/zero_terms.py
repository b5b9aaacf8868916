"""Parameters whose value removes a term: ``J*a = tau`` with ``J = 0`` is ``0 = tau``.

A Modelica tool evaluates such a parameter: the structural analysis then sees that the
equation no longer involves ``a`` and matches, reduces and sorts the system accordingly
(otherwise the sorted equations divide by ``J``). This pass does the same for the parameters
of value 0 that remove a variable from an equation: they are replaced by their value in
every equation and become bound to it (no longer tunable; the compiled model lists them in
``evaluated``). Every other parameter, zero or not, stays tunable.

Zeros propagate: an equation left as ``c = 0`` (``Capcjc = Cjc*powlin(v)`` with ``Cjc = 0``)
makes ``c`` a zero too, replaced by 0 in the equations where that removes another variable
(``C.i = ... - c*der(v)`` no longer holds ``der(v)``); ``c`` keeps its own equation.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import casadi as ca
import numpy as np

from ..core.flatmodel import FlatEquation, FlatModel, FlatVariable
from .symbolic import incidence, model_incidence


def evaluate_zero_terms(model: FlatModel) -> tuple[FlatModel, dict[str, float]]:
    """The model with the parameters that remove a term replaced by their value (and zero
    variables substituted where they remove one), and those parameters' names and values
    (the model itself and {} when there are none)."""
    zero_params = [p for p, v in zip(model.parameters, parameter_defaults(model), strict=True)
                   if v == 0.0]
    if zero_params and model.initial_equations:     # their value may be found there
        held = ca.vertcat(*[eq.residual for eq in model.initial_equations])
        zero_params = [p for p in zero_params if not ca.depends_on(held, p.sx)]
    if not zero_params or not model.equations:
        return model, {}
    state = _Zeros(model, zero_params)
    state.run()
    if not state.evaluated:
        return model, {}
    return _substituted(model, state), {p.name: 0.0 for p in state.evaluated.values()}


def parameter_defaults(model: FlatModel) -> list[float]:
    """Each parameter's default value, bindings to other parameters evaluated (NaN for one
    bound to something else)."""
    params = model.parameters
    if not params:
        return []
    syms = ca.vertcat(*[p.sx for p in params])
    values = ca.vertcat(*[ca.SX(p.decl.value) if isinstance(p.decl.value, ca.SX)
                          else ca.SX(_number(p.decl.value)) for p in params])
    for _ in range(len(params)):                   # bindings may chain
        if not ca.depends_on(values, syms):
            break
        values = ca.substitute(values, syms, values)
    return [float(values[k]) if values[k].is_constant() else float("nan")
            for k in range(values.numel())]


def _number(value: object) -> float:
    try:
        return float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return float("nan")


class _Zeros:
    """The worklist: equations holding a zero (a parameter of value 0, or a variable an
    equation sets to 0) are rewritten where that removes a variable."""

    def __init__(self, model: FlatModel, zero_params: list[FlatVariable]) -> None:
        self.model = model
        self.rows = model_incidence(model)
        column = model.stacked_variables()
        self.symbols = [column[j] for j in range(column.numel())]
        self.params = {p.sx.element_hash(): p for p in zero_params}
        self.evaluated: dict[int, FlatVariable] = {}    # hash -> parameter
        self.zero_vars: dict[int, int] = {}             # variable index -> its equation
        self.residuals: dict[int, ca.SX] = {}           # rewritten equations
        self.users = _users(self.rows, len(self.symbols))

    def run(self) -> None:
        todo = self._holding_params(list(self.params.values()))
        while todo:
            k = todo.pop()
            new_params, new_var = self._rewrite(k)
            if new_params:
                todo |= self._holding_params(new_params)
            if new_var is not None:
                todo |= {i for i in self.users[new_var] if i != k}

    def _holding_params(self, params: list[FlatVariable]) -> set[int]:
        """Equations (not long sums) whose residual holds one of ``params``."""
        syms = ca.vertcat(*[p.sx for p in params])
        rows = ca.jacobian_sparsity(self.model.stacked_residuals(), syms).get_triplet()[0]
        return {k for k in set(rows) if not self.model.equations[k].terms}

    def _residual(self, k: int) -> ca.SX:
        return self.residuals.get(k, self.model.equations[k].residual)

    def _rewrite(self, k: int) -> tuple[list[FlatVariable], int | None]:
        """Rewrite equation ``k`` if its zeros remove a variable; returns the parameters
        newly evaluated and the variable it newly sets to zero (or None)."""
        res = self._residual(k)
        zeros = [s for s in ca.symvar(res) if s.element_hash() in self.params]
        zeros += [self.symbols[j] for j in self.rows[k]
                  if j in self.zero_vars and self.zero_vars[j] != k]
        if not zeros:
            return [], None
        before = self._vars(res)
        full = _put_zero(res, zeros)
        if not _finite(full):                     # a zero divides: the model's error
            return [], None
        after = self._vars(full)
        sets_zero = len(before) > 1 and self._zero_variable(full) is not None
        if not after or not (before - after - set(self.zero_vars) or sets_zero):
            return [], None
        keep = after | set(self.zero_vars)

        def ok(subset: list[ca.SX]) -> bool:
            new = _put_zero(res, subset)
            return self._vars(new) <= keep and (not sets_zero
                                                or self._zero_variable(new) is not None)
        chosen = _fewest(zeros, ok)
        new = _put_zero(res, chosen)
        self.residuals[k] = new
        fresh = [self.params[s.element_hash()] for s in chosen
                 if s.element_hash() in self.params
                 and s.element_hash() not in self.evaluated]
        self.evaluated.update((p.sx.element_hash(), p) for p in fresh)
        var = self._zero_variable(new)
        if var is not None and var not in self.zero_vars:
            self.zero_vars[var] = k
            return fresh, var
        return fresh, None

    def _vars(self, res: ca.SX) -> set[int]:
        return set(incidence([res], self.symbols)[0])

    def _zero_variable(self, res: ca.SX) -> int | None:
        """The variable ``res = 0`` sets to zero, if it is one variable with a constant,
        nonzero coefficient and nothing else."""
        found = self._vars(res)
        if len(found) != 1:
            return None
        j = next(iter(found))
        sym = self.symbols[j]
        slope = ca.jacobian(res, sym)
        rest = ca.substitute(res, sym, ca.SX(0))
        if not (slope.is_constant() and float(slope) != 0.0 and rest.is_zero()):
            return None
        return j


def _finite(res: ca.SX) -> bool:
    """Whether ``res`` is finite at a point of its symbols in [0.5, 1.5] (a zero put into a
    denominator leaves an infinite constant)."""
    syms = ca.symvar(res)
    if not syms:
        return bool(np.isfinite(float(ca.evalf(res))))
    point = np.random.default_rng(0).uniform(0.5, 1.5, len(syms))
    with np.errstate(all="ignore"):
        value = float(ca.Function("zero_terms_check", [ca.vertcat(*syms)], [res])(point))
    return bool(np.isfinite(value))


def _users(rows: list[list[int]], n_vars: int) -> list[list[int]]:
    """For each variable, the equations it appears in."""
    out: list[list[int]] = [[] for _ in range(n_vars)]
    for k, row in enumerate(rows):
        for j in row:
            out[j].append(k)
    return out


def _put_zero(res: ca.SX, syms: list[ca.SX]) -> ca.SX:
    return ca.substitute(res, ca.vertcat(*syms), ca.SX.zeros(len(syms))) if syms else res


def _fewest(zeros: list[ca.SX], ok: Callable[[list[ca.SX]], bool]) -> list[ca.SX]:
    """A small subset of ``zeros`` for which ``ok`` holds (it holds for all): dropping
    each one that ``ok`` does without keeps the others tunable."""
    needed = list(zeros)
    for s in zeros:
        rest = [q for q in needed if q is not s]
        if rest and ok(rest):
            needed = rest
    return needed


def _substituted(model: FlatModel, state: _Zeros) -> FlatModel:
    """``model`` with the rewritten equations, the evaluated parameters replaced by 0
    everywhere and bound to 0."""
    params = list(state.evaluated.values())
    psyms = ca.vertcat(*[p.sx for p in params])
    zero = ca.SX.zeros(len(params))
    equations = [_equation(eq, state.residuals.get(k), psyms, zero)
                 for k, eq in enumerate(model.equations)]
    initial = [_equation(eq, None, psyms, zero) for eq in model.initial_equations]
    evaluated = {id(p) for p in params}
    parameters = [replace(p, decl=p.decl.evolve(value=ca.SX(0.0))) if id(p) in evaluated
                  else p for p in model.parameters]
    out = replace(model, equations=equations, parameters=parameters)
    out.initial_equations = initial
    return _without_unused_derivatives(out)


def _without_unused_derivatives(model: FlatModel) -> FlatModel:
    """``model`` without the derivative variables no equation holds any more (``C*der(v)``
    with ``C = 0``): ``v`` is then no state candidate."""
    used = {j for row in model_incidence(model) for j in row}
    extra = [eq.residual for eq in model.initial_equations]
    extra += model.hybrid.expressions() if model.hybrid is not None else []
    held = ca.vertcat(*extra) if extra else None
    variables = model.variables
    dropped: set[int] = set()
    for j, v in enumerate(variables):
        while v.der_of >= 0 and v.der < 0 and j not in used and j not in dropped \
                and (held is None or not ca.depends_on(held, v.sx)):
            dropped.add(j)
            j, v = v.der_of, variables[v.der_of]      # der(der(x)) gone: der(x) may go
            v = replace(v, der=-1)
            if j in used or j in dropped or v.der_of < 0:
                break
    if not dropped:
        return model
    keep = [j for j in range(len(variables)) if j not in dropped]
    new_index = {j: n for n, j in enumerate(keep)}
    kept = []
    for j in keep:
        v = variables[j]
        der = new_index.get(v.der, -1) if v.der >= 0 else -1
        der_of = new_index[v.der_of] if v.der_of >= 0 else -1
        kept.append(v if (der, der_of) == (v.der, v.der_of) else v.relinked(der_of, der))
    out = replace(model, variables=kept)
    out.initial_equations = model.initial_equations
    return out


def _equation(eq: FlatEquation, rewritten: ca.SX | None, psyms: ca.SX,
              zero: ca.SX) -> FlatEquation:
    res = eq.residual if rewritten is None else rewritten
    if eq.terms or not ca.depends_on(res, psyms):
        return eq if rewritten is None else replace(eq, _residual=res, at=None)
    return replace(eq, _residual=ca.substitute(res, psyms, zero), at=None)

