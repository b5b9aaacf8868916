"""Many-run studies on a compiled model: parameter sweeps and Monte Carlo on Dask
(:func:`sweep`, in :mod:`.sweeps`), forward sensitivities (:mod:`.sensitivity`, also through
``simulate(..., sensitivities=[...])``) and parameter estimation (:func:`fit`, in
:mod:`.fitting`).

Every study takes a :class:`~bgmodelica.compiler.CompiledModel` (or compiles a component
once) and only changes parameters between runs. Dask and xarray are imported when a study
runs, not with this package.
"""

from __future__ import annotations

from .fitting import Experiment, FitResult, fit
from .identifiability import IdentifiabilityError
from .sensitivity import finite_difference_sensitivities, sensitivities
from .sweeps import SweepResult, sweep

__all__ = ["sweep", "SweepResult", "fit", "FitResult", "Experiment", "IdentifiabilityError",
           "sensitivities", "finite_difference_sensitivities"]
