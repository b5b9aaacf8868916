"""Native re-implementations of the MSL's ``external "C"`` functions.

:data:`IMPLEMENTATIONS` maps the C function name of an ``external "C" ... = NAME(...)``
clause to a Python callable. The callable takes the arguments of that external call in their
order, evaluated: Integer/Real/Boolean/String as Python numbers, bools and strings,
enumerations as their 1-based index, arrays as numpy arrays, external objects as the objects
the ``init`` functions return; time-varying Real arguments of table lookups may be symbolic
(an expression of :mod:`bgmodelica.core.expr` or CasADi SX/MX), which gives a symbolic
result. Output arguments of the call (passed by reference in C) may be passed as
placeholders or left out. It returns the C function's result; when the call also has output
arguments, a tuple: the result first (if any), then the output arguments in call order.

Families: :mod:`.tables` (ModelicaStandardTables), :mod:`.strings` (ModelicaStrings),
:mod:`.files` (ModelicaInternal, ModelicaStreams, ModelicaIO), :mod:`.fft` (ModelicaFFT).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from . import fft, files, strings, tables
from .errors import ExternalFunctionError, ExtrapolationError, TableError
from .tables import CombiTable1D, CombiTimeTable, in_range, time_breakpoints, valid_range

IMPLEMENTATIONS: dict[str, Callable[..., Any]] = {
    **tables.REGISTRY, **strings.REGISTRY, **files.REGISTRY, **fft.REGISTRY,
}

__all__ = ["IMPLEMENTATIONS", "CombiTable1D", "CombiTimeTable", "time_breakpoints",
           "valid_range", "in_range", "ExternalFunctionError", "TableError",
           "ExtrapolationError"]
