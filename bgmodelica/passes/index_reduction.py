"""Index reduction: Pantelides on the integer graph, symbolic differentiation of the equations
it selects, then dummy derivatives (Mattsson-Söderlind) honouring ``state_select``.

The result is an index-1 system: the augmented flat model plus the chosen states (integrated
variables) and dummy derivatives (derivatives demoted to algebraic unknowns).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import casadi as ca

from ..core.flatmodel import FlatEquation, FlatModel, FlatVariable
from ..core.variables import TIME, Variable, derivative_unit
from ..errors import EquationError, StateSelectError, UnbalancedModelError
from ..structure import EquationGraph, dummy_derivatives, pantelides
from ..structure.errors import StateSelectionError, StructuralError, StructurallySingular
from .symbolic import incidence, long_rows, model_incidence, time_derivative

Selector = Callable[[int, list[int], list[int], list[int]], list[int]]


@dataclass
class ReducedModel:
    """An index-1 view of a flat model.

    model: the flat model augmented with differentiated equations and derivative variables.
    states: indices of the integrated variables; ``dummies``: derivatives made algebraic.
    differentiated: ``(new equation, equation it differentiates)`` in creation order.
    index: structural differential index of the original model.
    has_choice: whether the state selection could have to change during a simulation.
    """

    model: FlatModel
    graph: EquationGraph
    states: list[int]
    dummies: list[int]
    differentiated: list[tuple[int, int]]
    index: int
    has_choice: bool
    levels: list
    priority: list[int]

    def __repr__(self) -> str:
        return (f"ReducedModel({self.model.name}: index {self.index}, {len(self.states)} "
                f"states, {len(self.dummies)} dummy derivatives, "
                f"{len(self.differentiated)} differentiated equations)")


def reduce_index(model: FlatModel | ReducedModel,
                 select: Selector | None = None) -> ReducedModel:
    """Return the index-1 :class:`ReducedModel` of a balanced flat model.

    Given a :class:`ReducedModel` (whose differentiated equations are already present) it
    differentiates nothing more: reduction is idempotent.

    A variable that declares ``StateSelect.prefer`` (or ``always``) but appears only as a
    derivative in disguise (``v_rel = der(s_rel)``, the relative speed of the MSL's springs
    and dampers) is no state candidate on its own: no equation holds ``der(v_rel)``. As
    Modelica tools do, the reduction is then tried again with ``der(v_rel)`` made available
    (the equations that need it are differentiated); that selection is kept when it makes
    such a variable a state, in place of one of lower priority. It matters beyond accuracy:
    a ``reinit`` of a state keeps the other states, so which ones they are is semantics.
    """
    if isinstance(model, ReducedModel):
        return _reduce(model.model, list(model.graph.eq_derivative), select)
    plain = _reduce(model, [], select)
    wanted = [v for v in preferred_derivative_aliases(model) if v not in plain.states]
    if not wanted:
        return plain
    try:
        augmented = _reduce(_with_derivatives(model, wanted), [], select)
    except (UnbalancedModelError, EquationError, StateSelectError):
        return plain
    return augmented if any(v in augmented.states for v in wanted) else plain


def preferred_derivative_aliases(model: FlatModel) -> list[int]:
    """Variables declaring ``StateSelect.prefer`` or ``always`` that are not differentiated
    and are set equal to a derivative by an equation of two unknowns (``v = der(s)``)."""
    variables = model.variables
    out = []
    for row in model_incidence(model):
        if len(row) != 2:
            continue
        a, b = row
        for v, d in ((a, b), (b, a)):
            var = variables[v]
            if var.der < 0 and var.der_of < 0 and variables[d].der_of >= 0 \
                    and int(getattr(var.decl, "state_select", 0)) >= 1 and v not in out:
                out.append(v)
    return out


def _with_derivatives(model: FlatModel, wanted: list[int]) -> FlatModel:
    """``model`` with a derivative variable added for each of ``wanted``."""
    variables = list(model.variables)
    for v in wanted:
        var = variables[v]
        variables[v] = replace(var, der=len(variables))
        name = f"der({var.name})"
        variables.append(FlatVariable(name, ca.SX.sym(name), Variable(
            unit=derivative_unit(var.decl.unit), nominal=getattr(var.decl, "nominal", 1.0)),
            var.component, der_of=v))
    out = FlatModel(model.name, variables, model.parameters, model.inputs, model.equations,
                    model.aliases, model.discretes, model.hybrid)
    out.initial_equations = model.initial_equations
    out.asserts = model.asserts
    return out


def _reduce(model: FlatModel, links: list[int], select: Selector | None) -> ReducedModel:
    eq_vars = [list(row) for row in model_incidence(model)]
    graph = EquationGraph(eq_vars, len(model.variables), [v.der for v in model.variables],
                          links)
    try:
        pant = pantelides(graph)
    except StructurallySingular as err:
        raise _singular(model, err) from None
    except StructuralError as err:
        raise UnbalancedModelError(f"index reduction of {model.name} failed: {err}") from None

    variables = list(model.variables)
    equations = list(model.equations)
    for new, of in pant.new_variables:
        assert new == len(variables), "derivative variables must be appended in order"
        v = variables[of]
        variables[of] = replace(v, der=new)
        name = f"der({v.name})"
        variables.append(FlatVariable(name, ca.SX.sym(name), Variable(
            unit=derivative_unit(v.decl.unit), nominal=getattr(v.decl, "nominal", 1.0)),
            v.component, der_of=of))
    rows = list(eq_vars)
    for new, of in pant.new_equations:
        assert new == len(equations), "differentiated equations must be appended in order"
        src = equations[of]
        vs = rows[of]
        missing = [variables[j].name for j in vs if variables[j].der < 0]
        if missing:
            raise EquationError(f"index reduction must differentiate {src.origin} but "
                                f"{', '.join(missing)} has no derivative")
        _check_inputs(model, src)
        res = time_derivative(src.residual, [variables[j].sx for j in vs],
                              [variables[variables[j].der].sx for j in vs], TIME.sx)
        equations.append(FlatEquation(res, f"d/dt of {src.origin}", terms=src.terms))
        rows.append(sorted(set(vs) | {variables[j].der for j in vs}))   # superset for now
    n_old = len(eq_vars)
    if len(equations) > n_old:                 # exact incidence of all new equations at once
        rows[n_old:] = incidence([e.residual for e in equations[n_old:]],
                                 [v.sx for v in variables],
                                 long_rows(equations[n_old:]))
    aug = FlatModel(model.name, variables, model.parameters, model.inputs, equations,
                    model.aliases, model.discretes, model.hybrid)
    aug.remember_stacked(      # the old columns, extended by what was added
        ca.vertcat(model.stacked_residuals(), *[e.residual for e in equations[n_old:]]),
        ca.vertcat(model.stacked_variables(),
                   *[v.sx for v in variables[len(model.variables):]]), like=model)
    eq_derivative = (links + [-1] * (len(equations) - len(links))) if links \
        else [-1] * len(equations)
    for new, of in pant.new_equations:
        eq_derivative[of] = new
    exact = EquationGraph(rows, len(variables), [v.der for v in variables], eq_derivative)
    base = exact.base_vars()
    declared = [int(getattr(v.decl, "state_select", 0)) for v in variables]
    priority = [declared[b] for b in base]
    try:
        dd = dummy_derivatives(exact, priority, select=select)
    except StateSelectionError as err:
        if select is not None or "cannot all be states" not in str(err):
            raise UnbalancedModelError(f"state selection for {model.name} failed: {err}") \
                from None
        names = ", ".join(variables[j].origin for j in err.variables if j < len(variables))
        raise StateSelectError(
            f"{names} have StateSelect.ALWAYS but cannot all be states: equations of "
            f"{model.name} constrain them (fewer states are possible); remove "
            "StateSelect.ALWAYS from some of them") from None
    except StructuralError as err:
        raise UnbalancedModelError(f"state selection for {model.name} failed: {err}") from None
    return ReducedModel(aug, exact, list(dd.states), list(dd.dummies),
                        list(pant.new_equations), _index(pant), dd.has_choice, dd.levels,
                        priority)


def _index(pant) -> int:
    return int(getattr(pant, "index", getattr(pant, "max_equation_differentiations", 0)))


def _check_inputs(model: FlatModel, src: FlatEquation) -> None:
    """Differentiating an equation that reads an input would need the input's derivative."""
    for u in model.inputs:
        if ca.depends_on(src.residual, u.sx):
            raise EquationError(
                f"index reduction must differentiate an equation of {src.origin} that reads "
                f"the model input {u.name}; its time derivative is unknown. Drive it through a "
                "smooth source (e.g. a block computing it) or reformulate the coupling")


def _singular(model: FlatModel, err: StructurallySingular) -> UnbalancedModelError:
    names = model.names()
    over = [model.equations[i].describe(names) for i in err.overdetermined_eqs
            if i < len(model.equations)]
    under = [model.variables[j].origin for j in err.underdetermined_vars
             if j < len(model.variables)]
    lines = [f"model {model.name} is structurally singular"]
    if under:
        lines.append("under-determined variables:")
        lines += [f"  {u}" for u in under[:12]]
    if over:
        lines.append("over-determined equations:")
        lines += [f"  {o}" for o in over[:12]]
    return UnbalancedModelError("\n".join(lines), missing=under, surplus=over)
