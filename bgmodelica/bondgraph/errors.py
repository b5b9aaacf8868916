"""Errors of bond-graph models. All subclass :class:`bgmodelica.errors.ModelError` and name
the element (dotted path) they are about in ``element``."""

from __future__ import annotations

from ..errors import ModelError


class BondGraphError(ModelError):
    """Base class of bond-graph errors. ``element`` is the dotted path of the culprit."""

    def __init__(self, message: str, element: str | None = None) -> None:
        super().__init__(message)
        self.element = element


class BondError(BondGraphError):
    """A bond names a missing port or element, reuses a bonded port, or has an impossible
    direction (a TF/GY whose two bonds both point in or both point out)."""


class JunctionError(BondGraphError):
    """A 0- or 1-junction has fewer than two bonds."""


class ModulusError(BondGraphError):
    """A modulus or constitutive-law expression is malformed or uses an unknown name."""


class CausalConflictError(BondGraphError):
    """Sources (or detectors) impose contradictory causality: e.g. two effort sources on one
    0-junction. The model is structurally singular. ``conflicts`` lists every conflict."""

    def __init__(self, message: str, element: str | None = None,
                 conflicts: list | None = None) -> None:
        super().__init__(message, element)
        self.conflicts = conflicts or []
