"""Errors of the Modelica reader and writer: one line, with ``file:line:column`` when known."""

from __future__ import annotations

import re
from typing import Any

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


def internal_text(err: BaseException) -> str:
    """One short line for an exception of Python or CasADi that a Modelica construct caused:
    its type and the gist of its message (CasADi's source locations dropped)."""
    if isinstance(err, RecursionError):
        return "nested too deeply (recursion limit reached; a recursive definition or a " \
            "very deep expression?)"
    lines = [ln for ln in str(err).splitlines() if ln.strip()]
    text = lines[-1] if lines else ""
    text = re.sub(r"^(\S*\.(?:cpp|hpp|h):\d+:\s*)+", "", text.strip())
    text = " ".join(text.split())
    if len(text) > 200:
        text = text[:200] + "..."
    return f"unsupported construct or internal error ({type(err).__name__}: {text})"


def compile_failure(model: Any, err: BaseException, stage: str = "compile"
                    ) -> ModelicaError | None:
    """For a model read from Modelica, an internal exception of its compilation (or
    simulation: ``stage``) as one line at the model's class (None for other models)."""
    where = getattr(model, "__dict__", {}).get("_mo_where")
    if where is None:
        return None
    return ModelicaError(f"{where}: cannot {stage} this model: {internal_text(err)}")


def locate_error(model: Any, err: BaseException) -> None:
    """Prefix the message of ``err`` (raised while compiling ``model``) with the position of
    the model's class when the model was read from Modelica and the message names no
    Modelica source position."""
    where = getattr(model, "__dict__", {}).get("_mo_where")
    if where is None or not err.args or _POSITION.search(str(err)):
        return
    err.args = (f"{where}: {err.args[0]}", *err.args[1:])


_POSITION = re.compile(r"\.mo:\d+")
