"""BLT sorting and tearing of an index-1 system into explicit assignments and residuals.

Given the states as known, every other variable (state derivatives, algebraic variables, dummy
derivatives) is an unknown. The equations are matched to unknowns, sorted into strongly
connected blocks (Tarjan), and each block is made explicit where possible:

- a scalar equation linear in its unknown becomes an assignment;
- a loop is torn; if the torn residuals are linear in the tearing variables they are solved
  symbolically, so the loop disappears from the simulated system. Inside a loop, no equation
  is solved for a variable whose coefficient vanishes in some branch of a piecewise
  expression (``x = if s > 1 then s - 1 else 0`` does not determine ``s`` in its second
  branch); such a variable is torn instead;
- otherwise the tearing variables stay algebraic unknowns (IDAS ``z``) with their residuals.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from ..core.flatmodel import Picked, take
from ..diagnose import singular_linear_block
from ..errors import EquationError, UnbalancedModelError
from ..structure import block_lower_triangular, compiled, maximum_matching, tear
from ..structure.compiled import remap_rows
from .index_reduction import ReducedModel
from .symbolic import (
    LONG_ROW,
    fails_in_branch,
    solve_linear_block,
    solve_linear_scalar,
    solve_scalar_blocks,
)


@dataclass
class BlockInfo:
    """One BLT block, for reports: its size, tearing variables and how it was solved."""

    size: int
    kind: str          # "explicit", "linear", "nonlinear"
    variables: list[str]
    tear: list[str] = field(default_factory=list)


@dataclass
class SortedDAE:
    """The causalized index-1 system.

    assignments: ``(variable index, expression)`` in evaluation order; an expression uses
    knowns (states, algebraic ``z``, parameters, inputs, time) and earlier assignments only.
    algebraic: variable indices kept as algebraic unknowns; ``residuals`` determine them.
    """

    reduced: ReducedModel
    assignments: list[tuple[int, ca.SX]]
    algebraic: list[int]
    residuals: list[ca.SX]
    blocks: list[BlockInfo]          # loops and nonlinear scalar blocks
    n_explicit: int = 0              # scalar blocks solved explicitly
    #: the explicit solutions as one column, and each assignment's position in it (-1: the
    #: expression is in ``assignments`` only); see :meth:`stacked_definitions`
    solution_column: ca.SX | None = field(default=None, repr=False)
    positions: list[int] = field(default_factory=list, repr=False)

    def __repr__(self) -> str:
        return (f"SortedDAE({self.model.name}: {len(self.assignments)} assignments, "
                f"{len(self.algebraic)} algebraic, {len(self.blocks)} blocks (loops or "
                "nonlinear))")

    def stacked_definitions(self) -> ca.SX:
        """The assignments' expressions as one column, in evaluation order (taken from the
        vectors they were solved in, instead of stacking a scalar per assignment)."""
        if self.solution_column is None or len(self.positions) != len(self.assignments):
            return ca.vertcat(*[d for _, d in self.assignments]) if self.assignments \
                else ca.SX(0, 1)
        loose = [k for k, p in enumerate(self.positions) if p < 0]
        base = self.solution_column.numel()
        pool = ca.vertcat(self.solution_column, *[self.assignments[k][1] for k in loose])
        pos = list(self.positions)
        for i, k in enumerate(loose):
            pos[k] = base + i
        return take(pool, pos)

    @property
    def model(self):
        return self.reduced.model

    @property
    def states(self) -> list[int]:
        return self.reduced.states


def sort_equations(reduced: ReducedModel) -> SortedDAE:
    """BLT-sort and tear ``reduced``; raise if it is structurally singular."""
    model = reduced.model
    variables = model.variables
    states = set(reduced.states)
    unknowns = [j for j in range(len(variables)) if j not in states]
    if len(unknowns) >= compiled.LARGE:        # in numpy (rows come out ascending)
        column = np.full(len(variables), -1, dtype=np.int64)
        column[unknowns] = np.arange(len(unknowns))
        eq_cols = remap_rows(reduced.graph.eq_vars, column)
    else:
        where = {j: k for k, j in enumerate(unknowns)}
        eq_cols = [[where[j] for j in row if j in where] for row in reduced.graph.eq_vars]
    if len(eq_cols) != len(unknowns):
        raise UnbalancedModelError(
            f"after index reduction {model.name} has {len(eq_cols)} equations for "
            f"{len(unknowns)} unknowns")
    matching = maximum_matching(eq_cols, len(unknowns))
    if matching.size != len(unknowns):
        names = model.names()
        bad_vars = [variables[unknowns[c]].origin for c in range(len(unknowns))
                    if matching.var_to_eq[c] < 0]
        bad_eqs = [model.equations[i].describe(names) for i in range(len(eq_cols))
                   if matching.eq_to_var[i] < 0]
        raise UnbalancedModelError(
            f"{model.name} is structurally singular once the states are known:\n"
            + "\n".join(f"  undetermined: {v}" for v in bad_vars[:12])
            + "\n" + "\n".join(f"  surplus: {e}" for e in bad_eqs[:12]),
            missing=bad_vars, surplus=bad_eqs)

    res = Picked(model.equations, "residual")
    sym = Picked(variables, "sx", unknowns)
    out = SortedDAE(reduced, [], [], [], [])
    blocks = block_lower_triangular(eq_cols, len(unknowns), matching)
    scalar = [b for b in blocks if len(b.eqs) == 1]
    scalar_eqs = [b.eqs[0] for b in scalar]
    block_of_col = np.full(len(unknowns), -1, dtype=np.int64)  # unknown -> its scalar block
    block_of_col[[b.vars[0] for b in scalar]] = np.arange(len(scalar))
    solved, out.solution_column, position = solve_scalar_blocks(
        Picked(model.equations, "residual", scalar_eqs),
        Picked(variables, "sx", [unknowns[b.vars[0]] for b in scalar]),
        {k for k, e in enumerate(scalar_eqs) if model.equations[e].terms > LONG_ROW},
        take(model.stacked_residuals(), scalar_eqs),
        take(model.stacked_variables(), [unknowns[b.vars[0]] for b in scalar]),
        remap_rows([eq_cols[e] for e in scalar_eqs], block_of_col) if scalar else [])
    has_discrete = any(v.decl.kind == "discrete" for v in variables)
    assignments, positions = out.assignments, out.positions
    if not has_discrete and len(scalar) == len(blocks) and -1 not in position:
        # every block an explicit assignment (most large models): no per-block dispatch
        var_of_col = np.asarray(unknowns, dtype=np.int64)
        assignments.extend(zip(var_of_col[[b.vars[0] for b in scalar]].tolist(), solved,
                               strict=True))
        positions.extend(position)
        out.n_explicit = len(scalar)
        return out
    var_hashes: set[int] = set()
    discrete: frozenset[int] = frozenset()
    k = -1                                      # position of the block among the scalar ones
    for block in blocks:
        eqs, cols = block.eqs, block.vars
        if has_discrete:
            _check_discrete_loop(model, list(eqs), [unknowns[c] for c in cols], res)
        if len(eqs) == 1:
            k += 1
            expr = solved[k]
            if expr is not None:
                assignments.append((unknowns[cols[0]], expr))
                positions.append(position[k])
                out.n_explicit += 1
                continue
            names = [variables[unknowns[cols[0]]].name]
            out.algebraic.append(unknowns[cols[0]])
            out.residuals.append(res[eqs[0]])
            out.blocks.append(BlockInfo(1, "nonlinear", names, names))
            continue
        if not var_hashes:
            var_hashes.update(v.sx.element_hash() for v in variables)
            discrete = _discrete_hashes(model)
        names = [variables[unknowns[c]].name for c in cols]
        _loop(out, list(eqs), list(cols), eq_cols, res, sym, unknowns, names, variables,
              var_hashes, discrete)
    return out


def _check_discrete_loop(model, eqs: list[int], var_idx: list[int], res: list) -> None:
    """A discrete variable may not be determined through a loop of equations (Modelica's
    single-assignment rule for discrete-time equations): such a loop has no ordering; it
    needs pre() on one of the variables to become an event iteration."""
    variables = model.variables
    discrete = [j for j in var_idx if variables[j].decl.kind == "discrete"]
    if not discrete:
        return
    if len(eqs) == 1 and not _switches_on(res[eqs[0]], variables[var_idx[0]].sx):
        return
    names = ", ".join(variables[j].origin for j in var_idx[:8])
    eq_text = "; ".join(model.describe(e) for e in eqs[:4])
    raise EquationError(
        f"algebraic loop through the discrete variable(s) {names}: {eq_text}. Discrete "
        "equations must not depend on themselves; use pre() of one of them to read the value "
        "before the event")


_SWITCHING_OPS = tuple(getattr(ca, n) for n in (
    "OP_NOT", "OP_AND", "OP_OR", "OP_EQ", "OP_NE", "OP_LT", "OP_LE", "OP_IF_ELSE_ZERO",
    "OP_FLOOR", "OP_CEIL", "OP_SIGN") if hasattr(ca, n))


def _switches_on(e: ca.SX, var: ca.SX) -> bool:
    """Whether ``e`` reads ``var`` through a logical or piecewise-constant operation (a
    dependence that solving for ``var`` cannot remove)."""
    seen: set[int] = set()
    stack = [e]
    while stack:
        node = stack.pop()
        h = node.element_hash()
        if h in seen or node.is_leaf():
            continue
        seen.add(h)
        if any(node.is_op(op) for op in _SWITCHING_OPS) and ca.depends_on(node, var):
            return True
        stack.extend(node.dep(i) for i in range(node.n_dep()))
    return False


def _discrete_hashes(model) -> frozenset[int]:
    """Element hashes of the discrete symbols of ``model`` (discrete variables and the
    hidden slots: pre() values, relation values, ...)."""
    return frozenset([v.sx.element_hash() for v in model.variables if v.decl.kind == "discrete"]
                     + [d.sx.element_hash() for d in model.discretes])


def _dependent(model, eqs: list[int], names: list[str]) -> UnbalancedModelError:
    """A linear block whose equations are linearly dependent for every parameter value."""
    shown = "; ".join(model.describe(e) for e in eqs[:4]) + ("; ..." if len(eqs) > 4 else "")
    return UnbalancedModelError(
        f"{model.name} is singular: the equations {shown} cannot determine "
        f"{', '.join(names[:8])} (they are linearly dependent for every parameter value); "
        "likely cause: ideal sources or storage elements that constrain each other (voltage "
        "sources or capacitors in a loop, current sources or inductors in a cut)",
        missing=list(names), surplus=[model.describe(e) for e in eqs])


def _loop(out: SortedDAE, eqs, cols, eq_cols, res, sym, unknowns, names, variables,
          var_hashes: set[int], discrete: frozenset[int]) -> None:
    cache: dict[tuple[int, int], ca.SX | None] = {}

    def solved(e: int, c: int) -> ca.SX | None:
        if (e, c) not in cache:
            cache[(e, c)] = solve_linear_scalar(res[e], sym[c], var_hashes, discrete)
        return cache[(e, c)]

    torn = tear(eqs, cols, eq_cols, lambda e, c: solved(e, c) is not None)
    tear_cols = list(torn.tear_vars)
    tear_names = [variables[unknowns[c]].name for c in tear_cols]
    causal = [(c, solved(e, c)) for e, c in torn.causal]
    # residuals in terms of the tearing variables only
    inner_sym = [sym[c] for c, _ in causal]
    inner_def = [d for _, d in causal]
    resid = [res[e] for e in torn.residual_eqs]
    if inner_sym:
        _, (resid_sub,) = ca.substitute_inplace([ca.vertcat(*inner_sym)],
                                                [ca.vertcat(*inner_def)],
                                                [ca.vertcat(*resid)], False)
        resid = [resid_sub[k] for k in range(resid_sub.numel())]
    solution = solve_linear_block(resid, [sym[c] for c in tear_cols]) if tear_cols else None
    if solution is not None and discrete and fails_in_branch(
            resid, [sym[c] for c in tear_cols], solution, discrete):
        solution = None                     # solved numerically instead
    if solution is not None and singular_linear_block(resid, [sym[c] for c in tear_cols],
                                                      discrete=discrete):
        raise _dependent(out.reduced.model, eqs, names)
    if solution is not None or not tear_cols:
        for k, c in enumerate(tear_cols):
            out.assignments.append((unknowns[c], solution[k]))
        out.blocks.append(BlockInfo(len(eqs), "linear", names, tear_names))
    else:
        out.algebraic.extend(unknowns[c] for c in tear_cols)
        out.residuals.extend(res[e] for e in torn.residual_eqs)
        out.blocks.append(BlockInfo(len(eqs), "nonlinear", names, tear_names))
    out.assignments.extend((unknowns[c], d) for c, d in causal)
    out.positions.extend([-1] * (len(out.assignments) - len(out.positions)))
