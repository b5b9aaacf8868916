"""Errors of the Modelica reader and writer: one line, with ``file:line:column`` when known."""

from __future__ import annotations

from ..errors import ModelLoadError


class ModelicaError(ModelLoadError):
    """A Modelica file cannot be read or a class cannot be instantiated (unknown name,
    unsupported construct, wrong modifier...). The message starts with ``file:line:column``
    when the construct at fault has a position."""


class ModelicaSyntaxError(ModelicaError):
    """The text is not Modelica (or not of the subset bgmodelica reads)."""

    def __init__(self, file: str, line: int, column: int, message: str) -> None:
        super().__init__(f"{file}:{line}:{column}: {message}")
        self.file = file
        self.line = line
        self.column = column
        self.detail = message


class ModelicaExportError(ModelicaError):
    """A model cannot be written as Modelica (names the construct and the component)."""
