"""The steady-state solve of :mod:`.steady_state`: ``der(x) = 0`` and the algebraic
equations for the states and algebraic variables, checked structurally first (a maximum
matching and the Dulmage-Mendelsohn decomposition name what is over- or under-determined),
then solved by a damped Newton method; a failure names the conditions and variables at
fault."""

from __future__ import annotations

from collections.abc import Sequence

import casadi as ca
import numpy as np

from ..backends.casadi_dae import CasadiDAE
from ..errors import InitializationError, ParameterError


def state_name(dae: CasadiDAE, name: str) -> str:
    """The state that ``name`` (a state or an alias of one) is; a clear error otherwise."""
    from ..overrides import resolve_alias

    kept, _ = resolve_alias(name, dae.aliases, set(), dae.observed_index)
    if kept not in dae.state_names:
        raise ParameterError(f"exclude: {name!r} is not a state of the model (states: "
                             f"{', '.join(dae.state_names) or 'none'})")
    return kept


def solve_steady_state(dae: CasadiDAE, p: np.ndarray, t: float = 0.0, *,
                       exclude: Sequence[str] = (), tol: float = 1e-10,
                       max_iter: int = 100) -> tuple[np.ndarray, np.ndarray, int]:
    """``(x, z, iterations)`` with ``der(x) = 0`` (states in ``exclude`` pinned at their start
    values) and the algebraic equations satisfied; ``dae.x_start``/``z_start`` are the
    guesses. See the module docstring for the method and the errors."""
    excl = {state_name(dae, n) for n in exclude}
    keep = [i for i, n in enumerate(dae.state_names) if n not in excl]
    pin = [i for i, n in enumerate(dae.state_names) if n in excl]
    nz = dae.z.numel()
    w_sym = ca.vertcat(*[dae.x[i] for i in keep], dae.z)
    known = ca.vertcat(*[dae.x[i] for i in pin]) if pin else ca.SX(0, 1)
    rows_ode = [dae.ode[i] for i in keep]
    F = ca.vertcat(*rows_ode, dae.alg) if (rows_ode or nz) else ca.SX(0, 1)
    labels = [f"der({dae.state_names[i]}) = 0" for i in keep] \
        + [_alg_label(dae, k) for k in range(nz)]
    names = [dae.state_names[i] for i in keep] + list(dae.algebraic_names)
    x = np.array(dae.x_start, dtype=float)
    if F.numel() == 0:
        return x, np.array(dae.z_start, dtype=float), 0
    _structural_check(dae, F, w_sym, labels, names, keep, excl)
    args = ca.vertcat(known, dae.p, dae.t)
    fun = ca.Function("ss_F", [w_sym, args], [F])
    jac = ca.Function("ss_J", [w_sym, args], [ca.densify(ca.jacobian(F, w_sym))])
    a = np.concatenate([x[pin], np.asarray(p, float), [t]])
    w = np.concatenate([x[keep], np.asarray(dae.z_start, float)])
    w, its, r, J = _newton(lambda v: np.asarray(fun(v, a)).ravel(),
                           lambda v: np.asarray(jac(v, a)), w, tol, max_iter)
    if not (np.all(np.isfinite(r)) and np.max(np.abs(r)) <= tol):
        raise InitializationError(_numeric_failure(dae, r, J, labels, names, its))
    x[keep] = w[:len(keep)]
    return x, w[len(keep):], its


def _newton(F, J, w, tol: float, max_iter: int):
    """Damped Newton on F(w) = 0: backtracking on ||F||_2, continuing past ``tol`` while the
    residual still drops (to machine precision on a well-conditioned point)."""
    with np.errstate(all="ignore"):
        r = F(w)
        norm = np.linalg.norm(r) if np.all(np.isfinite(r)) else np.inf
        Jm = None
        its = 0
        polish = 0
        for its in range(1, max_iter + 1):  # noqa: B007 -- returned
            Jm = J(w)
            if not np.all(np.isfinite(Jm)):
                break
            try:
                dw = np.linalg.solve(Jm, -r)
            except np.linalg.LinAlgError:
                dw = np.linalg.lstsq(Jm, -r, rcond=None)[0]
            if not np.all(np.isfinite(dw)):
                break
            lam, accepted = 1.0, False
            while lam >= 1e-8:
                w_new = w + lam * dw
                r_new = F(w_new)
                n_new = np.linalg.norm(r_new) if np.all(np.isfinite(r_new)) else np.inf
                if n_new < (1.0 - 1e-4 * lam) * norm or (n_new <= norm and
                                                          np.max(np.abs(r)) <= tol):
                    accepted = True
                    break
                lam *= 0.5
            if not accepted:                 # Levenberg-Marquardt steps: singular J
                JtJ, Jtr = Jm.T @ Jm, Jm.T @ r
                scale = np.maximum(np.diag(JtJ), 1e-12 * max(np.max(np.diag(JtJ)), 1e-300))
                for mu in 10.0 ** np.arange(-8, 5):
                    try:
                        dw = np.linalg.solve(JtJ + mu * np.diag(scale), -Jtr)
                    except np.linalg.LinAlgError:
                        continue
                    lam = 1.0
                    w_new = w + dw
                    r_new = F(w_new)
                    n_new = np.linalg.norm(r_new) if np.all(np.isfinite(r_new)) else np.inf
                    if n_new < (1.0 - 1e-4) * norm:
                        accepted = True
                        break
            if not accepted:
                break
            step = np.max(np.abs(lam * dw) / (1.0 + np.abs(w)))
            w, r, norm_old, norm = w_new, r_new, norm, n_new
            if np.max(np.abs(r)) <= tol:
                polish += 1
                if step < 1e-15 or polish > 3 or norm >= 0.5 * norm_old:
                    break
        if Jm is None or not np.all(np.isfinite(Jm)):
            Jm = J(w)
    return w, its, r, Jm


def _structural_check(dae, F, w_sym, labels, names, keep, excl) -> None:
    from ..structure import maximum_matching
    from ..structure.diagnosis import dulmage_mendelsohn

    sp = ca.jacobian_sparsity(F, w_sym)
    rows: list[list[int]] = [[] for _ in range(F.numel())]
    for r, c in zip(*sp.get_triplet(), strict=True):
        rows[r].append(c)
    match = maximum_matching(rows, w_sym.numel())
    if all(e >= 0 for e in match.eq_to_var) and all(v >= 0 for v in match.var_to_eq):
        return
    dm = dulmage_mendelsohn(rows, w_sym.numel(), match)
    over = [labels[e] for e in dm.overdetermined_eqs]
    over_vars = [names[v] for v in dm.overdetermined_vars]
    under = [names[v] for v in dm.underdetermined_vars]
    parts = ["no steady state:"]
    if over:
        defs = [_defining(dae, lab) for lab in over]
        parts.append("the conditions " + "; ".join(
            lab + (f" ({d})" if d else "") for lab, d in zip(over, defs, strict=True))
            + (f" over-determine {', '.join(over_vars)};" if over_vars
               else " depend on no state or algebraic variable: they hold only for special "
                    "parameter or input values;"))
    if under:
        parts.append(f"{', '.join(under)} {'is' if len(under) == 1 else 'are'} not "
                     "determined by der(x) = 0")
    moving = [n for n in under if n in dae.state_names]
    hint = (f"; a state that moves at steady state (e.g. an angle turning at constant speed) "
            f"can be excluded: exclude=[{', '.join(repr(n) for n in moving[:3])}]"
            if moving else "")
    raise InitializationError(" ".join(parts) + hint)


def _numeric_failure(dae, r, J, labels, names, its) -> str:
    with np.errstate(all="ignore"):
        finite = np.all(np.isfinite(r))
        worst = int(np.argmax(np.where(np.isfinite(r), np.abs(r), np.inf)))
    lab = labels[worst]
    d = _defining(dae, lab)
    msg = (f"no steady state found: after {its} Newton iterations from the start values the "
           f"residual of {lab}" + (f" ({d})" if d else "")
           + (f" is still {r[worst]:.3g}" if finite else " is not finite"))
    try:
        if J is not None and np.all(np.isfinite(J)) and J.size:
            U, s, Vt = np.linalg.svd(J)
            if s[-1] <= 1e-10 * max(s[0], 1e-300):
                v = np.abs(Vt[-1])
                u = np.abs(U[:, -1])
                vs = [names[k] for k in np.argsort(-v)[:3] if v[k] > 0.2 * v.max()]
                es = [labels[k] for k in np.argsort(-u)[:3] if u[k] > 0.2 * u.max()]
                msg += (f"; the Jacobian is singular there (conditions {'; '.join(es)} do not "
                        f"determine {', '.join(vs)})")
    except np.linalg.LinAlgError:
        pass
    return msg + ("; the steady state may not exist for these parameters and inputs, or the "
                  "start values (guesses) are too far from it")


def _defining(dae, label: str) -> str:
    """The model equation that defines ``der(x)`` for a label ``der(x) = 0``."""
    if not label.startswith("der(") or dae.sorted is None:
        return ""
    name = label[:-4]
    model = dae.sorted.model
    var = next((v for v in model.variables if v.name == name), None)
    if var is None:
        return ""
    names = model.names()
    for eq in model.equations:
        if ca.depends_on(eq.residual, var.sx) and not eq.origin.startswith("d/dt"):
            return eq.describe(names, width=80)
    return ""


def _alg_label(dae, k: int) -> str:
    name = dae.algebraic_names[k] if k < len(dae.algebraic_names) else str(k)
    return f"algebraic equation for {name}"
