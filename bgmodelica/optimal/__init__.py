"""Optimal control on compiled models: ``optimize`` (direct collocation, IPOPT) and its
result."""

from .problem import OptimizationError
from .result import OptimalControl
from .solve import optimize

__all__ = ["optimize", "OptimalControl", "OptimizationError"]
