"""The contract between the model compiler and the FMU exporter.

The compiler reduces a model to an explicit ODE with outputs and hands over an :class:`FmuSpec`:

* ``states`` ``x`` (``nx``), ``inputs`` ``u`` (``nu``), ``parameters`` ``p`` (``np``);
* ``ode``: a CasADi function ``(t[1], x[nx], u[nu], p[np]) -> (xdot[nx], y[ny])``.  The
  observation vector ``y`` is ``outputs`` followed by ``locals``:
  ``ny == len(outputs) + len(locals)``.  ``outputs`` become FMI variables with
  ``causality="output"``, ``locals`` become ``causality="local"`` observables (both
  continuous, ``initial="calculated"``).  Algebraic loops must already be solved *inside*
  ``ode`` (for instance with ``casadi.rootfinder(..., "fast_newton", ...)``, which CasADi can
  turn into C); the exported C code never solves algebraic equations itself.
* ``init``: optional CasADi function ``(t[1], u[nu], p[np]) -> x0[nx]`` giving consistent
  initial states as a function of inputs and parameters.  With ``init`` the states are exported
  as ``initial="calculated"`` (computed in Initialization Mode, their ``start`` is only used by
  the exporter's own checks); without it they are ``initial="exact"`` and the ``start`` values of
  ``states`` are the initial values (settable before initialization).

Variables:

* names are dotted Modelica-style names (``motor.inertia.w``); the derivative of state ``s`` is
  exported as ``der(s)`` automatically, so derivatives are *not* listed by the compiler;
* ``unit`` is a Modelica unit string (``"rad/s"``, ``"N.m"``, ``"1"``, ``""`` for none);
* ``min``/``max`` (optional) are written to ``modelDescription.xml`` for every variable; they
  bound the values the FMU accepts for inputs, parameters and state start values (outside, or
  NaN: an error status and a logged message naming the variable; nothing is set);
* ``nominal`` (optional, states only) scales the absolute tolerance of integrators and is returned
  by ``GetNominalsOfContinuousStates``;
* the ``start`` of outputs and locals is not exported (they are calculated).

All parameters are ``causality="parameter"``, ``variability="tunable"``: settable before and
during initialization, in Event Mode (Model Exchange) and between communication steps
(Co-Simulation).  Inputs are continuous real inputs.

``start_time``, ``stop_time``, ``step_size`` (communication/output step, optional) and
``tolerance`` go to ``<DefaultExperiment>``; ``tolerance`` is also the default of the
Co-Simulation solver parameter ``solver.tolerance``.  ``solver_max_step`` (optional) is the
default of ``solver.max_step``; when ``None`` it defaults to ``stop_time - start_time``.
"""

from __future__ import annotations

import keyword
import math
import re
from dataclasses import dataclass, field
from typing import Any

RESERVED_NAMES = ("time", "solver.tolerance", "solver.max_step")

_IDENT = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


class FmuExportError(Exception):
    """Base class of the errors raised by :mod:`bgmodelica.fmi`."""


class FmuSpecError(FmuExportError, ValueError):
    """The :class:`FmuSpec` is inconsistent (sizes, names, values)."""


@dataclass(frozen=True)
class ScalarVariable:
    """One scalar real variable of the exported model."""

    name: str
    start: float
    unit: str = ""
    description: str = ""
    min: float | None = None
    max: float | None = None
    nominal: float | None = None


@dataclass
class FmuSpec:
    """Everything the exporter needs; see the module docstring for the semantics."""

    model_name: str
    description: str
    states: list[ScalarVariable]
    inputs: list[ScalarVariable]
    parameters: list[ScalarVariable]
    outputs: list[ScalarVariable]
    locals: list[ScalarVariable] = field(default_factory=list)
    ode: Any = None  # casadi.Function (t, x, u, p) -> (xdot, y)
    init: Any = None  # casadi.Function (t, u, p) -> x0, or None
    start_time: float = 0.0
    stop_time: float = 1.0
    step_size: float | None = None
    tolerance: float = 1e-6
    solver_max_step: float | None = None
    #: models with events: a :class:`bgmodelica.fmi.hybrid.HybridSpec`; then ``ode`` (and
    #: ``init``) take the discrete slots as their last argument ``(t, x, u, p, d)``
    hybrid: Any = None
    #: names of states that are also outputs (exported with causality="output")
    state_outputs: list[str] = field(default_factory=list)

    @property
    def nx(self) -> int:
        return len(self.states)

    @property
    def nu(self) -> int:
        return len(self.inputs)

    @property
    def np(self) -> int:
        return len(self.parameters)

    @property
    def ny(self) -> int:
        return len(self.outputs) + len(self.locals)

    def default_max_step(self) -> float:
        if self.solver_max_step is not None:
            return float(self.solver_max_step)
        span = float(self.stop_time) - float(self.start_time)
        return span if span > 0 else 1.0

    def validate(self) -> None:
        """Raise :class:`FmuSpecError` if the spec cannot be exported."""
        if not isinstance(self.model_name, str) or not _IDENT.match(self.model_name) \
                or keyword.iskeyword(self.model_name):
            raise FmuSpecError(f"model_name {self.model_name!r} is not a valid C/Python identifier")
        if len(self.model_name) > 64:
            raise FmuSpecError(f"model_name {self.model_name!r} is longer than 64 characters")
        if self.ode is None:
            raise FmuSpecError("FmuSpec.ode is missing")
        n_in = [1, self.nx, self.nu, self.np] + ([self.hybrid.nd] if self.hybrid else [])
        _check_function(self.ode, "ode", n_in, [self.nx, self.ny])
        if self.init is not None:
            _check_function(self.init, "init", n_in[:1] + n_in[2:], [self.nx])
        seen: dict[str, str] = {}
        groups = (("state", self.states), ("input", self.inputs), ("parameter", self.parameters),
                  ("output", self.outputs), ("local", self.locals))
        for kind, variables in groups:
            for v in variables:
                if not isinstance(v, ScalarVariable):
                    raise FmuSpecError(f"{kind} {v!r} is not a ScalarVariable")
                _check_name(v.name, kind)
                if v.name in seen:
                    raise FmuSpecError(f"variable name {v.name!r} used twice ({seen[v.name]} and "
                                       f"{kind})")
                seen[v.name] = kind
                if not math.isfinite(float(v.start)):
                    raise FmuSpecError(f"{kind} {v.name!r}: start value {v.start!r} is not finite")
                lo = -math.inf if v.min is None else float(v.min)
                hi = math.inf if v.max is None else float(v.max)
                if lo > hi:
                    raise FmuSpecError(f"{kind} {v.name!r}: min {lo} > max {hi}")
                if kind in ("state", "input", "parameter") and not lo <= float(v.start) <= hi:
                    raise FmuSpecError(f"{kind} {v.name!r}: start {v.start} outside [{lo}, {hi}]")
                if v.nominal is not None and not (math.isfinite(v.nominal) and v.nominal > 0):
                    raise FmuSpecError(f"{kind} {v.name!r}: nominal must be finite and > 0")
        if self.hybrid is not None:
            self.hybrid.validate(self.nx, seen)
        for s in self.states:
            der = f"der({s.name})"
            if der in seen:
                raise FmuSpecError(f"variable name {der!r} clashes with a state derivative")
        if not (math.isfinite(self.start_time) and math.isfinite(self.stop_time)):
            raise FmuSpecError("start_time and stop_time must be finite")
        if self.stop_time <= self.start_time:
            raise FmuSpecError("stop_time must be larger than start_time")
        if self.step_size is not None and not self.step_size > 0:
            raise FmuSpecError("step_size must be > 0")
        if not (0 < self.tolerance < 1):
            raise FmuSpecError("tolerance must be in (0, 1)")
        if not self.default_max_step() > 0:
            raise FmuSpecError("solver_max_step must be > 0")


def _check_name(name: str, kind: str) -> None:
    if not isinstance(name, str) or not name or name != name.strip():
        raise FmuSpecError(f"{kind} name {name!r} is empty or has surrounding blanks")
    if name in RESERVED_NAMES:
        raise FmuSpecError(f"{kind} name {name!r} is reserved by the exporter")
    if name.startswith("der("):
        raise FmuSpecError(f"{kind} name {name!r}: derivatives are generated, do not list them")
    if any(ch in name for ch in "\n\r\t\"\\"):
        raise FmuSpecError(f"{kind} name {name!r} contains a control, quote or backslash character")


def _check_function(f: Any, what: str, n_in: list[int], n_out: list[int]) -> None:
    try:
        nin, nout = f.n_in(), f.n_out()
    except AttributeError as err:
        raise FmuSpecError(f"FmuSpec.{what} is not a casadi.Function") from err
    if nin != len(n_in) or nout != len(n_out):
        raise FmuSpecError(f"FmuSpec.{what} must have {len(n_in)} inputs and {len(n_out)} "
                           f"outputs, has {nin} and {nout}")
    for i, n in enumerate(n_in):
        if f.numel_in(i) != n:
            raise FmuSpecError(f"FmuSpec.{what} input {i} ({f.name_in(i)}) has {f.numel_in(i)} "
                               f"elements, expected {n}")
    for i, n in enumerate(n_out):
        if f.numel_out(i) != n:
            raise FmuSpecError(f"FmuSpec.{what} output {i} ({f.name_out(i)}) has "
                               f"{f.numel_out(i)} elements, expected {n}")
