"""Errors of the re-implemented MSL external functions."""

from __future__ import annotations

from ...errors import ModelError


class ExternalFunctionError(ModelError):
    """An MSL external function cannot be evaluated (bad arguments, file problems...)."""


class TableError(ExternalFunctionError, ValueError):
    """A table (CombiTable1D, CombiTimeTable) is invalid: empty, abscissa not increasing,
    a column out of range, an unreadable table file. The message names the table."""


class ExtrapolationError(TableError):
    """A table with ``extrapolation = NoExtrapolation`` was evaluated outside its abscissa
    range."""
