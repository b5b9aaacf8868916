"""Errors of the co-simulation package; all are :class:`bgmodelica.errors.ModelError`, so the
command line prints them as one line and exits with status 2."""

from __future__ import annotations

from ..errors import ModelError


class CosimError(ModelError):
    """Base class of the co-simulation errors."""


class SetupError(CosimError):
    """The co-simulation set-up (SSP system) is inconsistent."""


class ArchiveError(SetupError):
    """An FMU or SSP file cannot be used as an archive: it does not exist, is not a zip file,
    is truncated or corrupt (bad CRC, broken compressed data), encrypted, or lacks its
    ``modelDescription.xml`` / ``SystemStructure.ssd``. The message names the file (and the
    member at fault)."""


class UnsafeArchiveError(ArchiveError):
    """An archive would write outside its extraction folder or exhaust the disk: a member
    name with ``..`` components, an absolute path or a drive letter, a symbolic link or
    other special file, a name that occurs twice, or more uncompressed bytes (or members)
    than the limit (a zip bomb). Nothing is extracted from such an archive."""


class FmuFormatError(ArchiveError):
    """An FMU cannot be read: see :class:`ArchiveError`, or its ``modelDescription.xml`` is
    malformed or not a valid FMI 2.0/3.0 model description."""


class SspFormatError(ArchiveError):
    """An ``.ssp``/``.ssd`` file cannot be read (not a zip, missing or malformed SSD, missing
    resource, unsupported content, unsafe resource paths)."""


class DuplicateElementError(SetupError):
    """Two components of a system, two connectors of one component or two values of one
    parameter set share a name."""


class InvalidParameterError(SetupError):
    """A parameter binding or override cannot be applied: the value is not finite or lies
    outside the variable's ``[min, max]``, or the variable is not settable (a constant, a
    calculated parameter, an output, a local...)."""


class InvalidExperimentError(SetupError):
    """Start time, stop time, macro step or recording options are not usable: not finite,
    not positive, or so large/small that the run would need an absurd number of steps (the
    message gives the number)."""


class UnknownConnectorError(SetupError):
    """A connection or parameter binding names an element or connector that does not exist."""


class UnconnectedInputError(SetupError):
    """An input of an element is not driven by any connection (``inputs`` lists them as
    ``element.connector``)."""

    def __init__(self, message: str, inputs: list[str] | None = None) -> None:
        super().__init__(message)
        self.inputs = inputs or []


class ConnectorMismatchError(SetupError):
    """A connection joins connectors of different types or units, or of wrong causality
    (e.g. output to output), or one input is driven twice."""


class AlgebraicLoopError(SetupError):
    """The connections close a cycle of direct feedthrough (output depends on input without a
    state in between) through the subsystems: a fixed-step master cannot evaluate it.
    ``cycle`` lists the connectors along the loop (``element.connector``)."""

    def __init__(self, message: str, cycle: list[str] | None = None) -> None:
        super().__init__(message)
        self.cycle = cycle or []


class CosimStepError(CosimError):
    """An FMU call failed during the co-simulation (``element`` names the unit, ``time`` the
    communication point)."""

    def __init__(self, message: str, element: str = "", time: float = float("nan")) -> None:
        super().__init__(message)
        self.element = element
        self.time = time
