"""Linearization of a compiled model at an operating point.

The index-reduced DAE ``x' = f(t, x, z, p)``, ``0 = g(t, x, z, p)`` with outputs
``y = h(t, x, z, p)`` is differentiated by CasADi's algorithmic differentiation at the point
``(t, x, z, p)``; the algebraic variables are eliminated exactly by the implicit function
theorem on ``g`` (``dz = -g_z^-1 (g_x dx + g_u du)``, one LU solve):

    A = f_x - f_z g_z^-1 g_x      B = f_u - f_z g_z^-1 g_u
    C = h_x - h_z g_z^-1 g_x      D = h_u - h_z g_z^-1 g_u

The states are the states the compiler selected (index reduction, dummy derivatives): for a
constrained system (the Cartesian pendulum) the linear model lives on the constraint
manifold, in the independent coordinates. Inputs are the model's top-level ``Input``s (or
inputs / free parameters chosen by name: a parameter is then a constant input), outputs its
top-level ``Output``s (or any variables chosen by name; states when the model has no
outputs). The result is a python-control ``StateSpace`` with named signals.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from ..errors import ParameterError, SimulationError
from .steady_state import OperatingPoint, operating_point

__all__ = ["Linearization", "linearize", "linearization", "linearize_at"]


@dataclass
class Linearization:
    """``x' = A x + B u``, ``y = C x + D u`` (deviations from ``point``) and its signals."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    states: list[str]
    inputs: list[str]
    outputs: list[str]
    point: OperatingPoint
    name: str = "model"

    def ss(self):
        """The python-control ``StateSpace``: states named as in the model; inputs and
        outputs too, except that python-control reserves ``.`` in signal names (for
        ``system.signal``), so a dotted name ``motor1.inductor.i`` becomes
        ``motor1_inductor_i`` (``.signal_names`` maps them back). ``.operating_point`` and
        ``.linearization`` are attached."""
        import control

        ins = [_signal(n) for n in self.inputs]
        outs = [_signal(n) for n in self.outputs]
        sys = control.ss(self.A, self.B, self.C, self.D, states=list(self.states),
                         inputs=ins, outputs=outs, name=self.name)
        sys.operating_point = self.point
        sys.linearization = self
        sys.signal_names = dict(zip(ins + outs, list(self.inputs) + list(self.outputs),
                                    strict=True))
        return sys

    @property
    def eigenvalues(self) -> np.ndarray:
        """Eigenvalues of A (the poles of the linear model), sorted by real then imaginary
        part."""
        ev = np.linalg.eigvals(self.A) if self.A.size else np.zeros(0, complex)
        return np.array(sorted(ev, key=lambda v: (round(v.real, 12), v.imag)))

    def frequency_response(self, omega: Sequence[float]) -> np.ndarray:
        """``G(j w) = C (j w I - A)^-1 B + D``, shape (len(omega), outputs, inputs)."""
        n = self.A.shape[0]
        out = []
        minimal = None
        for w in np.asarray(omega, dtype=float):
            M = 1j * w * np.eye(n) - self.A
            if n and np.linalg.cond(M) > 1e12:   # a pole on the axis (e.g. an integrator):
                if minimal is None:                # use the minimal realization there
                    from .controllability import minimal_realization

                    minimal = minimal_realization(self.A, self.B, self.C)
                Am, Bm, Cm = minimal
                M, B, C = 1j * w * np.eye(Am.shape[0]) - Am, Bm, Cm
            else:
                B, C = self.B, self.C
            if M.shape[0]:
                out.append(C @ np.linalg.solve(M, B) + self.D)
            else:
                out.append(self.D.astype(complex))
        return np.array(out)

    def to_dict(self, tol: float | None = None) -> dict[str, Any]:
        """JSON-ready: states, inputs, outputs, A, B, C, D, operating_point, eigenvalues,
        controllability_rank, observability_rank (and the details of both)."""
        from .controllability import controllability, observability

        ctrb = controllability(self.A, self.B, tol=tol, states=self.states)
        obsv = observability(self.A, self.C, tol=tol, states=self.states)
        ev = self.eigenvalues
        return {
            "model": self.name,
            "states": list(self.states), "inputs": list(self.inputs),
            "outputs": list(self.outputs),
            "A": self.A.tolist(), "B": self.B.tolist(), "C": self.C.tolist(),
            "D": self.D.tolist(),
            "operating_point": self.point.to_dict(),
            "eigenvalues": [[float(v.real), float(v.imag)] for v in ev],
            "controllability_rank": ctrb.rank, "observability_rank": obsv.rank,
            "controllability": ctrb.to_dict(), "observability": obsv.to_dict(),
        }


def _signal(name: str) -> str:
    """A python-control signal name for a model variable (no ``.``)."""
    return name.replace(".", "_")


def linearize(model: Any, params: dict[str, Any] | None = None, *, steady_state: bool = False,
              at_time: float | None = None, inputs: Sequence[str] | None = None,
              outputs: Sequence[str] | None = None, exclude: Sequence[str] = (),
              t: float = 0.0, tol: float = 1e-10, units: str = "error",
              point: OperatingPoint | None = None):
    """Linearize ``model`` (a component, compiled model or MODEL reference such as
    ``"library.examples:DCMotor"``) and return a python-control
    ``StateSpace`` with named states, inputs and outputs.

    The operating point: the consistent initial point from the start values (default; start
    values in ``params`` are fixed conditions), the steady state (``steady_state=True``,
    start values are guesses, see :func:`~bgmodelica.steady_state`; ``exclude`` states that
    need not be stationary), the state of a simulation at ``at_time`` [s], or a given
    ``point``. ``params`` also set parameters and inputs (the operating input values).
    inputs / outputs: names (default: the top-level ``Input``s / ``Output``s). The returned
    system has ``.operating_point`` (an :class:`OperatingPoint`) and ``.linearization``
    (a :class:`Linearization`, with ``to_dict()`` and the numeric ranks)."""
    return linearization(model, params, steady_state=steady_state, at_time=at_time,
                         inputs=inputs, outputs=outputs, exclude=exclude, t=t, tol=tol,
                         units=units, point=point).ss()


def linearization(model: Any, params: dict[str, Any] | None = None, *,
                  steady_state: bool = False, at_time: float | None = None,
                  inputs: Sequence[str] | None = None, outputs: Sequence[str] | None = None,
                  exclude: Sequence[str] = (), t: float = 0.0, tol: float = 1e-10,
                  units: str = "error", point: OperatingPoint | None = None) -> Linearization:
    """Like :func:`linearize`, returning the :class:`Linearization` (matrices, names,
    point)."""
    if point is None:
        point = operating_point(model, params, steady=steady_state, at_time=at_time, t=t,
                                exclude=exclude, tol=tol, units=units)
    return linearize_at(point, inputs=inputs, outputs=outputs)


def linearize_at(point: OperatingPoint, inputs: Sequence[str] | None = None,
                 outputs: Sequence[str] | None = None) -> Linearization:
    """The :class:`Linearization` at ``point``."""
    dae = point.dae
    compiled = point.compiled
    u_idx, u_names = _input_slots(dae, inputs)
    h, y_names = _outputs(compiled, dae, outputs)
    nx, nz, nu = dae.x.numel(), dae.z.numel(), len(u_idx)
    u_sym = ca.vertcat(*[dae.p[i] for i in u_idx]) if nu else ca.SX(0, 1)

    def jac(expr, wrt):
        if expr.numel() == 0 or wrt.numel() == 0:
            return ca.SX(expr.numel(), wrt.numel())
        return ca.densify(ca.jacobian(expr, wrt))

    key = ("linearize", tuple(u_idx), tuple(y_names))
    if key not in dae.cache:
        blocks = [jac(e, w) for e in (dae.ode, dae.alg, h) for w in (dae.x, dae.z, u_sym)]
        dae.cache[key] = ca.Function("lin", [dae.t, dae.x, dae.z, dae.p], blocks)
    vals = [np.asarray(ca.DM(v)) for v in dae.cache[key](point.t, point.x, point.z, point.p)]
    fx, fz, fu, gx, gz, gu, hx, hz, hu = (v.reshape(s) for v, s in zip(vals, [
        (nx, nx), (nx, nz), (nx, nu), (nz, nx), (nz, nz), (nz, nu),
        (len(y_names), nx), (len(y_names), nz), (len(y_names), nu)], strict=True))
    if nz:
        cond = np.linalg.cond(gz) if gz.size else 1.0
        if not np.isfinite(cond) or cond > 1e14:
            raise SimulationError(
                f"cannot linearize {compiled.name} at this point: the algebraic equations are "
                f"singular with respect to {', '.join(dae.algebraic_names[:6])} (condition "
                f"number {cond:.3g}); the states {', '.join(dae.state_names)} are not valid "
                "coordinates here", point.t)
        X = np.linalg.solve(gz, np.hstack([gx, gu]))
        Xx, Xu = X[:, :nx], X[:, nx:]
        A, B = fx - fz @ Xx, fu - fz @ Xu
        C, D = hx - hz @ Xx, hu - hz @ Xu
    else:
        A, B, C, D = fx, fu, hx, hu
    bad = [n for n, M in (("A", A), ("B", B), ("C", C), ("D", D)) if not np.all(np.isfinite(M))]
    if bad:
        raise SimulationError(f"cannot linearize {compiled.name}: {', '.join(bad)} not finite "
                              "at the operating point", point.t)
    return Linearization(A, B, C, D, list(dae.state_names), u_names, y_names, point,
                         compiled.name)


def _input_slots(dae, inputs: Sequence[str] | None) -> tuple[list[int], list[str]]:
    n_par = len(dae.parameters)
    if inputs is None:
        return [n_par + k for k in range(len(dae.inputs))], [u.name for u in dae.inputs]
    where = {q.name: k for k, q in enumerate(dae.parameters)}
    where.update({u.name: n_par + k for k, u in enumerate(dae.inputs)})
    bound = {q.name for q in getattr(dae, "bound", [])}
    idx, names = [], []
    for name in inputs:
        key = name
        seen = set()
        while key not in where and key in dae.aliases and key not in seen:
            seen.add(key)
            key = dae.aliases[key][0]
        if key not in where:
            from ..overrides import did_you_mean

            if name in bound:
                raise ParameterError(f"input {name!r}: the parameter is bound to an expression "
                                     "of other parameters; perturb those instead")
            raise ParameterError(f"input {name!r} is not an input or free parameter of the "
                                 f"model{did_you_mean(name, list(where))}")
        idx.append(where[key])
        names.append(name)
    return idx, names


def top_level_outputs(compiled) -> list[str]:
    """Names of the top-level ``Output``s of the model, in declaration order (aliases
    included)."""
    src = compiled.source
    decls = getattr(src, "_symbols", {}) if src is not None else {}
    out = [n for n, s in decls.items() if s.decl.kind == "output"]
    if not out:                                    # no source: read the flat model
        out = [v.name for v in compiled.reduced.model.variables
               if v.decl.kind == "output" and v.component == "" and v.der_of < 0]
    return out


def _outputs(compiled, dae, outputs: Sequence[str] | None) -> tuple[ca.SX, list[str]]:
    from ..overrides import did_you_mean, resolve_alias

    names = list(outputs) if outputs is not None else top_level_outputs(compiled)
    if outputs is None and not names:
        names = list(dae.state_names)
    rows = []
    n_var = dae.n_variables or len(dae.names)
    for name in names:
        kept, sign = resolve_alias(name, dae.aliases, set(), dae.observed_index)
        if kept not in dae.observed_index or dae.observed_index[kept] >= n_var:
            raise ParameterError(f"output {name!r} is not a variable of the model"
                                 f"{did_you_mean(name, dae.names[:n_var])}")
        rows.append(float(sign) * dae.observed[dae.observed_index[kept]])
    return (ca.vertcat(*rows) if rows else ca.SX(0, 1)), names
