"""Turn a :class:`SortedDAE` into CasADi functions: the semi-explicit DAE handed to IDAS
(``x' = f(t, x, z, p)``, ``0 = g(t, x, z, p)``) and the observation of every variable.

``p`` stacks the free parameters then the model inputs (held constant over a simulation
interval). Parameters bound to expressions of other parameters are substituted away.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from itertools import chain
from operator import attrgetter

import casadi as ca
import numpy as np

from ..core.flatmodel import FlatVariable, HybridPart, take
from ..core.variables import TIME
from ..errors import ParameterError, UnitError
from ..passes.sorting import SortedDAE

_DECL, _VALUE, _START = attrgetter("decl"), attrgetter("value"), attrgetter("start")

#: common subexpressions are merged (``casadi.cse``) in models with up to this many
#: expressions (ODE, residuals, observed): the solved loops of a multibody model repeat
#: products (the robot's ODE 352 -> 293 instructions), while regular large models have none
#: to merge and the pass would cost 0.35 s at 10,000 sections for nothing
CSE_UP_TO = 5000


@dataclass
class CasadiDAE:
    """Symbolic semi-explicit DAE and its observation map.

    x, z, p: SX column vectors; ode/alg: SX expressions; observed: SX of every variable in
    ``names`` order (derivatives and aliases included).
    """

    x: ca.SX
    z: ca.SX
    p: ca.SX
    t: ca.SX
    ode: ca.SX
    alg: ca.SX
    observed: ca.SX
    names: list[str]
    state_names: list[str]
    algebraic_names: list[str]
    parameters: list[FlatVariable]
    inputs: list[FlatVariable]
    x_start: np.ndarray
    z_start: np.ndarray
    fixed: list[tuple[int, float]]          # (index in names, value) of fixed start values
    observed_index: dict[str, int]
    cache: dict = field(default_factory=dict, repr=False)   # CasADi functions built on demand
    discretes: list[FlatVariable] = field(default_factory=list)  # slots at the end of p
    hybrid: HybridPart | None = None      # SX in terms of t, x, z, p
    n_variables: int = 0                  # names[:n_variables] are continuous-time variables
    bound: list[FlatVariable] = field(default_factory=list)   # parameters bound to others
    discrete_names: set[str] = field(default_factory=set)     # discrete-valued variables
    differentiated: set[str] = field(default_factory=set)     # variables x with der(x)
    aliases: dict[str, tuple[str, float]] = field(default_factory=dict)
    #: the SortedDAE it was built from (names the equations in diagnostics)
    sorted: object = field(default=None, repr=False, compare=False)
    #: Modelica initial equations as residuals in (t, x, z, p) and their descriptions
    #: (``initial equation TEXT [component]``); see :func:`attach_initial_equations`
    initial: ca.SX = field(default_factory=lambda: ca.SX(0, 1))
    initial_labels: list[str] = field(default_factory=list)
    #: parameters evaluated when compiling (name -> value): not settable
    evaluated: dict[str, float] = field(default_factory=dict)

    def __repr__(self) -> str:
        return (f"CasadiDAE({self.x.numel()} states, {self.z.numel()} algebraic, "
                f"{len(self.parameters)} parameters, {len(self.inputs)} inputs, "
                f"{len(self.names)} observed)")

    def parameter_values(self, p: np.ndarray) -> dict[str, float]:
        """Every parameter's value for the vector ``p``, bound ones included (a new dict)."""
        return dict(self.parameter_values_read(p))

    def parameter_values_read(self, p: np.ndarray) -> dict[str, float]:
        """:meth:`parameter_values` to read, not to change: the dict of the last ``p`` is
        remembered (a run asks for it several times)."""
        names = self.cache.get("parameter names")
        if names is None or names[0] is not self.parameters:
            names = self.cache["parameter names"] = (self.parameters,
                                                     [q.name for q in self.parameters])
        key = (self.parameters, self.bound, np.asarray(p, dtype=float).tobytes())
        last = self.cache.get("parameter values")
        if last is not None and last[0][0] is key[0] and last[0][1] is key[1] \
                and last[0][2] == key[2]:
            return last[1]
        out = self._parameter_values(p, names[1])
        self.cache["parameter values"] = (key, out)
        return out

    def _parameter_values(self, p: np.ndarray, names: list[str]) -> dict[str, float]:
        values = np.asarray(p, dtype=float).ravel()[:len(names)].tolist()
        out = dict(zip(names, values, strict=True))
        if self.bound:
            if "bound_values" not in self.cache:
                free = ca.vertcat(*[q.sx for q in self.parameters]) if self.parameters \
                    else ca.SX(0, 1)
                _, expr = resolved_bindings(self.bound)
                try:
                    self.cache["bound_values"] = ca.Function("bound", [free], [expr])
                except RuntimeError:      # bound to something else than free parameters
                    self.cache["bound_values"] = None
            f = self.cache["bound_values"]
            if f is not None:
                vals = np.asarray(f(p[:len(self.parameters)])).ravel()
                out.update({q.name: float(v) for q, v in zip(self.bound, vals, strict=True)})
        return out

    @property
    def initial_parameters(self) -> list[int]:
        """Positions in ``p`` of the parameters the initial equations determine (declared
        ``fixed=False``): unknowns of the initialization, constant afterwards."""
        return [k for k, q in enumerate(self.parameters) if not getattr(q.decl, "fixed", True)]

    @property
    def n_base(self) -> int:
        """Index of the first discrete slot in ``p`` (parameters and inputs come first)."""
        return len(self.parameters) + len(self.inputs)

    @property
    def p_default(self) -> np.ndarray:
        decls = map(_DECL, self.parameters)
        n = len(self.parameters) + len(self.inputs) + len(self.discretes)
        return np.fromiter(chain(map(float, map(_VALUE, decls)),
                                 map(float, map(_START, map(_DECL, self.inputs))),
                                 map(float, map(_START, map(_DECL, self.discretes)))),
                           dtype=float, count=n)

    def p_vector(self, overrides: dict[str, float] | None = None) -> np.ndarray:
        """Parameter-and-input vector with ``overrides`` applied (by dotted name)."""
        vec = self.p_default
        if overrides:
            names = [p.name for p in self.parameters] + [u.name for u in self.inputs] \
                + [d.name for d in self.discretes]
            where = {n: k for k, n in enumerate(names)}
            units = [v.decl.unit for v in (*self.parameters, *self.inputs, *self.discretes)]
            for key, value in overrides.items():
                if key in self.evaluated and _number(key, value) == self.evaluated[key]:
                    continue
                if key in self.evaluated:
                    raise evaluated_error(key, self.evaluated[key])
                if key not in where:
                    close = [n for n in names if n.split(".")[-1] == key.split(".")[-1]]
                    hint = f"; did you mean {', '.join(close[:5])}?" if close else ""
                    raise ParameterError(f"{key!r} is not a parameter or input of the "
                                         f"model{hint}")
                vec[where[key]] = _number(key, value, units[where[key]])
        return vec


def evaluated_error(name: str, value: float) -> ParameterError:
    """The error for setting a parameter that compiling replaced by its value."""
    return ParameterError(f"{name!r} was evaluated when compiling (its value {value:g} "
                          "removes a term from the equations); change it in the model and "
                          "compile again")


def _number(name: str, value: object, unit: str | None = None) -> float:
    """``value`` as a finite float; a string with a unit (``"2 kOhm"``) is converted to
    ``unit``, the declared unit of ``name``."""
    if isinstance(value, str):
        from ..core.units import quantity_value

        try:
            value = quantity_value(name, value, unit)
        except ValueError as err:
            raise UnitError(str(err)) from None
    try:
        out = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ParameterError(f"value for {name!r} is not a number: {value!r}") from None
    if not np.isfinite(out):
        raise ParameterError(f"value for {name!r} is not finite: {value!r}")
    return out


def resolved_bindings(bound: list[FlatVariable]) -> tuple[ca.SX, ca.SX]:
    """The symbols of the parameters ``bound`` to expressions and those expressions in terms
    of free parameters only: bindings may chain in any order (``L1 = L1sigma + M*n`` before
    ``M = Lm1/n``), so they are substituted into each other until none is left."""
    syms = ca.vertcat(*[q.sx for q in bound])
    values = ca.vertcat(*[ca.SX(q.decl.value) for q in bound])
    for _ in range(len(bound)):
        if not ca.depends_on(values, syms):
            break
        values = ca.substitute(values, syms, values)
    return syms, values


def build_dae(sorted_dae: SortedDAE) -> CasadiDAE:
    """Assemble the CasADi DAE of a sorted model."""
    model = sorted_dae.model
    variables = model.variables
    states = sorted_dae.states
    alg_vars = sorted_dae.algebraic

    bound = [p for p in model.parameters if type(p.decl.value) is not float
             and isinstance(p.decl.value, ca.SX)]
    free_params = [p for p in model.parameters if not isinstance(p.decl.value, ca.SX)] \
        if bound else list(model.parameters)

    # columns are taken from the model's stacked symbols: no scalar restacking
    column = model.stacked_variables()
    assigned = [j for j, _ in sorted_dae.assignments]
    # what we need in terms of knowns: state derivatives, residuals, every variable
    hybrid = model.hybrid
    extra = hybrid.expressions() if hybrid is not None else []
    targets = ca.vertcat(take(column, [variables[j].der for j in states]),
                         *sorted_dae.residuals, column, *extra)
    n_obs = len(variables)
    if assigned:
        _, (targets,) = ca.substitute_inplace([take(column, assigned)],
                                              [sorted_dae.stacked_definitions()],
                                              [targets], False)
    if bound:
        bsym, bdef = resolved_bindings(bound)
        targets = ca.substitute(targets, bsym, bdef)
    n_x, n_r = len(states), len(sorted_dae.residuals)
    if targets.numel() <= CSE_UP_TO:
        targets = ca.cse(targets)
    ode = targets[:n_x]
    alg = targets[n_x:n_x + n_r]
    observed = targets[n_x + n_r:n_x + n_r + n_obs]
    if hybrid is not None:
        rest = targets[n_x + n_r + n_obs:]
        hybrid = hybrid.with_expressions([rest[k] for k in range(rest.numel())])
    shown = [d for d in model.discretes if not d.name.startswith(("$", "pre(", "initial()",
                                                                  "terminal()"))]
    if shown:
        observed = ca.vertcat(observed, *[d.sx for d in shown])

    names = [v.name for v in variables] + [d.name for d in shown]
    observed_index = {n: k for k, n in enumerate(names)}
    # a discrete variable's start value is its pre() value before the first event, not a
    # condition on the continuous initial state
    fixed = [(k, float(v.decl.start)) for k, v in enumerate(variables)
             if v.der_of < 0 and getattr(v.decl, "fixed", False) and v.decl.kind != "discrete"]
    p = ca.vertcat(model.stacked_parameters() if not bound else
                   ca.vertcat(*[q.sx for q in free_params]), *[u.sx for u in model.inputs],
                   *[d.sx for d in model.discretes])
    return CasadiDAE(
        x=take(column, list(states)),
        z=take(column, list(alg_vars)),
        p=p if p.numel() else ca.SX(0, 1), t=TIME.sx, ode=ode, alg=alg, observed=observed,
        names=names, state_names=[variables[j].name for j in states],
        algebraic_names=[variables[j].name for j in alg_vars],
        parameters=free_params, inputs=list(model.inputs),
        x_start=np.array([_start(variables[j]) for j in states], dtype=float),
        z_start=np.array([_start(variables[j]) for j in alg_vars], dtype=float),
        fixed=fixed, observed_index=observed_index, discretes=list(model.discretes),
        hybrid=hybrid, n_variables=len(variables), bound=bound,
        discrete_names={v.name for v in variables if _discrete_valued(v.decl)}
        | {d.name for d in shown},
        differentiated={v.name for v in variables if v.der >= 0}, aliases=dict(model.aliases),
        sorted=sorted_dae)


def _start(v: FlatVariable) -> float:
    return float(getattr(v.decl, "start", 0.0))


def attach_initial_equations(dae: CasadiDAE, model) -> None:
    """Set ``dae.initial`` from ``model.initial_equations`` (a :class:`FlatModel` after alias
    elimination, or the index-reduced one: both hold the same variable symbols): every
    variable is replaced by its observation in (t, x, z, p), bound parameters by their
    values."""
    eqs = getattr(model, "initial_equations", None) or []
    if not eqs:
        return
    res = ca.vertcat(*[e.residual for e in eqs])
    n_var = dae.n_variables or len(dae.names)
    vsyms = dae.sorted.model.stacked_variables() if dae.sorted is not None else ca.SX(0, 1)
    if vsyms.numel() != n_var:
        raise RuntimeError("initial equations: variables and observations do not match")
    obs = dae.observed[:n_var]
    res = ca.substitute([res], [vsyms], [obs])[0] if vsyms.numel() else res
    if dae.bound:
        for _ in range(len(dae.bound)):               # bindings may chain
            bsym = ca.vertcat(*[q.sx for q in dae.bound])
            if not ca.depends_on(res, bsym):
                break
            res = ca.substitute(res, bsym, ca.vertcat(*[ca.SX(q.decl.value) for q in dae.bound]))
    dae.initial = res
    dae.initial_labels = [e.origin for e in eqs]


def _discrete_valued(decl: object) -> bool:
    """Whether a variable changes at events only: discrete, or an Integer or Boolean signal."""
    return decl.kind == "discrete" or (decl.kind in ("input", "output")
                                       and getattr(decl, "type_name", "Real") != "Real")
