"""Diagnosis of non-finite values (NaN, Inf) at a point of a simulation: which variable became
non-finite first, through which operation (division by zero, log or sqrt of a negative
number...) of which equation, with the values that caused it.

Used at the initial point (before the integrator sees a NaN and fails with a generic message)
and on results (the first time and variable that is not finite).
"""

from __future__ import annotations

import math
from typing import Any

import casadi as ca
import numpy as np

from .core.variables import TIME
from .errors import InitializationError, SimulationError

_HINTS = {
    "OP_DIV": "division by zero", "OP_INV": "division by zero",
    "OP_LOG": "log of a number <= 0", "OP_LOG1P": "log1p of a number <= -1",
    "OP_SQRT": "square root of a negative number",
    "OP_POW": "power of a negative number or of zero", "OP_CONSTPOW": "power of a negative "
    "number or of zero", "OP_ASIN": "asin outside [-1, 1]", "OP_ACOS": "acos outside [-1, 1]",
    "OP_ATANH": "atanh outside (-1, 1)", "OP_ACOSH": "acosh below 1", "OP_TAN": "tan at a pole",
    "OP_EXP": "exp overflow", "OP_SINH": "sinh overflow", "OP_COSH": "cosh overflow",
    "OP_MUL": "0 * inf or overflow", "OP_ADD": "inf - inf or overflow",
    "OP_SUB": "inf - inf or overflow", "OP_FMOD": "fmod by zero",
}
_OPS = {getattr(ca, k): v for k, v in _HINTS.items() if hasattr(ca, k)}


def _kind(v: float) -> str:
    return "NaN" if math.isnan(v) else ("+Inf" if v > 0 else "-Inf")


class _Layout:
    """The symbols a :class:`_Point` gives values to, in order: the sorted model's variables,
    the parameters, inputs and discretes of ``p`` (its first ``n_p`` entries), the
    parameters bound to others, time. Made once per model (kept in ``dae.cache``)."""

    def __init__(self, dae: Any, n_p: int) -> None:
        self.model = dae.sorted.model
        self.names = self.model.names()
        self.variables = [v.name for v in self.model.variables]
        syms = [v.sx for v in self.model.variables]
        base = list(dae.parameters) + list(dae.inputs) + list(getattr(dae, "discretes", ()))
        self.n_base = min(len(base), n_p)
        syms += [q.sx for q in base[:self.n_base]]
        self.bound = [q for q in self.model.parameters if isinstance(q.decl.value, ca.SX)]
        for q in self.bound:
            syms.append(q.sx)
            self.names[q.sx.element_hash()] = q.name
        syms.append(TIME.sx)
        self.names[TIME.sx.element_hash()] = "time"
        self.syms = syms
        self.X = ca.vertcat(*syms)
        # where each variable's value is in the observed vector (-1: not observed)
        n = min(getattr(dae, "n_variables", 0) or len(dae.names), len(dae.names))
        at = {name: k for k, name in enumerate(dae.names[:n])}
        self.source = np.array([at.get(name, -1) for name in self.variables], dtype=np.int64)

    @staticmethod
    def of(dae: Any, n_p: int) -> _Layout:
        key = ("bgm_point_layout", n_p)
        found = dae.cache.get(key)
        if found is None:
            found = dae.cache[key] = _Layout(dae, n_p)
        return found

    def values(self, dae: Any, variables: np.ndarray, p: np.ndarray, t: float) -> np.ndarray:
        """The values of :attr:`syms` given those of the variables (in model order)."""
        from .value_checks import _bound_values

        bound = [math.nan if v is None else v
                 for v in _bound_values(dae, self.bound, p)] if self.bound else []
        return np.concatenate([np.asarray(variables, dtype=float), p[:self.n_base],
                               np.asarray(bound, dtype=float), [float(t)]])

    def observed_values(self, dae: Any, obs: np.ndarray, p: np.ndarray,
                        t: float) -> np.ndarray:
        """The values of :attr:`syms` with the variables read from the observed vector."""
        obs = np.asarray(obs, dtype=float)
        src = self.source
        ok = (src >= 0) & (src < len(obs))
        got = np.full(len(src), math.nan)
        got[ok] = obs[src[ok]]
        return self.values(dae, got, p, t)


class _Point:
    """Values of every symbol of a sorted model at one point, and evaluation of expressions."""

    def __init__(self, dae: Any, values: dict[str, float], p: np.ndarray, t: float,
                 vals: np.ndarray | None = None) -> None:
        """``vals``: the values of the layout's symbols when already known."""
        p = np.asarray(p, dtype=float)
        layout = _Layout.of(dae, len(p))
        self.model = layout.model
        self.names = layout.names
        if vals is None:
            got = [float(values.get(n, math.nan)) for n in layout.variables]
            vals = layout.values(dae, np.asarray(got, dtype=float), p, t)
        self.syms = layout.syms
        self.X = layout.X
        self.vals = vals
        self.value_of = {s.element_hash(): v
                         for s, v in zip(layout.syms, vals.tolist(), strict=True)}
        self.t = float(t)

    def eval(self, exprs: list[ca.SX]) -> np.ndarray:
        if not exprs:
            return np.zeros(0)
        f = ca.Function("bgm_diag", [self.X], [ca.vertcat(*exprs)], {"allow_free": True}) \
            if _ALLOW_FREE else ca.Function("bgm_diag", [self.X], [ca.vertcat(*exprs)])
        with np.errstate(all="ignore"):
            return np.asarray(f(self.vals), dtype=float).ravel()

    def text(self, e: ca.SX, width: int = 90) -> str:
        syms = [s for s in ca.symvar(e) if s.element_hash() in self.names]
        if syms:
            e = ca.substitute(e, ca.vertcat(*syms),
                              ca.vertcat(*[ca.SX.sym(self.names[s.element_hash()])
                                           for s in syms]))
        out = str(e)
        return out if len(out) <= width else out[: width - 3] + "..."

    def leaves(self, e: ca.SX, limit: int = 6) -> str:
        parts = []
        for s in ca.symvar(e)[:limit]:
            h = s.element_hash()
            if h in self.value_of and h in self.names:
                parts.append(f"{self.names[h]} = {self.value_of[h]:g}")
        return ", ".join(parts)


def _allow_free() -> bool:
    try:
        x = ca.SX.sym("x")
        ca.Function("f", [x], [x], {"allow_free": True})
        return True
    except RuntimeError:
        return False


_ALLOW_FREE = _allow_free()


def _nodes(e: ca.SX, limit: int = 400) -> list[ca.SX]:
    """Operation nodes of ``e`` in post order (children first), unique, at most ``limit``."""
    out: list[ca.SX] = []
    seen: set[int] = set()
    stack: list[tuple[ca.SX, bool]] = [(e, False)]
    while stack and len(out) < limit:
        node, done = stack.pop()
        h = node.element_hash()
        if node.is_leaf() or (h in seen and not done):
            continue
        if done:
            if h not in seen:
                seen.add(h)
                out.append(node)
            continue
        stack.append((node, True))
        stack.extend((node.dep(i), False) for i in range(node.n_dep()))
    return out


def _operation(pt: _Point, e: ca.SX) -> str:
    """The first operation of ``e`` giving a non-finite value from finite operands."""
    nodes = _nodes(e)
    if not nodes:
        return ""
    vals = pt.eval(nodes)
    index = {n.element_hash(): k for k, n in enumerate(nodes)}

    def value(x: ca.SX) -> float:
        if x.is_constant():
            return float(ca.DM(x))
        h = x.element_hash()
        if h in index:
            return float(vals[index[h]])
        return float(pt.value_of.get(h, math.nan))

    for k, node in enumerate(nodes):
        if math.isfinite(vals[k]):
            continue
        deps = [node.dep(i) for i in range(node.n_dep())]
        if all(math.isfinite(value(d)) for d in deps):
            hint = next((h for op, h in _OPS.items() if node.is_op(op)), "")
            what = pt.text(node, 60)
            where = pt.leaves(node)
            return (f"{hint}: " if hint else "") + f"{what} = {_kind(vals[k])}" \
                + (f" with {where}" if where else "")
    return ""


def explain(dae: Any, values: dict[str, float], p: np.ndarray, t: float) -> str:
    """Why some variable is not finite at time ``t`` given the values of every variable:
    the first variable (in evaluation order) computed from finite values that is not
    finite, its operation and its equation; "" when it cannot be told."""
    if getattr(dae, "sorted", None) is None:
        return ""
    pt = _Point(dae, values, p, t)
    srt = dae.sorted
    model = pt.model
    variables = model.variables
    eq_vars = srt.reduced.graph.eq_vars
    finite = [math.isfinite(v) for v in pt.vals[:len(variables)]]
    # 1) an equation undefined although every variable in it is finite
    residuals = pt.eval([e.residual for e in model.equations])
    for k, r in enumerate(residuals):
        if not math.isfinite(r) and all(finite[j] for j in eq_vars[k] if j < len(finite)):
            op = _operation(pt, model.equations[k].residual)
            return (f"equation {model.describe(k)} is {_kind(r)} at t = {pt.t:g} s"
                    + (f" ({op})" if op else ""))
    # 2) the first assignment computing a non-finite value from finite ones
    exprs = [d for _, d in srt.assignments]
    got = pt.eval(exprs)
    for (j, expr), val in zip(srt.assignments, got, strict=True):
        if math.isfinite(val):
            continue
        ins = [s.element_hash() for s in ca.symvar(expr)]
        if not all(math.isfinite(pt.value_of.get(h, math.nan)) for h in ins):
            continue
        name = variables[j].name
        op = _operation(pt, expr)
        eq = next((k for k, row in enumerate(eq_vars) if j in row
                   and all(finite[i] for i in row if i != j and i < len(finite))), None)
        return (f"{name} = {pt.text(expr)} is {_kind(val)} at t = {pt.t:g} s"
                + (f" ({op})" if op else "")
                + (f", from the equation {model.describe(eq)}" if eq is not None else ""))
    return ""


# -- checks --------------------------------------------------------------------------------------

def _point_function(dae: Any) -> Any:
    """``(t, x, z, p) -> (ode, alg, observed)``, dense, with bound buffers
    (:class:`~bgmodelica.events.fast.Fast`, made once per model)."""
    from .events.fast import Fast

    key = ("bgm_point", dae.x.numel(), dae.z.numel(), dae.p.numel())
    f = dae.cache.get(key)
    if f is None:
        f = dae.cache[key] = Fast(ca.Function(
            "bgm_point", [dae.t, dae.x, dae.z, dae.p],
            [ca.densify(e) for e in (dae.ode, dae.alg, dae.observed)]))
    return f


def check_initial_point(dae: Any, x0: Any, z0: Any, p: Any, t0: float) -> None:
    """Raise :class:`InitializationError` naming the equation and variable when the model is
    undefined (NaN/Inf) at its initial point (``x0``, ``z0``)."""
    f = _point_function(dae)
    x0 = np.asarray(x0, dtype=float).reshape(-1)
    z0 = np.asarray(z0, dtype=float).reshape(-1)
    with np.errstate(all="ignore"):
        ode, alg, obs = (v.copy() for v in f(t0, x0 if dae.x.numel() else np.zeros(0),
                                            z0 if dae.z.numel() else np.zeros(0),
                                            np.asarray(p, dtype=float).ravel()))
    if np.all(np.isfinite(ode)) and np.all(np.isfinite(alg)) and np.all(np.isfinite(obs)):
        _check_residuals(dae, obs, p, t0)
        return
    why = explain(dae, _values(dae, obs), p, t0)
    if not why:
        bad = [dae.names[k] for k in np.flatnonzero(~np.isfinite(obs))][:5] \
            or [f"der({dae.state_names[k]})" for k in np.flatnonzero(~np.isfinite(ode))][:5] \
            or [f"residual of {dae.algebraic_names[k]}"
                for k in np.flatnonzero(~np.isfinite(alg)) if k < len(dae.algebraic_names)][:5]
        why = f"{', '.join(bad) or 'the model'} not finite at t = {t0:g} s"
    raise InitializationError(f"the model is undefined at the initial point: {why}; check the "
                              "parameter and start values")


def _values(dae: Any, obs: np.ndarray) -> dict[str, float]:
    """The variables' values by name, read from the observed vector ``obs``."""
    n_var = getattr(dae, "n_variables", 0) or len(dae.names)
    return {n: float(v) for n, v in zip(dae.names[:n_var], obs, strict=False)}


def _check_residuals(dae: Any, obs: np.ndarray, p: Any, t0: float) -> None:
    """Every equation defined at a finite initial point (``obs``: the observed variables
    there): a solved form can hide an undefined one (``e1 = m*e2`` with ``m = l1/0`` gives
    ``e2 = e1/m = 0``)."""
    srt = getattr(dae, "sorted", None)
    if srt is None:
        return
    p = np.asarray(p, dtype=float)
    layout = _Layout.of(dae, len(p))
    f = dae.cache.get("bgm_residuals")
    if f is None:
        from .events.fast import Fast

        known = {s.element_hash() for s in layout.syms}
        rows = [k for k, e in enumerate(srt.model.equations)
                if all(s.element_hash() in known for s in ca.symvar(e.residual))]
        out = ca.vertcat(*[srt.model.equations[k].residual for k in rows]) if rows \
            else ca.SX(0, 1)
        f = dae.cache["bgm_residuals"] = (
            Fast(ca.Function("bgm_res", [layout.X], [ca.densify(out)])), rows)
    fn, rows = f
    vals = layout.observed_values(dae, obs, p, t0)
    with np.errstate(all="ignore"):
        res = fn(vals)[0]
    if np.all(np.isfinite(res)):
        return
    pt = _Point(dae, {}, p, t0, vals)
    k = rows[int(np.flatnonzero(~np.isfinite(res))[0])]
    op = _operation(pt, srt.model.equations[k].residual) or _constant(
        srt.model.equations[k].residual)
    raise InitializationError(
        f"the model is undefined at the initial point: equation {srt.model.describe(k)} is "
        f"{_kind(float(res[rows.index(k)]))} at t = {t0:g} s" + (f" ({op})" if op else "")
        + "; check the parameter and start values")


def _constant(e: ca.SX) -> str:
    """A non-finite constant of ``e`` (what a parameter expression such as ``l1/0`` folds
    to), as text; "" when there is none."""
    stack, seen = [e], 0
    while stack and seen < 2000:
        node = stack.pop()
        seen += 1
        if node.is_constant():
            v = float(ca.DM(node))
            if not math.isfinite(v):
                return (f"a term is the constant {v}: a modulus or parameter expression of "
                        "this element is not finite")
        elif not node.is_leaf():
            stack.extend(node.dep(i) for i in range(node.n_dep()))
    return ""


def check_result(result: Any, dae: Any, p: Any) -> None:
    """Raise :class:`SimulationError` naming the first variable and time at which ``result``
    is not finite; the error's ``result`` keeps the rows before that time."""
    vals = result.values
    if vals.size == 0:
        return
    with np.errstate(all="ignore"):
        ok = np.isfinite(vals)
    if ok.all():
        return
    row = int(np.argmax(~ok.all(axis=1)))
    cols = np.flatnonzero(~ok[row])
    names = [result.names[c] for c in cols]
    t_bad = float(result.time[row])
    first = f"{names[0]} is {_kind(float(vals[row, cols[0]]))} at t = {t_bad:g} s"
    if len(names) > 1:
        first += f" (also {', '.join(names[1:4])}{', ...' if len(names) > 4 else ''})"
    why = ""
    try:
        values = {n: float(v) for n, v in zip(result.names, vals[row], strict=True)}
        why = explain(dae, values, p, t_bad)
    except Exception:       # a diagnosis must not hide the error itself  # noqa: BLE001
        why = ""
    from dataclasses import replace

    kept = replace(result, time=result.time[:row], data=vals[:row])
    t_ok = float(result.time[row - 1]) if row else float(result.time[0])
    raise SimulationError(
        f"{first}" + (f": {why}" if why else "")
        + (f". The result is kept up to t = {t_ok:g} s (last finite point)" if row else
           "; check the parameter and start values"), t_ok, kept)


def singular_linear_block(residuals: list, unknowns: list, tries: int = 2,
                          discrete: frozenset[int] = frozenset()) -> bool:
    """Whether the block ``residuals = 0``, linear in ``unknowns``, is singular for every
    value of the other symbols (its Jacobian is rank-deficient at random points): equations
    that structural analysis matched but that are linearly dependent (ideal sources in a
    loop or a cut, a state fixed by a constraint that index reduction could not see).

    Symbols whose element hash is in ``discrete`` (Booleans, modes, relation values) take
    random 0/1 values: a block singular in some combination of modes only (one the discrete
    equations never produce) is not singular for every value."""
    if not unknowns:
        return False
    r, v = ca.vertcat(*residuals), ca.vertcat(*unknowns)
    a = ca.jacobian(r, v)
    n = v.numel()
    syms = ca.symvar(a)
    if not syms:
        m = np.asarray(ca.DM(ca.evalf(a)), dtype=float)
        return bool(np.all(np.isfinite(m)) and np.linalg.matrix_rank(m) < n)
    f = ca.Function("bgm_jac", [ca.vertcat(*syms)], [a])
    is_discrete = np.array([s.element_hash() in discrete for s in syms])
    if is_discrete.any():
        tries = max(tries, 8)
    rng = np.random.default_rng(2024)
    for _ in range(tries):
        x = rng.uniform(0.5, 1.5, len(syms))
        x[is_discrete] = rng.integers(0, 2, int(is_discrete.sum()))
        with np.errstate(all="ignore"):
            m = np.asarray(f(x), dtype=float)
        if not np.all(np.isfinite(m)) or np.linalg.matrix_rank(m) == n:
            return False
    return True


_UNSAFE_UNARY = tuple(getattr(ca, n) for n in ("OP_SQRT", "OP_LOG", "OP_ASIN", "OP_ACOS",
                                                 "OP_TAN", "OP_ATANH", "OP_ACOSH", "OP_INV",
                                                 "OP_ERFINV", "OP_LOG1P") if hasattr(ca, n))
_UNSAFE_ANY = tuple(getattr(ca, n) for n in ("OP_POW", "OP_CONSTPOW", "OP_FMOD")
                    if hasattr(ca, n))


def unsafe_outputs(f: ca.Function, varying: tuple[int, ...]) -> list[int]:
    """Output entries of ``f`` (one dense output) that can turn non-finite for finite
    inputs: they apply a division, root, logarithm, power, ... to something that depends on
    the ``varying`` inputs (time, states, algebraic variables). The others are finite
    whenever those inputs are, so a result check need not evaluate them.

    One pass over ``f``'s instructions with a state per work slot: bit 1, depends on the
    varying inputs; bit 2, can be non-finite. About 4 us per instruction."""
    from casadi import _casadi as raw  # the wrappers' argument dispatch costs as much again

    op_of, ins_of, outs_of = (raw.Function_instruction_id, raw.Function_instruction_input,
                              raw.Function_instruction_output)
    op_input, op_output, op_div = ca.OP_INPUT, ca.OP_OUTPUT, ca.OP_DIV
    unsafe = frozenset(_UNSAFE_UNARY + _UNSAFE_ANY)
    vary = frozenset(varying)
    state = [0] * f.sz_w()
    out: list[int] = []
    for k in range(f.n_instructions()):
        op = op_of(f, k)
        if op == op_input:
            state[outs_of(f, k)[0]] = 1 if ins_of(f, k)[0] in vary else 0
        elif op == op_output:
            if state[ins_of(f, k)[0]] & 2:
                out.append(outs_of(f, k)[1])
        else:
            outs = outs_of(f, k)
            if not outs:
                continue
            ins = ins_of(f, k)
            s = 0
            for i in ins:
                s |= state[i]
            if op == op_div:
                if state[ins[1]] & 1:
                    s |= 2
            elif s & 1 and op in unsafe:
                s |= 2
            state[outs[0]] = s
    return sorted(set(out))
