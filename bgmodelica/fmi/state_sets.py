"""Export of models that need dynamic state selection (the Cartesian pendulum).

Index reduction leaves a choice of states whose validity changes with the motion
(:mod:`bgmodelica.dynamic_selection`). The FMU carries every candidate choice (a *variant*:
the model recompiled with that selection) and switches between them at events, with the
event runtime of :mod:`bgmodelica.fmi.hybrid`:

* the variants are the base compilation and every choice the native pivot test can select
  (found by the native test at sampled points), at most :data:`MAX_VARIANTS`;
* the discrete slot ``_stateSet.selection`` holds the active variant; every generated function
  (model, event step, indicator) dispatches on it (``casadi.Function.conditional``);
* the continuous states are ``_stateSet.x[1..n]``: the states of the active variant, so their
  meaning changes when the variant does (the variable descriptions list them per variant);
  every model variable is exported as an output or a local whatever the variant;
* one state-event indicator: ``score(active) - threshold * max(score)``, where a score is the
  product over dummy-derivative levels of the pivot determinants (native: ``_score``); it
  crosses zero when the active choice degrades below ``threshold`` times the best;
* at that event the best variant becomes active: the states take the values of its state
  variables from the full variable values before the switch (the native consistent
  re-initialisation), the Model Exchange importer sees ``valuesOfContinuousStatesChanged``;
  the nominals are those of the slots (1 unless every candidate declares one) and do not
  change; a bad choice at the start time switches in the initial event iteration;
* the algebraic variables of each variant are solved by Newton from guesses kept in discrete
  slots, refreshed after every completed integrator step and at every switch (so the solution
  stays on the branch it follows: the pendulum's ``x = +-sqrt(L^2 - y^2)``).
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from ..backends.casadi_init import initialize
from ..compiler import CompiledModel, recompile
from ..dynamic_selection import StateSelector
from .hybrid import DiscreteVariable, HybridSpec
from .spec import FmuSpec, FmuSpecError, ScalarVariable

MAX_VARIANTS = 16
THRESHOLD = 0.3          # the native StateSelector's switching threshold
SLOT_PREFIX = "_stateSet"


def _observed(dae, x, z, p, t: float = 0.0) -> np.ndarray:
    f = ca.Function("observed", [dae.t, dae.x, dae.z, dae.p], [dae.observed])
    return np.asarray(f(t, x, z, p), dtype=float).ravel()


def start_variant(sel: StateSelector) -> CompiledModel:
    """The selection the native simulation starts with (``_initial_selection``): the pivot
    test at the base compilation's initial point, undefined values taken at their starts."""
    base = sel.base
    dae = base.dae
    init = initialize(dae, dae.p_default)
    with np.errstate(all="ignore"):
        values = _observed(dae, init.x0, init.z0, dae.p_default)[:dae.n_variables]
    bad = ~np.isfinite(values)
    if bad.any():
        starts = [float(getattr(v.decl, "start", 0.0)) for v in base.reduced.model.variables]
        values[bad] = np.asarray(starts)[bad]
    return sel.check(base, values, dae.p_default, 0.0)


def variants(compiled: CompiledModel, samples: int = 400, seed: int = 0
             ) -> list[CompiledModel]:
    """The selection the native simulation starts with, then the base compilation and every
    other selection the native pivot test picks as best at ``samples`` random points
    (deterministic)."""
    sel = StateSelector(compiled)
    first = start_variant(sel)
    out = {sel.key(first.reduced.dummies): first, sel.key(compiled.reduced.dummies): compiled}
    rng = np.random.default_rng(seed)
    n = len(compiled.reduced.model.variables)
    p = compiled.dae.p_default
    for _ in range(samples):
        _, _, dummies, levels = sel.assess(compiled, rng.uniform(-2.0, 2.0, n), p,
                                           float(rng.uniform()))
        key = sel.key(dummies)
        if key in out:
            continue
        if len(out) >= MAX_VARIANTS:
            raise FmuSpecError(f"cannot export {compiled.name}: more than {MAX_VARIANTS} "
                               "state selections; choose states with state_select")
        choice = {lvl: chosen for lvl, (_, _, chosen) in enumerate(levels, start=1)}
        out[key] = recompile(compiled, lambda lvl, r, c, d, ch=choice: ch.get(lvl, d))
    return list(out.values())


def _scores(compiled: CompiledModel, levels: list) -> ca.Function:
    """``(values of all variables, native p, t) -> score of each selection``."""
    model = compiled.reduced.model
    syms = ca.vertcat(*[v.sx for v in model.variables])
    res = ca.vertcat(*[e.residual for e in model.equations])
    jac = ca.jacobian(res, syms)
    bound = [q for q in model.parameters if isinstance(q.decl.value, ca.SX)]
    for _ in range(len(bound)):
        if not bound or not ca.depends_on(jac, ca.vertcat(*[q.sx for q in bound])):
            break
        jac = ca.substitute(jac, ca.vertcat(*[q.sx for q in bound]),
                            ca.vertcat(*[ca.SX(q.decl.value) for q in bound]))
    free = [q for q in model.parameters if not isinstance(q.decl.value, ca.SX)]
    p_vec = ca.vertcat(*[q.sx for q in free], *[u.sx for u in model.inputs])
    from ..core.variables import TIME

    out = []
    for lv in levels:
        s = ca.SX(1.0)
        for rows, _cands, chosen in lv:
            s = s * ca.fabs(ca.det(jac[rows, chosen]))
        out.append(s)
    return ca.Function("pivot_scores", [syms, p_vec, TIME.sx], [ca.vertcat(*out)])


def _is_best(scores: ca.MX, j: int) -> ca.MX:
    """1 when selection ``j`` has the largest score (the first of equal ones), else 0."""
    flag = ca.MX(1.0)
    for i in range(scores.numel()):
        if i < j:
            flag = flag * (scores[j] > scores[i])
        elif i > j:
            flag = flag * (scores[j] >= scores[i])
    return flag


class StateSetExport:
    """The FMU functions and variables of a model with dynamic state selection (see the
    module docstring). ``names``: the exported model variables (outputs first)."""

    def __init__(self, compiled: CompiledModel, names: list[str],
                 newton_tolerance: float = 1e-12) -> None:
        if compiled.dae.hybrid is not None:
            raise FmuSpecError(f"cannot export {compiled.name}: dynamic state selection and "
                               "events in one FMU are not supported; give states valid "
                               "everywhere with state_select")
        self.compiled = compiled
        self.variants = variants(compiled)
        self.names = names
        self.tol = newton_tolerance
        base = compiled.dae
        self.nx = base.x.numel()
        self.nu, self.np = len(base.inputs), len(base.parameters)
        self.n_var = len(self.variants)
        # discrete slots: selection, relation "pivots ok", initial(), z guesses per variant
        self.z_slot: list[list[int]] = []
        k = 3
        for v in self.variants:
            nz = v.dae.z.numel()
            self.z_slot.append(list(range(k, k + nz)))
            k += nz
        self.nd = k
        self.score_fn = _scores(compiled, [v.reduced.levels for v in self.variants])
        self._build()

    # ------------------------------------------------------------------ symbolic parts
    def _variant_parts(self, k: int, t, x, u, p, d):
        """(xdot, y, values of all variables, z) of variant ``k`` at (t, x, u, p, d)."""
        dae = self.variants[k].dae
        pfull = ca.vertcat(p, u)
        if dae.z.numel():
            g = ca.Function("g", [dae.z, ca.vertcat(dae.t, dae.x, dae.p)], [dae.alg])
            solver = ca.rootfinder(f"loops{k}", "fast_newton", g,
                                   {"abstol": self.tol, "max_iter": 50})
            guess = ca.vertcat(*[d[s] for s in self.z_slot[k]])
            z = solver(guess, ca.vertcat(t, x, pfull))
        else:
            z = ca.MX(0, 1)
        nv = dae.n_variables
        obs = ca.Function("obs", [dae.t, dae.x, dae.z, dae.p],
                          [dae.ode, dae.observed])(t, x, z, pfull)
        xdot, observed = obs
        y = ca.vertcat(*[observed[dae.observed_index[n]] for n in self.names])
        return xdot, y, observed[:nv], z, observed

    def _build(self) -> None:
        t = ca.MX.sym("t")
        x = ca.MX.sym("x", self.nx)
        u = ca.MX.sym("u", self.nu)
        p = ca.MX.sym("p", self.np)
        d = ca.MX.sym("d", self.nd)
        args, an = [t, x, u, p, d], ["t", "x", "u", "p", "d"]
        odes, steps, inds = [], [], []
        for k, var in enumerate(self.variants):
            xdot, y, values, z, observed = self._variant_parts(k, t, x, u, p, d)
            scores = self.score_fn(values, ca.vertcat(p, u), t)
            g = scores[k] - THRESHOLD * ca.mmax(scores)
            ok, init = d[1], d[2]
            best = [_is_best(scores, j) for j in range(self.n_var)]
            cond = ca.vertcat(*[(1 - ok) * b for b in best],
                              *[init * (1 - ok) * b for b in best])
            idx = var.dae.observed_index
            assign, reinit = [], []
            for j, other in enumerate(self.variants):
                assign += [ca.MX(float(j))]
                assign += [observed[idx[n]] for n in other.dae.algebraic_names]
                reinit += [observed[idx[n]] for n in other.dae.state_names]
            pre = [z[i] if j == k else d[s]
                   for j in range(self.n_var) for i, s in enumerate(self.z_slot[j])]
            odes.append(ca.Function(f"ode{k}", args, [xdot, y]))
            steps.append(ca.Function(
                f"evstep{k}", args,
                [g, ca.MX(0.0), cond, ca.vertcat(*assign), ca.vertcat(*reinit),
                 ca.vertcat(*pre) if pre else ca.MX(0, 1), d[0]]))
            inds.append(ca.Function(f"evind{k}", args, [g]))
        self.ode = _dispatch("ode", odes, args, an, ["xdot", "y"])
        self.step = _dispatch("evstep", steps, args, an,
                              ["g", "dgdt", "cond", "assign", "reinit", "pre", "dv"])
        self.indicators = _dispatch("evind", inds, args, an, ["z"])
        self.samples = ca.Function("evsamp", args, [ca.MX(0, 1)], an, ["samples"])

    # ------------------------------------------------------------------ spec parts
    def init_function(self) -> ca.Function | None:
        """``(t, u, p, d) -> x0`` of the first variant when the initial state follows from
        conditions through the equations (as :func:`~bgmodelica.fmi.from_model.fmu_spec`)."""
        from ..backends.casadi_init import initial_state_function

        first = self.variants[0].dae
        f0 = initial_state_function(first, first.p_default)
        if f0 is None:
            return None
        t, u = ca.MX.sym("t"), ca.MX.sym("u", self.nu)
        p, d = ca.MX.sym("p", self.np), ca.MX.sym("d", self.nd)
        return ca.Function("init", [t, u, p, d], [f0(t, ca.vertcat(p, u))],
                           ["t", "u", "p", "d"], ["x0"])

    def start(self) -> tuple[np.ndarray, list[float]]:
        """Consistent initial states of the first variant and the start of the slots."""
        first = self.variants[0].dae
        init = initialize(first, first.p_default)
        values = dict(zip(first.names, _observed(first, init.x0, init.z0, first.p_default),
                          strict=True))
        d = [0.0, 1.0, 0.0]
        for v in self.variants:
            d += [values.get(n, 0.0) for n in v.dae.algebraic_names]
        return np.asarray(init.x0, dtype=float), d

    def states(self, x0: np.ndarray) -> list[ScalarVariable]:
        out = []
        for i in range(self.nx):
            which = ", ".join(f"{v.dae.state_names[i]} ({k})"
                              for k, v in enumerate(self.variants))
            out.append(ScalarVariable(f"{SLOT_PREFIX}.x[{i + 1}]", float(x0[i]),
                                      description=f"state slot {i + 1}: {which} (selection)"))
        return out

    def hybrid(self, d_start: list[float]) -> HybridSpec:
        nvar = self.n_var
        assigns, reinits = [], []
        apos = rpos = 0
        per = []
        for j in range(self.n_var):
            a = [(0, apos)] + [(s, apos + 1 + i) for i, s in enumerate(self.z_slot[j])]
            r = [(i, 1.0, rpos + i) for i in range(self.nx)]
            apos += 1 + len(self.z_slot[j])
            rpos += self.nx
            per.append((a, r))
        for _ in range(2):
            for a, r in per:
                assigns.append(a)
                reinits.append(r)
        z_names = [f"{SLOT_PREFIX}.guess[{j}].{n}" for j, v in enumerate(self.variants)
                   for n in v.dae.algebraic_names]
        pre = [(s, False, z_names[i]) for i, s in
               enumerate(s for slots in self.z_slot for s in slots)]
        return HybridSpec(
            d_names=[f"{SLOT_PREFIX}.selection", f"{SLOT_PREFIX}.pivots", "initial()"]
            + z_names,
            d_start=list(d_start),
            relations=[f"pivots of the selected states >= {THRESHOLD:g} x the best"],
            rel_slot=[1], rel_strict=[True], state_rel=[0], time_rel=[],
            whens=[list(range(nvar)), list(range(nvar, 2 * nvar))],
            assigns=assigns, reinits=reinits, pre=pre, sample_slots=[], tables=[],
            initial_slot=2, terminal_slot=-1,
            discretes=[DiscreteVariable(
                f"{SLOT_PREFIX}.selection", "Integer", None,
                description="active state selection (see the descriptions of the state "
                            "slots)")],
            step=self.step, indicators=self.indicators, samples=self.samples,
            track_pre=True)


def _dispatch(name: str, fs: list[ca.Function], args, arg_names, out_names) -> ca.Function:
    """``fs[round(d[0])]`` called on ``args`` (the last argument is ``d``)."""
    sw = ca.Function.conditional(f"{name}_switch", fs, fs[0])
    d = args[-1]
    outs = sw(ca.floor(d[0] + 0.5), *args)
    outs = outs if isinstance(outs, (list, tuple)) else [outs]
    return ca.Function(name, args, list(outs), arg_names, out_names)


def state_set_spec(compiled: CompiledModel, *, stop_time: float = 1.0,
                   step_size: float | None = None, tolerance: float = 1e-6,
                   newton_tolerance: float = 1e-12) -> FmuSpec:
    """The :class:`FmuSpec` of a model that needs dynamic state selection (see the module
    docstring): every model variable an output or a local, the state slots as states."""
    from ..core.variables import KIND_OUTPUT
    from .from_model import _bounds, model_identifier, parameters_and_inputs

    flat = compiled.reduced.model
    dae = compiled.dae
    by_name = {v.name: v for v in flat.variables}
    outputs = [v.name for v in flat.variables
               if v.decl.kind == KIND_OUTPUT and v.component == "" and v.der_of < 0]
    locals_ = [n for n in dae.names[:dae.n_variables]
               if by_name[n].der_of < 0 and n not in outputs]
    aliases = [a for a, (rep, _) in sorted(flat.aliases.items())
               if rep in dae.observed_index and by_name[rep].der_of < 0
               and not a.startswith("der(")]
    names = outputs + locals_
    exp = StateSetExport(compiled, names + aliases, newton_tolerance)
    x0, d0 = exp.start()
    hyb = exp.hybrid(d0)
    p_all = dae.p_default
    n_par = len(dae.parameters)
    y0 = np.asarray(exp.ode(0.0, x0, p_all[n_par:], p_all[:n_par], d0)[1]).ravel()

    def scalar(name: str, start: float) -> ScalarVariable:
        rep, sign = flat.aliases.get(name, (name, 1.0))
        decl = by_name[rep].decl
        lo, hi = _bounds(decl, rep, "variable")
        if sign < 0:
            lo, hi = (None if hi is None else -hi), (None if lo is None else -lo)
        return ScalarVariable(name, float(start), getattr(decl, "unit", "") or "",
                              getattr(decl, "description", "") or "", min=lo, max=hi)

    all_names = names + aliases
    values = dict(zip(all_names, y0, strict=True))
    params, inputs = parameters_and_inputs(dae, p_all)
    name = model_identifier(compiled.name)
    return FmuSpec(model_name=name, description=f"{compiled.name} (bgmodelica)",
                   states=exp.states(x0), inputs=inputs, parameters=params,
                   outputs=[scalar(n, values[n]) for n in outputs],
                   locals=[scalar(n, values[n]) for n in locals_ + aliases],
                   ode=exp.ode, init=exp.init_function(), stop_time=stop_time,
                   step_size=step_size, tolerance=tolerance, hybrid=hyb)
