"""The exported variable table: value references, causality, variability, initial.

One layout serves FMI 2.0 and 3.0; value references are unique over all variables (required by
FMI 3.0, harmless for FMI 2.0) and the variables are listed in value-reference order, so the
FMI 2.0 ``index`` of a variable is ``valueReference + 1``:

=====================  ==============================  ===========  ============  ===========
block (in VR order)    name                            causality    variability   initial
=====================  ==============================  ===========  ============  ===========
time (VR 0)            ``time``                        independent  continuous    --
states x               ``motor.inertia.w``             local        continuous    exact [1]_
derivatives            ``der(motor.inertia.w)``        local        continuous    calculated
inputs u               spec name                       input        continuous    -- (start)
parameters p           spec name                       parameter    tunable       exact
outputs                spec name                       output       continuous    calculated
locals                 spec name                       local        continuous    calculated
solver (CS only)       ``solver.tolerance``,           parameter    tunable       exact
                       ``solver.max_step``
=====================  ==============================  ===========  ============  ===========

.. [1] ``calculated`` (no start value) when the spec has an ``init`` function.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .spec import FmuSpec, ScalarVariable
from .units import derivative_unit

SOLVER_TOLERANCE_MIN = 1e-12
SOLVER_TOLERANCE_MAX = 1e-1


@dataclass
class FmiVariable:
    name: str
    vr: int
    kind: str  # time, state, derivative, input, parameter, output, local, solver
    index: int  # position within its kind
    causality: str
    variability: str
    initial: str | None
    start: float | None
    unit: str = ""
    description: str = ""
    min: float | None = None
    max: float | None = None
    nominal: float | None = None
    derivative_of: int | None = None  # VR of the state, for derivatives
    type: str = "Real"  # Real, Integer or Boolean (discrete variables of hybrid models)

    @property
    def fmi2_index(self) -> int:
        return self.vr + 1


@dataclass
class VariableTable:
    variables: list[FmiVariable]
    nx: int
    nu: int
    np: int
    nout: int
    nlocal: int
    has_solver: bool

    def of_kind(self, kind: str) -> list[FmiVariable]:
        return [v for v in self.variables if v.kind == kind]

    @property
    def vr_x(self) -> int:
        return 1

    @property
    def vr_dx(self) -> int:
        return 1 + self.nx

    @property
    def vr_u(self) -> int:
        return 1 + 2 * self.nx

    @property
    def vr_p(self) -> int:
        return self.vr_u + self.nu

    @property
    def vr_y(self) -> int:
        return self.vr_p + self.np

    @property
    def vr_solver(self) -> int:
        return self.vr_y + self.nout + self.nlocal


def _opt(value: float | None) -> float | None:
    """Optional finite float (infinite bounds are the same as no bound)."""
    if value is None or not math.isfinite(float(value)):
        return None
    return float(value)


def build_table(spec: FmuSpec, with_solver: bool, with_indicators: bool = False
                ) -> VariableTable:
    """Lay out the variables of ``spec``; ``with_solver`` adds the CS solver parameters.

    Hybrid specs add, after the solver parameters, their discrete variables (local,
    ``variability="discrete"``, typed; ``initial="exact"`` with the declared start for those
    assigned in when-clauses, ``"calculated"`` for those defined by equations) and, with
    ``with_indicators`` (FMI 3.0 Model Exchange), one local Float64 per event indicator."""
    out: list[FmiVariable] = []

    def add(v: ScalarVariable | None, name: str, kind: str, index: int, causality: str,
            variability: str, initial: str | None, start: float | None, unit: str = "",
            **extra: object) -> FmiVariable:
        var = FmiVariable(name=name, vr=len(out), kind=kind, index=index, causality=causality,
                          variability=variability, initial=initial, start=start, unit=unit,
                          description=v.description if v is not None else "", **extra)
        out.append(var)
        return var

    add(None, "time", "time", 0, "independent", "continuous", None, None, "s")
    out[0].description = "Simulation time"
    state_vrs = []
    state_outputs = set(spec.state_outputs)
    for i, s in enumerate(spec.states):
        initial = "calculated" if spec.init is not None else "exact"
        start = None if spec.init is not None else float(s.start)
        causality = "output" if s.name in state_outputs else "local"
        var = add(s, s.name, "state", i, causality, "continuous", initial, start, s.unit,
                  min=_opt(s.min), max=_opt(s.max), nominal=_opt(s.nominal))
        state_vrs.append(var.vr)
    for i, s in enumerate(spec.states):
        var = add(None, f"der({s.name})", "derivative", i, "local", "continuous", "calculated",
                  None, derivative_unit(s.unit), derivative_of=state_vrs[i])
        var.description = f"Time derivative of {s.name}"
    for i, v in enumerate(spec.inputs):
        add(v, v.name, "input", i, "input", "continuous", None, float(v.start), v.unit,
            min=_opt(v.min), max=_opt(v.max))
    for i, v in enumerate(spec.parameters):
        add(v, v.name, "parameter", i, "parameter", "tunable", "exact", float(v.start), v.unit,
            min=_opt(v.min), max=_opt(v.max))
    for i, v in enumerate(spec.outputs):
        add(v, v.name, "output", i, "output", "continuous", "calculated", None, v.unit,
            min=_opt(v.min), max=_opt(v.max))
    for i, v in enumerate(spec.locals):
        add(v, v.name, "local", len(spec.outputs) + i, "local", "continuous", "calculated",
            None, v.unit, min=_opt(v.min), max=_opt(v.max))
    if with_solver:
        tol = add(None, "solver.tolerance", "solver", 0, "parameter", "tunable", "exact",
                  float(spec.tolerance), "1", min=SOLVER_TOLERANCE_MIN, max=SOLVER_TOLERANCE_MAX)
        tol.description = ("Relative (and, times the state nominal, absolute) error tolerance of "
                           "the embedded BDF solver (Co-Simulation)")
        hmax = add(None, "solver.max_step", "solver", 1, "parameter", "tunable", "exact",
                   float(spec.default_max_step()), "s", min=1e-12)
        hmax.description = "Largest internal step of the embedded solver (Co-Simulation)"
    if spec.hybrid is not None:
        from .hybrid import indicator_name

        for i, dv in enumerate(spec.hybrid.discretes):
            var = add(None, dv.name, "discrete", i, "local", "discrete",
                      "calculated" if dv.start is None else "exact",
                      None if dv.start is None else float(dv.start),
                      dv.unit if dv.type == "Real" else "", type=dv.type)
            var.description = dv.description
        if with_indicators:
            for k, r in enumerate(spec.hybrid.state_rel):
                var = add(None, indicator_name(k), "indicator", k, "local", "continuous",
                          "calculated", None)
                var.description = (f"Event indicator of the relation "
                                   f"{spec.hybrid.relations[r]} (> 0: true)")
    return VariableTable(out, spec.nx, spec.nu, spec.np, len(spec.outputs), len(spec.locals),
                         with_solver)
