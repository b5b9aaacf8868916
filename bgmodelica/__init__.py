"""bgmodelica: equation-based, Modelica-like modeling with first-class bond graphs.

Public API::

    from bgmodelica import Component, Connector, Parameter, Variable, Potential, Flow, \
        Input, Output, StateSelect, connect, der, time, compile, simulate
"""

from .core.component import Component, Connection, Connector, connect
from .core.expressions import (
    atan2,
    cos,
    der,
    exp,
    fabs,
    if_else,
    log,
    sign,
    sin,
    sqrt,
    tan,
    tanh,
)
from .core.flatten import flatten
from .core.variables import (
    Flow,
    Input,
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
]

from .compiler import CompiledModel, compile  # noqa: E402
from .result import Result  # noqa: E402
from .simulate import simulate  # noqa: E402

__all__ += ["compile", "simulate", "CompiledModel", "Result"]
