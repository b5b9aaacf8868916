"""Structural DAE algorithms on integer graphs (no CasADi).

Equations and variables are integers; an :class:`EquationGraph` holds the incidence plus the
time-derivative links. Pipeline: :func:`pantelides` (index reduction) ->
:func:`dummy_derivatives` (state selection) -> :func:`block_lower_triangular` (sorting) ->
:func:`tear` (algebraic loops). :func:`dulmage_mendelsohn` diagnoses singular systems.
"""

from .blt import Block, block_lower_triangular
from .diagnosis import DMDecomposition, check_structurally_nonsingular, dulmage_mendelsohn
from .dummy import ALWAYS, AVOID, DEFAULT, NEVER, PREFER, DummyDerivativeResult, dummy_derivatives
from .errors import (
    IndexReductionFailed,
    StateSelectionError,
    StructuralError,
    StructurallySingular,
)
from .graph import EquationGraph
from .matching import Matching, augment, maximum_matching, preferred_column_matching
from .pantelides import PantelidesResult, pantelides
from .tearing import Tearing, tear

__all__ = [
    "ALWAYS",
    "AVOID",
    "DEFAULT",
    "NEVER",
    "PREFER",
    "Block",
    "DMDecomposition",
    "DummyDerivativeResult",
    "EquationGraph",
    "IndexReductionFailed",
    "Matching",
    "PantelidesResult",
    "StateSelectionError",
    "StructuralError",
    "StructurallySingular",
    "Tearing",
    "augment",
    "block_lower_triangular",
    "check_structurally_nonsingular",
    "dulmage_mendelsohn",
    "dummy_derivatives",
    "maximum_matching",
    "pantelides",
    "preferred_column_matching",
    "tear",
]
