"""Scalar equations on the array path, grouped by shape.

Equations of one structural shape (``v == R*i`` of many components asked one by one, the
``p.v == 0`` of a ground) are lowered together, as the scalar pipeline's flattening groups
them: one MX block whose operands are the columns of each leaf position across the members.
The groups come in the order their shapes were first seen, members in the order written,
which is also the order in which the scalar pipeline meets their alias links.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from ..core.arrays import ArrayEquation
from ..core.expr import Equation
from ..core.flatten import _side_shape
from .connections import LinearRows


@dataclass
class ScalarGroup:
    """Scalar equations of one shape ``key`` (``(lhs shape, rhs shape)``, see
    :func:`~bgmodelica.core.expr.shape_of`): each member's leaf symbols and constants, in
    the order of the shape."""

    key: tuple[Any, Any]
    leaves: list[list[Any]] = field(default_factory=list)
    consts: list[list[float]] = field(default_factory=list)
    equations: list[Equation] = field(default_factory=list)
    wheres: list[str] = field(default_factory=list)

    @property
    def shape(self) -> tuple[int]:
        return (len(self.leaves),)

    def __len__(self) -> int:
        return len(self.leaves)


def group_scalars(equations: list[Any]) -> list[Any]:
    """``equations`` with the scalar ones replaced by their :class:`ScalarGroup`, each at
    the place of its first member (groups made before are kept as they are)."""
    out: list[Any] = []
    groups: dict[Any, ScalarGroup] = {}
    for eq in equations:
        if isinstance(eq, (ArrayEquation, LinearRows, ScalarGroup)):
            out.append(eq)
            continue
        leaves: list[Any] = []
        consts: list[float] = []
        key = (_side_shape(eq.lhs, leaves, consts), _side_shape(eq.rhs, leaves, consts))
        group = groups.get(key)
        if group is None:
            group = groups[key] = ScalarGroup(key)
            out.append(group)
        group.leaves.append(leaves)
        group.consts.append(consts)
        group.equations.append(eq)
    return out
