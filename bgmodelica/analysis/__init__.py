"""Control-engineering analyses of compiled models: operating points (start values, steady
states, a time of a simulation), linearization by algorithmic differentiation of the
index-reduced DAE, numeric controllability and observability (staircase form), and their
comparison with the structural properties of bond graphs.

    import bgmodelica as bg
    op = bg.steady_state(model, {"U1": 1.2})          # der(x) = 0, start values as guesses
    sys = bg.linearize(model, {"U1": 1.2}, steady_state=True)   # python-control StateSpace
"""

from .controllability import RankResult, controllability, observability
from .linearize import Linearization, linearization, linearize, linearize_at
from .steady_state import OperatingPoint, operating_point, steady_state

__all__ = ["OperatingPoint", "operating_point", "steady_state", "Linearization", "linearize",
           "linearization", "linearize_at", "RankResult", "controllability", "observability"]
