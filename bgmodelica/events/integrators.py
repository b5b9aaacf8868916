"""The CasADi integrators of the event loop (CVODES for ODEs, IDAS for DAEs), built once per
settings and reused for every segment, and a guard that keeps SUNDIALS' own error messages
off the terminal while a failure is expected and retried."""

from __future__ import annotations

import contextlib
import os
import sys

import casadi as ca

from ..backends.casadi_dae import CasadiDAE


@contextlib.contextmanager
def quiet_stderr():
    """Silence C-level stderr (SUNDIALS prints its error messages there)."""
    try:
        fd = sys.stderr.fileno()
    except (AttributeError, OSError, ValueError):
        yield
        return
    sys.stderr.flush()
    saved = os.dup(fd)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, fd)
        yield
    finally:
        os.dup2(saved, fd)
        os.close(saved)
        os.close(devnull)


def integrator(dae: CasadiDAE, opts: dict, tout: list[float], scaled: bool) -> ca.Function:
    """CVODES (ODE) or IDAS (DAE) integrator of the model from ``t0``: over ``tau`` in [0, 1]
    with ``t = t0 + tau*dt`` when ``scaled`` (p = [p, t0, dt]), else over offsets ``tau``
    with ``t = t0 + tau`` (p = [p, t0]). Cached in ``dae.cache`` by its settings."""
    key = ("hybrid_integrator", scaled, tuple(tout),
           tuple(sorted((k, repr(v)) for k, v in opts.items())))
    if key in dae.cache:
        return dae.cache[key]
    t0, dt, tau = ca.SX.sym("t0"), ca.SX.sym("dt"), ca.SX.sym("tau")
    t_of = t0 + tau * dt if scaled else t0 + tau
    scale = dt if scaled else 1
    x, ode = dae.x, dae.ode
    problem = {"x": x, "p": ca.vertcat(dae.p, t0, dt) if scaled else ca.vertcat(dae.p, t0),
               "t": tau, "ode": scale * ca.substitute(ode, dae.t, t_of)}
    solver = "cvodes"
    solver_opts = dict(opts, disable_internal_warnings=True, show_eval_warnings=False)
    if dae.z.numel():
        problem.update(z=dae.z, alg=ca.substitute(dae.alg, dae.t, t_of))
        solver = "idas"
        solver_opts["calc_ic"] = True
        # algebraic variables follow the states: leave them out of the local error test, whose
        # absolute tolerance their solve noise (a stiff switch) can exceed on every step
        solver_opts.setdefault("suppress_algebraic", True)
    F = ca.integrator("segment", solver, problem, 0.0, [float(v) for v in tout], solver_opts)
    if scaled:
        dae.cache[key] = F
    return F
