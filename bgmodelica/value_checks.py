"""Parameter, input and start values of a compiled model: finite and inside their declared
``min``/``max`` (:func:`check_values`, called before every run). A violation raises
:class:`~bgmodelica.errors.ParameterError` naming the value and where it was declared."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .errors import ParameterError


def _bounds(decl: Any) -> tuple[float | None, float | None]:
    lo, hi = getattr(decl, "min", None), getattr(decl, "max", None)
    return (None if lo is None else float(lo)), (None if hi is None else float(hi))


def _bound(decl: Any, side: str, none: float) -> float:
    value = getattr(decl, side, None)
    return none if value is None else float(value)


def _has_bounds(decl: Any) -> bool:
    return getattr(decl, "min", None) is not None or getattr(decl, "max", None) is not None


def _range_text(lo: float | None, hi: float | None) -> str:
    return (f"[{'-inf' if lo is None else f'{lo:g}'}, {'inf' if hi is None else f'{hi:g}'}]")


def _check_one(kind: str, name: str, value: float, decl: Any, where: str) -> None:
    if not math.isfinite(value):
        raise ParameterError(f"{kind} {name}{where} is {value}: it must be a finite number")
    lo, hi = _bounds(decl)
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        side = f"below its min = {lo:g}" if lo is not None and value < lo \
            else f"above its max = {hi:g}"
        raise ParameterError(f"{kind} {name}{where} = {value:g} is {side} (declared range "
                             f"{_range_text(lo, hi)})")


def check_values(dae: Any, p: np.ndarray, flat: Any = None) -> None:
    """Parameters, inputs and fixed start values: finite and inside their declared
    ``min``/``max``. ``flat`` (the reduced flat model) supplies parameters bound to
    expressions of others and the declarations of the variables. The parameters and inputs
    are checked in numpy against bounds kept in ``dae.cache``; the start values, fixed when
    the model was compiled, are checked once per model."""
    p = np.asarray(p, dtype=float)
    n_par, n_in = len(dae.parameters), len(dae.inputs)
    lo, hi = _value_bounds(dae)
    head = p[:n_par + n_in]
    with np.errstate(invalid="ignore"):
        bad = ~np.isfinite(head) | (head < lo) | (head > hi)
    for k in np.flatnonzero(bad).tolist():          # the first one raises
        kind, q = ("parameter", dae.parameters[k]) if k < n_par \
            else ("input", dae.inputs[k - n_par])
        _check_one(kind, q.name, float(head[k]), q.decl, _declared(q))
    bad_discrete = [d.name for k, d in enumerate(getattr(dae, "discretes", ()))
                    if not math.isfinite(float(p[n_par + n_in + k]))
                    and not d.name.startswith("$")]
    if bad_discrete:
        raise ParameterError(f"discrete variable {bad_discrete[0]} starts at a non-finite "
                             "value")
    if flat is not None:
        bound, lo, hi = _bound_parameters(dae, flat)
        if bound:
            values = _bound_values(dae, bound, p)
            v = np.array([math.nan if x is None else x for x in values], dtype=float)
            with np.errstate(invalid="ignore"):
                bad = ~np.isfinite(v) | (v < lo) | (v > hi)
            for k in np.flatnonzero(bad).tolist():     # the first one raises
                q = bound[k]
                if values[k] is not None:
                    comp = f", declared in {q.component}" if q.component else ""
                    _check_one("parameter", q.name, values[k], q.decl,
                               f" (bound to other parameters{comp})")
    # a DAE copied with other start values (dataclasses.replace) shares the cache: the
    # entries remember which objects they were made for
    key = ("starts checked", flat is not None)
    made_for = (dae.fixed, dae.x_start, dae.z_start)
    seen = dae.cache.get(key)
    if seen is None or any(a is not b for a, b in zip(seen, made_for, strict=True)):
        _check_starts(dae, flat)
        dae.cache[key] = made_for


def _value_bounds(dae: Any) -> tuple[np.ndarray, np.ndarray]:
    """Declared ``min``/``max`` of the parameters then the inputs (-inf/inf: none)."""
    seen = dae.cache.get("value bounds")
    if seen is None or seen[0] is not dae.parameters or seen[1] is not dae.inputs:
        lo, hi = _limits([q.decl for q in (*dae.parameters, *dae.inputs)])
        seen = dae.cache["value bounds"] = (dae.parameters, dae.inputs, lo, hi)
    return seen[2], seen[3]


def _limits(decls: list) -> tuple[np.ndarray, np.ndarray]:
    """Declared ``min``/``max`` of ``decls`` as arrays to compare values with (-inf/inf:
    none; a NaN bound compares as none, as it does as a float)."""
    try:
        lo = np.array([getattr(d, "min", None) for d in decls], dtype=float)
        hi = np.array([getattr(d, "max", None) for d in decls], dtype=float)
    except (TypeError, ValueError):      # a bound numpy cannot convert: one at a time
        lo = np.array([_bound(d, "min", -math.inf) for d in decls], dtype=float)
        hi = np.array([_bound(d, "max", math.inf) for d in decls], dtype=float)
    lo[np.isnan(lo)] = -math.inf
    hi[np.isnan(hi)] = math.inf
    return lo, hi


def _bound_parameters(dae: Any, flat: Any) -> tuple[list, np.ndarray, np.ndarray]:
    """The parameters of ``flat`` bound to expressions of others, and their declared
    ``min``/``max`` (-inf/inf: none), kept in ``dae.cache``."""
    import casadi as ca

    seen = dae.cache.get("bound parameters")
    if seen is None or seen[0] is not flat.parameters:
        bound = [q for q in flat.parameters if isinstance(q.decl.value, ca.SX)]
        lo, hi = _limits([q.decl for q in bound])
        seen = dae.cache["bound parameters"] = (flat.parameters, bound, lo, hi)
    return seen[1], seen[2], seen[3]


def _check_starts(dae: Any, flat: Any) -> None:
    """Fixed start values inside their bounds, all start values finite."""
    decls = _fixed_declarations(dae, flat)
    for k, value in dae.fixed:
        name = dae.names[k]
        decl = decls.get(name)
        value = float(value)
        if math.isfinite(value) and not _has_bounds(decl):
            continue
        v = _variable(flat, name) if decl is not None else None
        _check_one("start value of", name, value, decl, _declared(v) if v is not None else "")
    for names, starts in ((dae.state_names, dae.x_start), (dae.algebraic_names, dae.z_start)):
        starts = np.asarray(starts, dtype=float).ravel()
        for k in np.flatnonzero(~np.isfinite(starts[:len(names)])).tolist()[:1]:
            raise ParameterError(f"start value of {names[k]} is {starts[k]}: it must be a "
                                 "finite number")


def _fixed_declarations(dae: Any, flat: Any) -> dict[str, Any]:
    """The declarations of the variables with a fixed start value, by name (those found in
    ``flat``)."""
    if flat is None or not dae.fixed:
        return {}
    variables = flat.variables
    names = getattr(variables, "names", None)       # (a large model's: by position when
    at = getattr(variables, "declarations_at", None)                   # the names agree)
    if at is not None and isinstance(names, list) and names == dae.names[:len(names)]:
        found = [k for k, _ in dae.fixed if k < len(names)]
        return dict(zip([dae.names[k] for k in found], at(found), strict=True))
    wanted = {dae.names[k] for k, _ in dae.fixed}
    by_name = getattr(variables, "declarations", None)
    return by_name(wanted) if by_name is not None else \
        {v.name: v.decl for v in variables if v.name in wanted}


def _variable(flat: Any, name: str) -> Any:
    """The flat variable ``name`` (for where it was declared)."""
    lookup = getattr(flat.variables, "lookup", None)
    if lookup is not None:
        return lookup({name}).get(name)
    return next((v for v in flat.variables if v.name == name), None)


def _declared(v: Any, sep: str = " (") -> str:
    comp = getattr(v, "component", "")
    if not comp:
        return ""
    return f"{sep}declared in {comp}" + (")" if sep == " (" else "")


def _bound_values(dae: Any, bound: list, p: np.ndarray) -> list[float | None]:
    read = getattr(dae, "parameter_values_read", None) or getattr(dae, "parameter_values", None)
    values = read(p) if read is not None else {}
    return [values.get(q.name) for q in bound]
