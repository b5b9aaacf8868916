"""An optimal-control problem on a compiled model, in the model's own symbols.

Controls are top-level ``Input``s (their slots in ``dae.p``); the objective, final
conditions and path constraints are SX in ``(t, x, z, p)``; the initial state is the
model's consistent initial point with the given initial values fixed (as ``simulate``
makes it). :class:`Problem` is what the collocation transcribes.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np

from ..errors import ModelError, ParameterError


class OptimizationError(ModelError):
    """An optimal-control problem that cannot be posed (unsupported model, unbounded
    minimum time) or that has no solution (the message carries IPOPT's diagnosis)."""


Bounds = tuple[float, float]


@dataclass
class Constraint:
    """``lo <= expr <= hi`` (an equality when lo == hi); ``label`` as the user wrote it."""

    label: str
    expr: ca.SX
    lo: float
    hi: float
    name: str = ""          # the variable of a final condition


@dataclass
class Problem:
    """The problem in the compiled model's symbols (see the module docstring)."""

    compiled: Any
    dae: Any
    p: np.ndarray                    # parameters and inputs (control slots overwritten)
    controls: list[str]
    slots: list[int]                 # index of each control in p
    bounds: list[Bounds]
    x0: np.ndarray
    z0: np.ndarray
    start: dict[str, float]          # the initial values given (for the re-simulation)
    params: dict[str, Any]           # parameter / input overrides given
    final: list[Constraint]
    path: list[Constraint]
    lagrange: ca.SX
    mayer: ca.SX
    stop_time: float | None          # None: minimum time
    time_guess: float
    scale_x: np.ndarray = field(default_factory=lambda: np.ones(0))
    interval_integrator: Any = None  # built on the first mesh refinement

    @property
    def minimum_time(self) -> bool:
        return self.stop_time is None

    @property
    def u(self) -> ca.SX:
        """The control symbols (slots of ``dae.p``)."""
        return ca.vertcat(*[self.dae.p[i] for i in self.slots])


def parse_bounds(text: str, option: str) -> Bounds:
    """``"-12:12"`` -> (-12, 12); an empty side, ``inf`` or no range at all is unbounded."""
    if not text.strip():
        return (-math.inf, math.inf)
    lo, sep, hi = text.partition(":")
    if not sep:
        raise ParameterError(f"{option}: expected LOW:HIGH, got {text!r}")
    try:
        out = (float(lo) if lo.strip() else -math.inf, float(hi) if hi.strip() else math.inf)
    except ValueError:
        raise ParameterError(f"{option}: {text!r} is not LOW:HIGH with numbers") from None
    if any(math.isnan(v) for v in out) or out[0] > out[1]:
        raise ParameterError(f"{option}: empty range {text!r}")
    return out


def make_problem(compiled: Any, controls: Mapping[str, Bounds | None] | Sequence[str], *,
                 initial: Mapping[str, float] | None, final: Mapping[str, float] | None,
                 stop_time: float | None, lagrange: str | None, mayer: str | None,
                 path: Mapping[str, Bounds] | None, params: Mapping[str, Any] | None,
                 time_guess: float | None) -> Problem:
    """Check the request against the model and build the :class:`Problem`."""
    from ..backends.casadi_init import initialize
    from ..core.units import with_units
    from ..overrides import split_overrides, with_starts
    from .expression import parse_expression

    dae = compiled.dae
    if dae.hybrid is not None:
        raise OptimizationError(f"cannot optimize {compiled.name}: the model has events "
                                "(relations, when-clauses, samples or tables); only smooth "
                                "models are supported")
    ctrl = dict(controls) if isinstance(controls, Mapping) else {c: None for c in controls}
    if not ctrl:
        raise OptimizationError("no controls: name at least one top-level input "
                                "(--control NAME=LOW:HIGH)")
    inputs = [u.name for u in dae.inputs]
    n_par = len(dae.parameters)
    slots, bounds = [], []
    for name, bnd in ctrl.items():
        if name not in inputs:
            raise ParameterError(f"control {name!r} is not a top-level input of "
                                 f"{compiled.name} (its inputs: {', '.join(inputs) or 'none'})")
        slots.append(n_par + inputs.index(name))
        bounds.append((-math.inf, math.inf) if bnd is None else (float(bnd[0]), float(bnd[1])))
    if stop_time is None and any(not (math.isfinite(lo) and math.isfinite(hi))
                                 for lo, hi in bounds):
        bad = [c for c, (lo, hi) in zip(ctrl, bounds, strict=True)
               if not (math.isfinite(lo) and math.isfinite(hi))]
        raise OptimizationError(f"minimum time needs bounded controls: {', '.join(bad)} "
                                "unbounded (give --control NAME=LOW:HIGH)")
    if stop_time is not None and not (math.isfinite(stop_time) and stop_time > 0):
        raise ParameterError(f"stop time {stop_time}: must be a positive finite time")

    params = with_units(dict(params or {}), compiled)
    p_over, start_over = split_overrides(dae, params)
    given = {str(k): float(v) for k, v in (initial or {}).items()}
    p_init, start_init = split_overrides(dae, given)
    if p_init:
        raise ParameterError(f"initial value {next(iter(p_init))!r}: not a variable of the "
                             f"model (set parameters with --set)")
    p = dae.p_vector(p_over)
    for k, (lo, hi) in zip(slots, bounds, strict=True):   # a feasible start for the warm run
        p[k] = float(np.clip(p[k], lo, hi))
    start_all = {**start_over, **start_init}
    init_dae = with_starts(dae, start_all) if start_all else dae
    init = initialize(init_dae, p, 0.0)

    lookup = _lookup(compiled, p, slots)
    fin = [Constraint(f"final {name} = {val:g}", lookup(name), float(val), float(val), name)
           for name, val in (final or {}).items()]
    pth = [Constraint(f"path {name}", parse_expression(name, lookup, "--path"),
                      float(lo), float(hi)) for name, (lo, hi) in (path or {}).items()]
    lag = parse_expression(lagrange, lookup, "--lagrange") if lagrange else ca.SX(0)
    may = parse_expression(mayer, lookup, "--mayer") if mayer else ca.SX(0)
    if stop_time is not None and not lagrange and not mayer:
        raise OptimizationError("nothing to minimize: give --lagrange, --mayer or "
                                "--minimize time")
    return Problem(compiled, dae, p, list(ctrl), slots, bounds, np.asarray(init.x0, float),
                   np.asarray(init.z0, float), {**given},
                   {**params}, fin, pth, lag, may, stop_time,
                   float(time_guess or stop_time or 1.0))


def _lookup(compiled: Any, p: np.ndarray, slots: list[int]):
    """``name -> SX`` over the compiled model's variables, parameters and inputs."""
    from ..overrides import did_you_mean, resolve_alias

    dae = compiled.dae
    n_var = dae.n_variables or len(dae.names)
    pnames = [q.name for q in dae.parameters] + [u.name for u in dae.inputs]
    pindex = {n: k for k, n in enumerate(pnames)}
    bound = dae.parameter_values(p)

    def lookup(name: str) -> ca.SX:
        if name == "time":
            return dae.t
        kept, sign = resolve_alias(name, dae.aliases, set(pindex), dae.observed_index)
        if kept in pindex:
            return sign * dae.p[pindex[kept]]
        if kept in dae.observed_index and dae.observed_index[kept] < n_var:
            return sign * dae.observed[dae.observed_index[kept]]
        if kept in bound:
            return ca.SX(sign * bound[kept])
        raise ParameterError(f"{name!r} is not a variable, parameter or input of "
                             f"{compiled.name}"
                             f"{did_you_mean(name, dae.names[:n_var] + pnames)}")

    return lookup
