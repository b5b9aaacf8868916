"""Errors of the co-simulation package; all are :class:`bgmodelica.errors.ModelError`, so the
command line prints them as one line and exits with status 2."""

from __future__ import annotations

from ..errors import ModelError


class CosimError(ModelError):
    """Base class of the co-simulation errors."""


class SetupError(CosimError):
    """The co-simulation set-up (SSP system) is inconsistent."""


class SspFormatError(SetupError):
    """An ``.ssp``/``.ssd`` file cannot be read (not a zip, missing or malformed SSD, missing
    resource, unsupported content)."""


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
