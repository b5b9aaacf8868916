"""FMU export (FMI 2.0 and 3.0, Model Exchange and Co-Simulation) of compiled models.

The compiler hands an :class:`FmuSpec` (explicit ODE with outputs, as CasADi functions; see
:mod:`bgmodelica.fmi.spec`) to :func:`export_fmu`, which

1. builds dense canonical CasADi functions (model, forward derivative, Jacobian d(xdot)/dx,
   optional init) and generates their C code (:mod:`~bgmodelica.fmi.codegen`);
2. lays out the variables and writes ``modelDescription.xml``
   (:mod:`~bgmodelica.fmi.variables`, :mod:`~bgmodelica.fmi.model_description`,
   :mod:`~bgmodelica.fmi.units`);
3. adds our own C runtime (``templates/``: ``bgm_core`` + ``bgm_solver`` + the FMI 2.0 / 3.0
   wrappers) and the official FMI headers shipped with fmpy (:mod:`~bgmodelica.fmi.csources`);
4. compiles a shared library with the system C compiler and zips ``<model_name>.fmu`` with the
   sources included (:mod:`~bgmodelica.fmi.build`).

Co-Simulation solver.  Electromechanical models are stiff (electrical time constants of
microseconds next to mechanical ones of seconds), so the embedded solver must be L-stable; it
must also be cheap per communication step, self-contained C and accurate enough that the
communication step, not the solver, dominates the error.  We use variable-order (1-5),
variable-step backward differentiation formulas (the NDF variant of Shampine & Reichelt, as in
MATLAB's ode15s and scipy's BDF), the family CVODES and IDAS use: one function evaluation per
Newton iteration, a Jacobian (CasADi-generated) and a dense LU with partial pivoting reused
over many steps.  The history is kept between communication steps when nothing changed, and a
step may pass the communication point (the state there is interpolated), so short
communication steps do not cut the solver's steps.  The paper's robot takes 855 steps in 10 s
at tolerance 1e-6 (the order-4 SDIRK alone needed 9435).  New inputs (held over the step, a jump
of the right-hand side) would force a restart at order 1 with many small steps, at every step
of a co-simulation; such steps are taken by the 5-stage order-4 L-stable SDIRK of Hairer &
Wanner instead (``bgm_sdirk.c``; one LU per step serves all stages), which needs no history.
Tunable parameters ``solver.tolerance`` (default: the spec's ``tolerance``, 1e-6; the tighter of
it and a tolerance passed by the importer is used) and ``solver.max_step`` (default: the
experiment length) control it; inputs are held over each communication step.

Models with events: :mod:`~bgmodelica.fmi.hybrid` generates the native event functions into the
FMU and ``templates/bgm_events.c`` ports the native event loop (event indicators and event
iteration for Model Exchange, event location inside ``DoStep`` for Co-Simulation).
"""

from .build import FmuBuildError
from .export import export_fmu
from .spec import FmuExportError, FmuSpec, FmuSpecError, ScalarVariable

__all__ = ["FmuBuildError", "FmuExportError", "FmuSpec", "FmuSpecError", "ScalarVariable",
           "export_fmu"]
