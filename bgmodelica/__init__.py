"""bgmodelica: equation-based, Modelica-like modeling with first-class bond graphs.

Public API::

    from bgmodelica import Component, Connector, Parameter, Variable, Potential, Flow, \
        Input, Output, StateSelect, connect, der, time, compile, simulate, load_model, export_fmu
"""

from .core.arrays import ArrayExpr, array_of
from .core.component import Component, Connection, Connector, connect
from .core.expressions import (
    atan2,
    cos,
    der,
    exp,
    fabs,
    fmax,
    fmin,
    if_else,
    log,
    sign,
    sin,
    sqrt,
    tan,
    tanh,
)
from .core.flatten import flatten
from .core.hybrid import (
    and_,
    change,
    edge,
    eq,
    if_equation,
    initial,
    no_event,
    noEvent,
    not_,
    or_,
    pre,
    reinit,
    sample,
    terminal,
    time_table,
    when,
)
from .core.variables import (
    Boolean,
    Discrete,
    Flow,
    Input,
    Integer,
    Output,
    Parameter,
    Potential,
    StateSelect,
    Variable,
    time,
)

__version__ = "0.1.0"

__all__ = [
    "Component", "Connection", "Connector", "connect", "der", "time", "flatten",
    "Parameter", "Variable", "Potential", "Flow", "Input", "Output", "StateSelect",
    "sin", "cos", "tan", "exp", "log", "sqrt", "atan2", "fabs", "tanh", "sign", "if_else",
    "fmin", "fmax", "Discrete", "Integer", "Boolean", "when", "reinit", "pre", "edge",
    "change", "initial", "terminal", "sample", "no_event", "noEvent", "eq", "and_", "or_",
    "not_", "if_equation", "time_table", "array_of", "ArrayExpr",
]

from .compiler import CompiledModel, compile  # noqa: E402
from .result import Result  # noqa: E402
from .simulate import simulate  # noqa: E402

__all__ += ["compile", "simulate", "CompiledModel", "Result"]

from .analysis import linearize, steady_state  # noqa: E402

__all__ += ["linearize", "steady_state"]

from .optimal import optimize  # noqa: E402

__all__ += ["optimize"]

from .studies import fit, sweep  # noqa: E402  (Dask and xarray load only when a study runs)

__all__ += ["sweep", "fit"]

from .modelica import export_modelica, load_modelica  # noqa: E402  (lark loads on first use)

__all__ += ["load_modelica", "export_modelica"]

from .fmu_export import export_fmu  # noqa: E402
from .loader import load_model  # noqa: E402

__all__ += ["export_fmu", "load_model"]
