"""Co-simulation of FMUs: SSP set-ups, a fixed-step master, checks, a cross-check against
``fmucontainer`` and the verification of a co-simulation against the monolithic model.

Modules:

- :mod:`.wrap`: :func:`expose` turns an acausal component into a causal subsystem (connectors
  driven by / returning top-level inputs and outputs) for FMU export;
- :mod:`.ssp`: SSP 1.0 set-ups -- :class:`SystemStructure`, :func:`system_from_fmus`,
  :func:`write_ssp`; :mod:`.ssp_read`: :func:`read_ssp` (defensive reading of archives);
- :mod:`.fmu`: FMU model descriptions and fmpy-based Co-Simulation / Model Exchange units;
- :mod:`.archive`: safe reading and extraction of FMU/SSP zip archives (:class:`SafeZip`);
- :mod:`.checks`: set-up checks (unconnected inputs, type/unit mismatches, algebraic loops);
- :mod:`.master`: :class:`Master` / :func:`cosimulate` -- fixed macro step, Jacobi or
  Gauss-Seidel, optional linear extrapolation, feedthrough propagation;
- :mod:`.xcheck`: :func:`cross_check` against an ``fmucontainer`` container FMU;
- :mod:`.verify`: :func:`verify_model` -> :class:`VerificationReport` (any model against the
  co-simulation of its parts; the robot's study is :mod:`library.robots.verification`);
- :mod:`.cli`: the ``cosim`` and ``verify`` subcommands (:func:`~.cli.register`).

Errors are :class:`bgmodelica.errors.ModelError` subclasses (:mod:`.errors`).
"""

from .archive import SafeZip
from .errors import (
    AlgebraicLoopError,
    ArchiveError,
    ConnectorMismatchError,
    CosimError,
    CosimStepError,
    DuplicateElementError,
    FmuFormatError,
    InvalidExperimentError,
    InvalidParameterError,
    SetupError,
    SspFormatError,
    UnconnectedInputError,
    UnknownConnectorError,
    UnsafeArchiveError,
)
from .master import Master, cosimulate
from .single import simulate_fmu
from .ssp import (
    SspComponent,
    SspConnection,
    SspConnector,
    SystemStructure,
    system_from_fmus,
    write_ssp,
)
from .ssp_read import read_ssp
from .verify import VerificationReport, verify_model
from .wrap import FlowInput, FlowOutput, PotentialInput, PotentialOutput, add_signal, expose

__all__ = [
    "AlgebraicLoopError", "ArchiveError", "ConnectorMismatchError", "CosimError",
    "CosimStepError", "DuplicateElementError", "FmuFormatError", "InvalidExperimentError",
    "InvalidParameterError", "SafeZip", "SetupError", "SspFormatError",
    "UnconnectedInputError", "UnknownConnectorError", "UnsafeArchiveError",
    "Master", "cosimulate", "simulate_fmu", "SspComponent", "SspConnection", "SspConnector",
    "SystemStructure", "read_ssp", "system_from_fmus", "write_ssp", "VerificationReport",
    "verify_model", "FlowInput", "FlowOutput", "PotentialInput", "PotentialOutput",
    "add_signal", "expose",
]
