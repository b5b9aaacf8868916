"""Operating points of a compiled model: consistent start values, steady states, the state of
a simulation at a time.

A *steady state* of the index-reduced DAE ``x' = f(t, x, z, p)``, ``0 = g(t, x, z, p)`` solves
``f = 0``, ``g = 0`` for the states ``x`` and the algebraic variables ``z`` at fixed
parameters and inputs ``p`` (and time ``t``), the start values serving only as guesses
(Modelica's ``der(x) = 0`` initialization). States listed in ``exclude`` need not be
stationary (e.g. the angle of a shaft turning at constant speed): they keep their start
values and their derivative is not required to vanish.

The system is first checked structurally (a maximum matching of the Jacobian pattern, the
Dulmage-Mendelsohn decomposition naming the over-determined conditions and the undetermined
variables), then solved by a damped Newton method with a backtracking line search on the
residual's 2-norm. Failures raise :class:`~bgmodelica.errors.InitializationError` naming the
conditions (``der(x) = 0`` with the model equation that defines ``der(x)``) and variables at
fault.

Models that need dynamic state selection (the Cartesian pendulum) are handled by choosing
the state selection whose pivots are best at the guess, and again at the solution.
"""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import casadi as ca
import numpy as np

from ..backends.casadi_dae import CasadiDAE
from ..backends.casadi_init import initialize
from ..errors import InitializationError, ParameterError
from .steady_solve import solve_steady_state, state_name

__all__ = ["OperatingPoint", "steady_state", "operating_point", "solve_steady_state",
           "steady_state_dae"]


@dataclass
class OperatingPoint:
    """A consistent point ``(t, x, z, p)`` of a compiled model.

    compiled: the compiled model (the state selection the point is expressed in; a variant of
    the model given when dynamic state selection chose other states). x, z: states and
    algebraic variables (``compiled.dae.state_names``, ``algebraic_names``); p: parameters,
    inputs and discrete slots. kind: ``"start values"``, ``"steady state"`` or
    ``"simulation at t = T"``. residual: the largest ``|der(x)|`` over the states (0 at a
    steady state up to the tolerance). ``point["arm.q1"]`` gives any variable, alias,
    parameter or input; :attr:`values` all of them.
    """

    compiled: Any
    dae: CasadiDAE
    p: np.ndarray
    t: float
    x: np.ndarray
    z: np.ndarray
    kind: str = "start values"
    notes: list[str] = field(default_factory=list)
    iterations: int = 0
    excluded: list[str] = field(default_factory=list)

    @property
    def residual(self) -> float:
        xd = self.derivatives
        return float(max((abs(v) for k, v in xd.items()
                          if k[4:-1] not in self.excluded), default=0.0))

    @property
    def derivatives(self) -> dict[str, float]:
        """``der(x)`` of every state at the point."""
        f = _cached(self.dae, "ss_ode", lambda d: ca.Function(
            "ode", [d.t, d.x, d.z, d.p], [d.ode]))
        vals = np.asarray(f(self.t, self.x, self.z, self.p)).ravel()
        return {f"der({n})": float(v) for n, v in zip(self.dae.state_names, vals, strict=True)}

    @property
    def values(self) -> dict[str, float]:
        """Every variable (aliases included), parameter and input at the point."""
        dae = self.dae
        f = _cached(dae, "ss_obs", lambda d: ca.Function(
            "obs", [d.t, d.x, d.z, d.p], [d.observed]))
        obs = np.asarray(f(self.t, self.x, self.z, self.p)).ravel()
        out = {n: float(v) for n, v in zip(dae.names, obs, strict=True)}
        for a, (rep, sign) in dae.aliases.items():
            if rep in out and a not in out:
                out[a] = float(sign) * out[rep]
        pvals = dae.parameter_values(self.p) if hasattr(dae, "parameter_values") else {
            q.name: float(v) for q, v in zip(dae.parameters, self.p, strict=False)}
        for a, (rep, sign) in dae.aliases.items():
            if rep in pvals and a not in out:
                out[a] = float(sign) * pvals[rep]
        out.update({k: v for k, v in pvals.items() if k not in out})
        n_par = len(dae.parameters)
        out.update({u.name: float(self.p[n_par + k]) for k, u in enumerate(dae.inputs)})
        out["time"] = float(self.t)
        return out

    @property
    def states(self) -> dict[str, float]:
        return {n: float(v) for n, v in zip(self.dae.state_names, self.x, strict=True)}

    @property
    def inputs(self) -> dict[str, float]:
        n_par = len(self.dae.parameters)
        return {u.name: float(self.p[n_par + k]) for k, u in enumerate(self.dae.inputs)}

    def __getitem__(self, name: str) -> float:
        vals = self.values
        if name not in vals:
            from ..overrides import did_you_mean

            raise KeyError(f"no variable {name!r} at the operating point"
                           f"{did_you_mean(name, list(vals))}")
        return vals[name]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: kind, time, states, inputs, every variable, residual, notes."""
        vals = self.values
        return {"kind": self.kind, "time": float(self.t), "states": self.states,
                "inputs": self.inputs, "residual": self.residual, "notes": list(self.notes),
                "excluded": list(self.excluded),
                "variables": {k: v for k, v in vals.items() if k != "time"}}


def _cached(dae: CasadiDAE, key: str, make) -> Any:
    if key not in dae.cache:
        dae.cache[key] = make(dae)
    return dae.cache[key]


# -- the public entry points ------------------------------------------------------------------

def steady_state(model: Any, params: dict[str, Any] | None = None, *, t: float = 0.0,
                 exclude: Sequence[str] = (), tol: float = 1e-10, max_iter: int = 100,
                 units: str = "error") -> OperatingPoint:
    """The steady state of ``model`` (a component, a compiled model or a MODEL reference such
    as ``"library.examples:RC"``): ``der(x) = 0`` for
    every state (but those in ``exclude``) with the parameters and inputs in ``params``; the
    start values (the model's and those given in ``params``) are only guesses.

    tol: largest residual accepted (|der(x)| and algebraic residuals, in model units); the
    Newton iteration continues past it while it still improves, so a well-conditioned point is
    found to machine precision. Raises :class:`~bgmodelica.errors.InitializationError` naming
    the conditions and variables when the steady state is structurally impossible (e.g.
    ``der(x) = u`` with ``u != 0``, or a state no condition determines) or the iteration
    fails."""
    return operating_point(model, params, steady=True, t=t, exclude=exclude, tol=tol,
                           max_iter=max_iter, units=units)


def operating_point(model: Any, params: dict[str, Any] | None = None, *, steady: bool = False,
                    at_time: float | None = None, t: float = 0.0, exclude: Sequence[str] = (),
                    tol: float = 1e-10, max_iter: int = 100, units: str = "error",
                    simulate_options: dict[str, Any] | None = None) -> OperatingPoint:
    """A consistent operating point of ``model``: the initial point from the start values
    (default), the steady state (``steady=True``, see :func:`steady_state`), or the state of
    a simulation from the start values at ``at_time`` [s] (``simulate_options`` go to
    :func:`~bgmodelica.simulate`).

    ``params`` override parameters, inputs and start values by dotted name, as in
    :func:`~bgmodelica.simulate` (start values are fixed conditions for the initial point and
    guesses for a steady state). When the model needs dynamic state selection, the point is
    expressed in the states whose pivots are best there."""
    from ..compiler import CompiledModel, compile
    from ..core.units import with_units
    from ..overrides import split_overrides, with_starts
    from ..simulate import _selector
    from ..value_checks import check_values

    if steady and at_time is not None:
        raise ParameterError("choose either a steady state or a time of a simulation "
                             "(at_time), not both")
    compiled = model if isinstance(model, CompiledModel) else compile(model, units=units)
    params = with_units(dict(params or {}), compiled)
    dae0 = compiled.dae
    p_over, start_over = split_overrides(dae0, params)
    p = dae0.p_vector(p_over)
    check_values(dae0, p, compiled.reduced.model)
    selector = _selector(compiled)
    if at_time is not None:
        return _at_time(compiled, params, float(at_time), t, selector, simulate_options or {})
    if not steady:
        dae = with_starts(dae0, start_over) if start_over else dae0
        init = initialize(dae, p, t)
        point = OperatingPoint(compiled, dae, p, t, init.x0, init.z0, "start values",
                               list(init.notes))
        if selector is not None:
            point = _reselect(point, selector, p, t)
        return point
    guesses = {dae0.names[k]: float(v) for k, v in dae0.fixed}   # fixed starts: guesses
    guesses.update(start_over)
    current, dae, x, z, its = _steady_with_selection(compiled, compiled.dae, guesses, p, t,
                                                     selector, exclude, tol, max_iter)
    excluded = [state_name(dae, n) for n in exclude]
    notes = [] if current is compiled else [f"states chosen at the steady state: "
                                            f"{', '.join(dae.state_names)}"]
    return OperatingPoint(current, dae, p, t, x, z, "steady state", notes, its, excluded)


def _steady_with_selection(compiled, dae, guesses, p, t, selector, exclude, tol, max_iter):
    """Solve for the steady state in the state selection whose pivots are best at the guess
    and at the solution: ``(variant, its dae, x, z, iterations)``."""
    current = compiled
    dae = _with_guesses(dae, guesses, p, t)
    if selector is not None:                       # choose the states at the guess
        values = _all_values(dae, dae.x_start, dae.z_start, p, t)
        nxt = selector.check(current, values, p, t)
        if nxt is not current:
            current = nxt
            dae = _with_guesses(current.dae, {**_by_name(dae, values), **guesses}, p, t)
    x, z, its = solve_steady_state(dae, p, t, exclude=exclude, tol=tol, max_iter=max_iter)
    if selector is not None:                       # and again at the solution
        values = _all_values(dae, x, z, p, t)
        nxt = selector.check(current, values, p, t)
        if nxt is not current:
            current = nxt
            dae = _with_guesses(current.dae, _by_name(dae, values), p, t)
            x, z, more = solve_steady_state(dae, p, t, exclude=exclude, tol=tol,
                                             max_iter=max_iter)
            its += more
    return current, dae, x, z, its


def steady_state_dae(compiled: Any, dae: CasadiDAE, p: np.ndarray, t: float,
                     init: str = "steady-state", exclude: Sequence[str] = ()) -> CasadiDAE:
    """``dae`` whose initial conditions are its steady state (for ``simulate(...,
    init="steady-state")``): every state fixed at its steady value, algebraic guesses at
    theirs, the initial equations dropped (der(x) = 0 replaces them)."""
    if init in (None, "start", "start-values"):
        return dae
    if init != "steady-state":
        raise ParameterError(f"init must be 'start' or 'steady-state', not {init!r}")
    guesses = {n: float(v) for n, v in zip(dae.state_names, dae.x_start, strict=True)}
    guesses.update({n: float(v) for n, v in zip(dae.algebraic_names, dae.z_start,
                                                    strict=True)})
    for k, value in dae.fixed:                   # a given start value is a guess now
        guesses[dae.names[k]] = float(value)
    base = replace(dae, fixed=[], initial=dae.initial[:0], initial_labels=[])
    from ..simulate import _selector

    selector = _selector(compiled)
    current, work, x, z, _ = _steady_with_selection(compiled, base, guesses, p, t, selector,
                                                    exclude, 1e-10, 100)
    if current is not compiled:                    # back to the model's own states
        named = _by_name(work, _all_values(work, x, z, p, t))
        x = np.array([named[n] for n in dae.state_names])
        z = np.array([named.get(n, 0.0) for n in dae.algebraic_names])
    idx = dae.observed_index
    fixed = [(idx[n], float(v)) for n, v in zip(dae.state_names, x, strict=True)]
    return replace(base, fixed=fixed, x_start=np.asarray(x, float), z_start=np.asarray(z, float))


def fixed_at_values(dae: CasadiDAE, p: np.ndarray, t: float):
    """A function mapping a variant of ``dae`` (other states) to one whose states are fixed
    at the values they have at ``dae``'s initial point (for dynamic state selection after a
    steady-state initialization)."""
    init = initialize(dae, p, t)
    named = _by_name(dae, _all_values(dae, init.x0, init.z0, p, t))

    def prepare(d: CasadiDAE) -> CasadiDAE:
        x = np.array([named.get(n, 0.0) for n in d.state_names])
        return replace(d, fixed=[(d.observed_index[n], v) for n, v in
                                 zip(d.state_names, x, strict=True)], x_start=x,
                       z_start=np.array([named.get(n, 0.0) for n in d.algebraic_names]),
                       initial=d.initial[:0], initial_labels=[])

    return prepare


# -- helpers ------------------------------------------------------------------------------------

def _all_values(dae: CasadiDAE, x, z, p, t) -> np.ndarray:
    f = _cached(dae, "ss_obs", lambda d: ca.Function("obs", [d.t, d.x, d.z, d.p],
                                                      [d.observed]))
    with np.errstate(all="ignore"):
        vals = np.asarray(f(t, x, z, p)).ravel()[: dae.n_variables or len(dae.names)]
    bad = ~np.isfinite(vals)
    if bad.any():
        vals[bad] = 0.0
    return vals


def _by_name(dae: CasadiDAE, values: np.ndarray) -> dict[str, float]:
    return {n: float(v) for n, v in zip(dae.names, values, strict=False)}


def _with_guesses(dae: CasadiDAE, guesses: dict[str, float], p, t) -> CasadiDAE:
    """``dae`` with ``guesses`` (kept names) as start values of its states and algebraic
    variables; guesses for other variables (e.g. a coordinate that index reduction demoted)
    are turned into state guesses by a consistent initialization with them fixed."""
    x_start, z_start = dae.x_start.copy(), dae.z_start.copy()
    spos = {n: i for i, n in enumerate(dae.state_names)}
    zpos = {n: i for i, n in enumerate(dae.algebraic_names)}
    other = {}
    n_var = dae.n_variables or len(dae.names)
    for name, value in guesses.items():
        if name in spos:
            x_start[spos[name]] = value
        elif name in zpos:
            z_start[zpos[name]] = value
        elif name in dae.observed_index and dae.observed_index[name] < n_var:
            other[name] = value
    out = replace(dae, x_start=x_start, z_start=z_start)
    if other:
        trial = replace(out, fixed=[(dae.observed_index[n], v) for n, v in other.items()],
                        initial=dae.initial[:0], initial_labels=[])
        try:
            with _quiet():
                init = initialize(trial, p, t)
            if np.all(np.isfinite(init.x0)) and np.all(np.isfinite(init.z0)):
                out = replace(out, x_start=init.x0, z_start=init.z0)
        except InitializationError:
            pass                             # keep the plain guesses
    return out


@contextlib.contextmanager
def _quiet():
    """Silence C-level output (CasADi's warnings of a trial that may fail)."""
    saved = []
    try:
        for stream in (sys.stdout, sys.stderr):
            try:
                fd = stream.fileno()
            except (AttributeError, OSError, ValueError):
                continue
            stream.flush()
            saved.append((fd, os.dup(fd)))
        devnull = os.open(os.devnull, os.O_WRONLY)
        for fd, _ in saved:
            os.dup2(devnull, fd)
        os.close(devnull)
        yield
    finally:
        for fd, keep in saved:
            os.dup2(keep, fd)
            os.close(keep)


def _reselect(point: OperatingPoint, selector, p, t) -> OperatingPoint:
    values = _all_values(point.dae, point.x, point.z, p, t)
    nxt = selector.check(point.compiled, values, p, t)
    if nxt is point.compiled:
        return point
    dae = nxt.dae
    named = _by_name(point.dae, values)
    x = np.array([named[n] for n in dae.state_names])
    fixed = [(dae.observed_index[n], v) for n, v in zip(dae.state_names, x, strict=True)]
    work = replace(dae, fixed=fixed, x_start=x,
                   z_start=np.array([named.get(n, 0.0) for n in dae.algebraic_names]),
                   initial=dae.initial[:0], initial_labels=[])
    init = initialize(work, p, t)
    return OperatingPoint(nxt, dae, p, t, init.x0, init.z0, point.kind, point.notes
                          + [f"states chosen at the point: {', '.join(dae.state_names)}"])


def _at_time(compiled, params, at_time: float, t0: float, selector, options) -> OperatingPoint:
    from ..overrides import split_overrides
    from ..simulate import simulate

    if at_time < t0:
        raise ParameterError(f"at_time ({at_time:g} s) is before the start time ({t0:g} s)")
    dae = compiled.dae
    p_over, _ = split_overrides(dae, params)
    p = dae.p_vector(p_over)
    if at_time == t0:
        return operating_point(compiled, params, t=t0)
    opts = {"interval": at_time - t0, **options}
    res = simulate(compiled, stop_time=at_time, start_time=t0, params=params, **opts)
    named = {n: float(res[n][-1]) for n in res.names}
    for a in res.aliases:
        named.setdefault(a, float(res[a][-1]))
    current = compiled
    if selector is not None:
        values = np.array([named.get(n, 0.0) for n in dae.names[:dae.n_variables]])
        current = selector.check(compiled, values, p, at_time)
    dae = current.dae
    p = _discrete_slots(dae, p, named, at_time)
    x = np.array([named[n] for n in dae.state_names])
    fixed = [(dae.observed_index[n], v) for n, v in zip(dae.state_names, x, strict=True)]
    work = replace(dae, fixed=fixed, x_start=x,
                   z_start=np.array([named.get(n, 0.0) for n in dae.algebraic_names]),
                   initial=dae.initial[:0], initial_labels=[])
    init = initialize(work, p, at_time)
    notes = []
    if dae.hybrid is not None:
        notes.append("discrete variables and relations are held at their values at "
                     f"t = {at_time:g} s")
    return OperatingPoint(current, dae, p, at_time, init.x0, init.z0,
                          f"simulation at t = {at_time:g} s", notes)


def _discrete_slots(dae: CasadiDAE, p: np.ndarray, named: dict[str, float],
                    t: float) -> np.ndarray:
    """``p`` with the discrete slots of a hybrid model set from a simulation's last row:
    shown discrete variables by name, ``pre()`` slots from their variables, relations from
    the sign of their indicators (evaluated at the point)."""
    if dae.hybrid is None or not dae.discretes:
        return p
    p = np.array(p, dtype=float)
    base = dae.n_base
    for k, d in enumerate(dae.discretes):
        if d.name in named:
            p[base + k] = named[d.name]
    for slot, var in dae.hybrid.pre:
        if var in named:
            p[base + slot] = named[var]
    rels = dae.hybrid.relations
    if rels:
        x = np.array([named[n] for n in dae.state_names])
        z = np.array([named.get(n, 0.0) for n in dae.algebraic_names])
        f = ca.Function("ind", [dae.t, dae.x, dae.z, dae.p],
                        [ca.vertcat(*[r.indicator for r in rels])])
        g = np.asarray(f(t, x, z, p)).ravel()
        for r, val in zip(rels, g, strict=True):
            p[base + r.slot] = float(val > 0 if r.strict else val >= 0)
    return p
