"""FMU export (FMI 2.0 and 3.0, Model Exchange and Co-Simulation) of compiled models.

The compiler hands an :class:`FmuSpec` (explicit ODE with outputs, as CasADi functions) to
:func:`export_fmu`, which generates C with CasADi, adds our own FMI runtime (``templates/``),
compiles it with the system C compiler and zips ``<model_name>.fmu``.
"""

from .build import FmuBuildError
from .export import export_fmu
from .spec import FmuExportError, FmuSpec, FmuSpecError, ScalarVariable

__all__ = ["FmuBuildError", "FmuExportError", "FmuSpec", "FmuSpecError", "ScalarVariable",
           "export_fmu"]
