"""Exceptions raised by the structural algorithms.

They carry integer indices only; the caller maps them to variable and equation names.
"""

from __future__ import annotations

from collections.abc import Sequence


class StructuralError(Exception):
    """Base class of every error raised by :mod:`bgmodelica.structure`."""


def _preview(items: Sequence[int], limit: int = 10) -> str:
    shown = ", ".join(str(i) for i in items[:limit])
    return f"[{shown}{', ...' if len(items) > limit else ''}]"


class StructurallySingular(StructuralError):
    """No perfect matching exists between equations and unknowns.

    The Dulmage-Mendelsohn parts are attached: ``overdetermined_eqs``/``overdetermined_vars``
    (more equations than the variables they contain) and ``underdetermined_eqs``/
    ``underdetermined_vars`` (variables that no equation is left to determine).
    """

    def __init__(
        self,
        message: str | None = None,
        *,
        overdetermined_eqs: Sequence[int] = (),
        overdetermined_vars: Sequence[int] = (),
        underdetermined_eqs: Sequence[int] = (),
        underdetermined_vars: Sequence[int] = (),
    ) -> None:
        self.overdetermined_eqs = list(overdetermined_eqs)
        self.overdetermined_vars = list(overdetermined_vars)
        self.underdetermined_eqs = list(underdetermined_eqs)
        self.underdetermined_vars = list(underdetermined_vars)
        if message is None:
            parts = []
            if self.overdetermined_eqs:
                parts.append(
                    f"{len(self.overdetermined_eqs)} equations "
                    f"{_preview(self.overdetermined_eqs)} over-determine "
                    f"{len(self.overdetermined_vars)} variables "
                    f"{_preview(self.overdetermined_vars)}"
                )
            if self.underdetermined_vars:
                parts.append(
                    f"{len(self.underdetermined_vars)} variables "
                    f"{_preview(self.underdetermined_vars)} are under-determined by "
                    f"{len(self.underdetermined_eqs)} equations "
                    f"{_preview(self.underdetermined_eqs)}"
                )
            message = "structurally singular system: " + ("; ".join(parts) or "no details")
        super().__init__(message)


class IndexReductionFailed(StructuralError):
    """Index reduction did not terminate within its differentiation budget."""


class StateSelectionError(StructuralError):
    """Dummy-derivative state selection cannot honour a constraint.

    ``variables`` lists the offending variable indices (e.g. base variables with
    ``always`` priority that would have to lose their state, or invalid columns returned by a
    ``select`` callback).
    """

    def __init__(self, message: str, variables: Sequence[int] = ()) -> None:
        super().__init__(message)
        self.variables = list(variables)
