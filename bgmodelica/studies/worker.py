"""Worker preload: ``dask worker tcp://HOST:8786 --nthreads 1 --preload
bgmodelica.studies.worker`` imports bgmodelica, CasADi and the study code when the worker
starts rather than during the first study (LocalClusters started by
:func:`bgmodelica.studies.sweep` preload it themselves)."""

from __future__ import annotations

import casadi  # noqa: F401

from .. import simulate  # noqa: F401
from . import payload, sweeps  # noqa: F401
