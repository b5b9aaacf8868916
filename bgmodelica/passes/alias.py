"""Signed alias elimination: remove ``a = b``, ``a = -b``, ``a + b = 0`` and their variables."""

from __future__ import annotations

from dataclasses import replace

import casadi as ca
import numpy as np

from ..core.flatmodel import FlatEquation, FlatModel, FlatVariable, take
from ..core.variables import Variable, derivative_unit
from ..errors import InitializationError
from ..structure.alias import alias_classes


def eliminate_aliases(model: FlatModel) -> FlatModel:
    """Return a model without alias equations; ``aliases`` records every removed variable."""
    variables = model.variables
    links, link_eqs = [], []
    for k, eq in enumerate(model.equations):
        if eq.alias is not None:
            links.append(eq.alias)
            link_eqs.append(k)
    if not links:
        return model

    classes = alias_classes(len(variables), links, _ranks(variables, links))
    used = set(link_eqs) - {link_eqs[k] for k in classes.redundant}

    new_vars = list(variables)
    rep_of = np.asarray(classes.rep)
    members = np.flatnonzero(rep_of != np.arange(len(rep_of))).tolist()   # not representatives
    _merge_metadata(new_vars, classes.rep, classes.sign, members)
    old: list[int] = []              # indices in new_vars (which extends variables)
    new_rep: list[int] = []
    new_sign: list[float] = []
    eliminated: set[int] = set()
    aliases = dict(model.aliases)
    if not any(variables[i].der >= 0 for i in members):      # no derivative chains
        old = members
        new_rep = rep_of[members].tolist()
        new_sign = [classes.sign[i] for i in members]
        eliminated = set(members)
        aliases.update(zip([variables[i].name for i in members],
                           zip([variables[r].name for r in new_rep], new_sign, strict=True),
                           strict=True))
        members = []
    for i in members:
        v = variables[i]
        r = classes.rep[i]
        s = classes.sign[i]
        old.append(i)
        new_rep.append(r)
        new_sign.append(s)
        eliminated.add(i)
        aliases[v.name] = (variables[r].name, s)
        below_old, below_new = i, r
        while variables[below_old].der >= 0:       # der(v) = s * der(r), der(der(v)) = ...
            d_old = variables[below_old].der
            d_new = _ensure_derivative(new_vars, below_new)
            old.append(d_old)
            new_rep.append(d_new)
            new_sign.append(s)
            aliases[variables[d_old].name] = (new_vars[d_new].name, s)
            eliminated.add(d_old)
            below_old, below_new = d_old, d_new

    column = ca.vertcat(model.stacked_variables(),     # symbols of new_vars, by index
                        *[v.sx for v in new_vars[len(variables):]])
    kept_idx = _complement(len(model.equations), used)
    kept = [model.equations[k] for k in kept_idx]
    kept_column = None
    hybrid = model.hybrid
    extra = hybrid.expressions() if hybrid is not None else []
    n_init = len(model.initial_equations)          # substituted like the model's equations
    extra = [eq.residual for eq in model.initial_equations] + extra
    if kept or extra:
        targets = ca.vertcat(take(model.stacked_residuals(), kept_idx), *extra)
        if old:
            targets = ca.substitute(targets, take(column, old),
                                    take(column, new_rep) * ca.DM(new_sign))
        kept_column = targets[:len(kept)]
        rest = targets[len(kept):]
        parts = ca.vertsplit(rest) if rest.numel() > 1 else [rest] if extra else []
        initial = [FlatEquation(r, eq.origin) for r, eq in
                   zip(parts[:n_init], model.initial_equations, strict=True)]
        if hybrid is not None:
            hybrid = hybrid.with_expressions(parts[n_init:])
    equations = [FlatEquation(None, eq.origin, terms=eq.terms, at=(kept_column, k))
                 for k, eq in enumerate(kept)]
    keep_idx = _complement(len(new_vars), eliminated)
    remap_of = np.full(len(new_vars) + 1, -1)    # old index -> new; remap[-1] stays -1
    remap_of[keep_idx] = np.arange(len(keep_idx))
    remap = remap_of.tolist()
    final = []
    for i in keep_idx:
        v = new_vars[i]
        if v.der < 0 and v.der_of < 0:
            final.append(v)                        # no derivative links to renumber
        else:
            final.append(v.relinked(remap[v.der_of], remap[v.der]))
    out = FlatModel(model.name, final, model.parameters, model.inputs, equations, aliases,
                    model.discretes, hybrid)
    out.initial_equations = initial if n_init else []
    out.remember_stacked(residuals=kept_column, variables=take(column, keep_idx), like=model)
    return out


def _complement(n: int, removed: set[int]) -> list[int]:
    """``[k for k in range(n) if k not in removed]``, in numpy."""
    keep = np.ones(n, dtype=bool)
    keep[np.fromiter(removed, dtype=np.int64, count=len(removed))] = False
    return np.flatnonzero(keep).tolist()


def _ranks(variables: list[FlatVariable], links: list[tuple[int, int, float]]) -> list[int]:
    """Integer ranks (higher: better representative of an alias class) of the linked
    variables, by (has a derivative, state_select, fixed start, fewer dots, shorter name)."""
    linked = {i for a, b, _ in links for i in (a, b)}
    keys = {}
    for i in linked:
        v = variables[i]
        keys[i] = (v.der >= 0, getattr(v.decl, "state_select", 0),
                   bool(getattr(v.decl, "fixed", False)), -v.name.count("."), -len(v.name))
    dense = {key: k for k, key in enumerate(sorted(set(keys.values())))}
    out = [0] * len(variables)
    for i, key in keys.items():
        out[i] = dense[key]
    return out


def _ensure_derivative(variables: list[FlatVariable], i: int) -> int:
    """Index of der(variables[i]), appending a new derivative variable if needed."""
    v = variables[i]
    if v.der >= 0:
        return v.der
    d = FlatVariable(f"der({v.name})", ca.SX.sym(f"der({v.name})"),
                     Variable(unit=derivative_unit(v.decl.unit)), v.component, der_of=i)
    variables.append(d)
    variables[i] = replace(v, der=len(variables) - 1)
    return len(variables) - 1


def _merge_metadata(variables: list[FlatVariable], rep: list[int], sign: list[float],
                    members: list[int]) -> None:
    """Carry fixed start values and the strongest state priority to each representative
    (``members``: the variables that are not their class's representative)."""
    for i in members:
        v = variables[i]
        r = rep[i]
        rv = variables[r]
        dv, dr = v.decl, rv.decl
        updates = {}
        if getattr(dv, "state_select", 0) > getattr(dr, "state_select", 0):
            updates["state_select"] = dv.state_select
        if getattr(dv, "fixed", False):
            start = sign[i] * dv.start
            if getattr(dr, "fixed", False) and abs(dr.start - start) > 1e-12 * (1 + abs(start)):
                raise InitializationError(
                    f"conflicting fixed start values for aliases {v.name} = {sign[i]:+g} * "
                    f"{rv.name}: {v.name}.start = {dv.start} ({v.component or 'top'}) but "
                    f"{rv.name}.start = {dr.start} ({rv.component or 'top'})")
            updates.update(start=start, fixed=True)
        elif not getattr(dr, "fixed", False) and dr.start == 0 and dv.start != 0:
            updates["start"] = sign[i] * dv.start
        if updates and hasattr(dr, "fixed"):
            variables[r] = replace(rv, decl=replace(dr, **updates))
