"""Parameter and start-value overrides of a run, by name: split into parameter values and
start values, aliases resolved (with their sign), unknown names refused with the closest
ones, and a DAE whose start values are the overrides (the states they fix and the ones
they release)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import casadi as ca

from .backends.casadi_dae import CasadiDAE
from .errors import ParameterError


def split_overrides(dae: CasadiDAE, params: dict[str, Any]):
    """Split ``params`` into overrides of parameters / inputs (for ``dae.p_vector``) and start
    values of variables, both keyed by the names the DAE keeps.

    A start value may name a state, any other continuous variable the DAE observes (e.g. one
    that index reduction demoted: its start becomes a condition on the states), or an alias
    of either (``dae.aliases``: name -> (kept name, sign), value converted with the sign); an
    alias of a parameter or input overrides that. Unknown names raise :class:`ParameterError`
    with the closest names.
    """
    from .backends.casadi_dae import _number

    pnames = [q.name for q in dae.parameters] + [u.name for u in dae.inputs] \
        + [d.name for d in getattr(dae, "discretes", ())]
    pset = set(pnames)
    n_var = getattr(dae, "n_variables", 0) or len(dae.names)
    aliases = getattr(dae, "aliases", None) or {}
    p_over: dict[str, Any] = {}
    start_over: dict[str, float] = {}
    given: dict[str, tuple[str, float]] = {}      # kept name -> (name given, value)
    unknown = []
    for key, value in params.items():
        name, sign = resolve_alias(key, aliases, pset, dae.observed_index)
        if name in pset:
            val = sign * _number(key, value)
            target = p_over
        elif name in dae.observed_index and dae.observed_index[name] < n_var:
            val = sign * _number(key, value)
            target = start_over
            slot = start_slot(dae, name)
            if slot is not None:          # the variable is a parameter or input (connected)
                name, val = pnames[slot[0]], slot[1] * val
                target = p_over
        else:
            unknown.append(key)
            continue
        if name in given and given[name][1] != val:
            raise ParameterError(f"{given[name][0]!r} and {key!r} name the same variable "
                                 f"({name}) with conflicting values")
        given[name] = (key, val)
        target[name] = val
    evaluated = getattr(dae, "evaluated", None) or {}
    for key in list(unknown):
        if key in evaluated and _number(key, params[key]) != evaluated[key]:
            from .backends.casadi_dae import evaluated_error

            raise evaluated_error(key, evaluated[key])
        if key in evaluated:
            unknown.remove(key)                    # its value already
    if unknown:
        known = pnames + dae.names[:n_var] + list(aliases)
        raise ParameterError(f"{unknown[0]!r} is not a parameter, input or variable of the "
                             f"model{did_you_mean(unknown[0], known)}")
    return p_over, start_over


def start_slot(dae: CasadiDAE, name: str) -> tuple[int, float] | None:
    """``(index in p, sign)`` when variable ``name`` observes ``sign * p[index]`` (e.g. the
    input of a subcomponent connected to a model input); :class:`ParameterError` when it
    depends on no state or algebraic variable otherwise (its start cannot be chosen)."""
    expr = dae.observed[dae.observed_index[name]]
    for sign in (1.0, -1.0):
        e = sign * expr
        if e.is_symbolic():
            for i in range(dae.p.numel()):
                if ca.is_equal(e, dae.p[i]):
                    return i, sign
    unknowns = ca.vertcat(dae.x, dae.z)
    if unknowns.numel() == 0 or ca.jacobian_sparsity(expr, unknowns).nnz() == 0:
        raise ParameterError(f"{name!r} is computed from parameters, inputs and time only; "
                             "its start value cannot be set")
    return None


def resolve_alias(name: str, aliases: dict[str, tuple[str, float]], pset: set[str],
                   observed_index: dict[str, int]) -> tuple[str, float]:
    """``(kept name, sign)`` of ``name`` (``name = sign * kept``), following alias chains."""
    sign = 1.0
    seen = set()
    while name not in pset and name not in observed_index and name in aliases \
            and name not in seen:
        seen.add(name)
        name, s = aliases[name]
        sign *= float(s)
    return name, sign


def did_you_mean(key: str, names: Sequence[str]) -> str:
    """``"; did you mean a, b?"``: names with the same last part, else the closest spellings."""
    import difflib

    names = [n for n in dict.fromkeys(names) if not n.startswith(("der(", "$"))]
    last = key.split(".")[-1]
    close = [n for n in names if n.split(".")[-1] == last]
    if not close:
        close = difflib.get_close_matches(key, names, n=5, cutoff=0.6)
    return f"; did you mean {', '.join(close[:5])}?" if close else ""


def with_starts(dae: CasadiDAE, overrides: dict[str, Any]) -> CasadiDAE:
    """``dae`` with the start values ``overrides`` (by kept name) fixed.

    A state starts at its value; an algebraic variable takes it as its guess too; any other
    variable becomes a condition on the states. Start values fixed by the model that these
    conditions leave structurally impossible to meet (e.g. the states' default rest position
    when a demoted variable is set) are released to guesses, with a warning; conflicts among
    the given values themselves are left to :func:`initialize` to report.
    """
    import warnings
    from dataclasses import replace

    from .backends.casadi_dae import _number

    fixed = dict(dae.fixed)
    x_start, z_start = dae.x_start.copy(), dae.z_start.copy()
    state_pos = {n: i for i, n in enumerate(dae.state_names)}
    alg_pos = {n: i for i, n in enumerate(dae.algebraic_names)}
    given: set[int] = set()
    for name, value in overrides.items():
        k = dae.observed_index[name]
        fixed[k] = _number(name, value)
        given.add(k)
        if name in state_pos:
            x_start[state_pos[name]] = fixed[k]
        elif name in alg_pos:
            z_start[alg_pos[name]] = fixed[k]
    released = released_starts(dae, fixed, given)
    if released:
        warnings.warn(
            "start value(s) fixed by the model released to guesses: "
            + ", ".join(f"{dae.names[k]} = {fixed[k]:g}" for k in released)
            + " (they conflict with the start values given for "
            + ", ".join(dae.names[k] for k in sorted(given)) + ")", stacklevel=3)
        for k in released:
            del fixed[k]
    return replace(dae, fixed=sorted(fixed.items()), x_start=x_start, z_start=z_start)


def released_starts(dae: CasadiDAE, fixed: dict[int, float], given: set[int]) -> list[int]:
    """The model's fixed start values (``fixed`` minus ``given``) that cannot be met together
    with the ``given`` ones, structurally: each fixed value is a condition on the states and
    algebraic variables (a state's: itself), matched after the model's algebraic equations,
    the given conditions first. Empty when the model's own conditions already conflict."""
    from .structure import maximum_matching

    declared = sorted(k for k in fixed if k not in given)
    if not given or not declared:
        return []
    order = sorted(given) + declared
    unknowns = ca.vertcat(dae.x, dae.z)
    n_unknowns, nz = unknowns.numel(), dae.alg.numel()
    if n_unknowns == 0:
        return []
    expr = ca.vertcat(dae.alg, *[dae.observed[k] for k in order])
    rows: list[list[int]] = [[] for _ in range(expr.numel())]
    for r, c in zip(*ca.jacobian_sparsity(expr, unknowns).get_triplet(), strict=True):
        rows[r].append(c)
    n_given = len(given)

    def allowed(model: bool, giv: bool, decl: bool) -> list[bool]:
        return [model] * nz + [giv] * n_given + [decl] * len(declared)

    first = maximum_matching(rows, n_unknowns, eq_allowed=allowed(True, False, False))
    alone = maximum_matching(rows, n_unknowns, eq_allowed=allowed(True, False, True),
                             initial=first)
    if any(alone.eq_to_var[nz + n_given + i] < 0 for i in range(len(declared))):
        return []                 # the model's own start values conflict: initialize says so
    second = maximum_matching(rows, n_unknowns, eq_allowed=allowed(True, True, False),
                              initial=first)
    full = maximum_matching(rows, n_unknowns, initial=second)
    return [k for i, k in enumerate(declared) if full.eq_to_var[nz + n_given + i] < 0]
