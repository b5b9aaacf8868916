"""Bond graphs as first-class models.

Elements (:mod:`.elements`): ``Se, Sf, R, C, I, TF, GY, MTF, MGY, ZeroJunction (J0),
OneJunction (J1), De, Df, Dq, Sw`` (Sw: switch of hybrid bond graphs) with
:class:`PowerPort` s; :class:`BondGraph` components with
``bond(a, b)`` and ``expose(name, target)``; the pure :class:`Graph` (``graph_of``);
causality (SCAP, BGI/BGD views), structural controllability/observability, causal equations
(text, LaTeX), ``analyze(model) -> BondGraphReport`` and ``draw(model, path)``.
"""

from .causality import (
    BGD,
    BGI,
    Causality,
    Conflict,
    IdealMode,
    assign_causality,
    ideal_modes,
)
from .draw import draw, layout
from .elements import (
    GY,
    J0,
    J1,
    MGY,
    MTF,
    TF,
    BGElement,
    C,
    De,
    Df,
    Dq,
    I,
    OneJunction,
    PowerPort,
    R,
    Se,
    Sf,
    ZeroJunction,
    bond_flow,
    orientation,
)
from .equations import CausalEquations, causal_equations
from .errors import (
    BondError,
    BondGraphError,
    CausalConflictError,
    JunctionError,
    ModulusError,
)
from .graph import Bond, Graph, Node
from .model import BondGraph, graph_of
from .report import BondGraphReport, analyze
from .signal_flow import signal_graph
from .structural import StructuralProperty, controllability, observability
from .switch import Sw

__all__ = [
    "PowerPort", "BGElement", "Se", "Sf", "R", "C", "I", "TF", "GY", "MTF", "MGY",
    "ZeroJunction", "OneJunction", "J0", "J1", "De", "Df", "Dq", "Sw", "orientation",
    "bond_flow",
    "BondGraph", "graph_of", "Graph", "Node", "Bond",
    "assign_causality", "Causality", "Conflict", "BGI", "BGD", "signal_graph",
    "ideal_modes", "IdealMode",
    "controllability", "observability", "StructuralProperty",
    "causal_equations", "CausalEquations",
    "analyze", "BondGraphReport", "draw", "layout",
    "BondGraphError", "BondError", "JunctionError", "ModulusError", "CausalConflictError",
]
