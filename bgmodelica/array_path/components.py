"""Models made of leaf components and connections, on the array path.

A ladder of resistors and capacitors, a discretized line or shaft: a top-level component
whose subcomponents are leaf components (connectors, no subcomponents of their own), joined
by ``connect`` statements. Such a model is collected without a Python object per scalar:

- the equations of many components of one class are written once for all of them
  (:func:`~bgmodelica.core.flatten_vectorized.array_equations`, as the scalar pipeline
  groups them), the others are asked one by one and their scalar equations grouped by shape
  (:mod:`.scalars`);
- the columns follow the scalar pipeline's order (the tree, each variable followed by its
  derivative), computed per class and per declaration with numpy (:mod:`.columns`);
- the connection sets become linear rows (:mod:`.connections`).

Anything else (subcomponents with subcomponents, signal connections, connectors of the top
level, initial equations, events) goes the scalar way.
"""

from __future__ import annotations

from operator import attrgetter
from typing import Any

import numpy as np

from ..core.arrays import _SMOOTH_OPS, ArrayEquation
from ..core.component import Component, Connection, Connector, _own_methods
from ..core.expr import Equation
from ..core.flatmodel import EquationSources
from ..core.flatten import _side_shape
from ..core.flatten_connections import connection_set_arrays
from ..core.flatten_vectorized import GROUP_FROM, array_equations, component_groups
from ..core.variables import TIME
from .collect import Collected
from .columns import Columns, memo_of
from .connections import set_rows
from .scalars import ScalarGroup

_A, _B = attrgetter("a"), attrgetter("b")


def collect_components(model: Component, minimum: int) -> Any:
    """The :class:`~.collect.Collected` of a model of leaf components, or why it goes the
    scalar way."""
    children = model._children
    found = _shape_check(model, children, minimum)
    if found is not None:
        return found
    name = model.name or type(model).__name__
    where = f"top level ({type(model).__name__})"
    equations = _Equations(model, children, where)
    if equations.refused is not None:
        return equations.refused
    elements = {"": model, **children} if model._symbols else children   # in tree order
    cols = Columns(elements, [items for items, _ in equations.groups])
    if cols.refused is not None:
        return cols.refused
    rows = _connections(equations.links, cols)
    if isinstance(rows, str):
        return rows
    all_equations = [*rows, *equations.items]
    n_rows = sum(map(len, all_equations))
    if n_rows < minimum:
        return "small"
    pos = cols.pos
    pos[id(TIME)] = cols.n + len(cols.params)
    memo = memo_of(equations.groups, cols, elements)
    sources = EquationSources(groups=equations.unit_groups(), arrays=equations.arrays)
    return Collected(name, where, cols.order, cols.params, all_equations, n_rows, pos, memo,
                     0, cols.names, cols.param_names, cols.param_owners, sources, True,
                     cols.traits)


def _shape_check(model: Component, children: dict[str, Any], minimum: int) -> str | None:
    """Why the tree is not leaf components under a top level of connections (None: it is),
    or "small"."""
    if "_arrays" in model.__dict__ and any(not isinstance(c, Component)
                                           for c in children.values()):
        return "it has arrays of connectors"
    initial = (Component.initial_equations,)
    if _own_methods(type(model), "initial_equations") != initial \
            or model.__dict__.get("_initial_equations"):
        return "it has initial equations"
    for cls in set(map(type, children.values())):
        if not issubclass(cls, Component):
            return "it has connectors of its own"
        if cls is Component:
            return "a subcomponent is a plain Component"
        if _own_methods(cls, "initial_equations") != initial:
            return "a subcomponent has initial equations"
    size = 0
    for child in children.values():            # one pass: each element read once
        if child.__dict__.get("_initial_equations"):
            return "a subcomponent has initial equations"
        size += len(child._symbols)
        for sub in child._children.values():
            if not isinstance(sub, Connector) or sub._children:
                return "a subcomponent has subcomponents"
            size += len(sub._symbols)
    return "small" if size < minimum else None


class _Equations:
    """The model's equations in the scalar pipeline's order: the groups of components
    written once, then the others' one by one; ``links`` are the top level's connections,
    ``refused`` says why the model goes the scalar way."""

    def __init__(self, model: Component, children: dict[str, Any], where: str) -> None:
        from ..validate import guarded_equations

        self.items: list[Any] = []
        self.shapes: dict[Any, ScalarGroup] = {}     # scalar equations by shape
        self.arrays: list[tuple[ArrayEquation, str, list[str] | None]] = []
        self.refused: str | None = None
        self.groups: list[tuple[list[Any], dict]] = []     # (components, arrays they read)
        top = guarded_equations(model, where, "", blocks=True)
        self.links = [eq for eq in top if type(eq) is Connection]
        if not _connectors_only(self.links):
            self.refused = "the top level connects signals"
            return
        if len(self.links) < len(top) and not self._take(
                [eq for eq in top if type(eq) is not Connection], where):
            return
        done: set[int] = set()
        if len(children) >= GROUP_FROM or "_arrays" in model.__dict__:
            for names, items in component_groups(model):
                arrays: dict[tuple[str | None, str], Any] = {}
                eqs = array_equations(items, arrays)
                if eqs is None:
                    continue
                self.groups.append((items, arrays))
                cls = type(items[0]).__name__
                origin = f"{names[0]} .. {names[-1]} ({len(items)} {cls} components)"
                wheres = [f"{name} ({cls})" for name in names]
                self.items.extend(eqs)
                self.arrays.extend((eq, origin, wheres) for eq in eqs)
                done.update(map(id, items))
        for path, child in children.items():
            if id(child) in done:
                continue
            where = f"{path} ({type(child).__name__})"
            if not self._take(guarded_equations(child, where, path, blocks=True), where):
                return

    def _take(self, equations: list[Any], where: str) -> bool:
        """Add the equations of one component (False, with ``refused`` set, if they are not
        for the array path)."""
        shapes = self.shapes
        for eq in equations:
            if isinstance(eq, ArrayEquation):
                self.arrays.append((eq, where, None))
                self.items.append(eq)
                continue
            leaves: list[Any] = []
            consts: list[float] = []
            try:
                if type(eq) is not Equation:
                    raise TypeError(eq)
                key = (_side_shape(eq.lhs, leaves, consts), _side_shape(eq.rhs, leaves, consts))
                group = shapes.get(key)
                if group is None:
                    if not (_smooth(key[0]) and _smooth(key[1])):
                        raise TypeError(key)
                    group = shapes[key] = ScalarGroup(key)
                    self.items.append(group)
            except (TypeError, AttributeError):
                self.refused = f"{where} has an equation that is not smooth arithmetic"
                return False
            group.leaves.append(leaves)
            group.consts.append(consts)
            group.equations.append(eq)
            group.wheres.append(where)
        return True

    def unit_groups(self) -> dict[Any, list]:
        """The scalar equations as the unit check reads them (shape -> members)."""
        return {key: list(zip(g.leaves, g.consts, g.wheres, g.equations, strict=True))
                for key, g in self.shapes.items()}


def _connectors_only(links: list[Connection]) -> bool:
    """Whether every connection joins two connectors (not signals)."""
    ends = set(map(type, map(_A, links))) | set(map(type, map(_B, links)))
    return all(issubclass(t, Connector) for t in ends)


def _smooth(shape: Any) -> bool:
    """Whether an equation shape is made of leaves, constants and smooth operations."""
    if isinstance(shape, str):
        return True
    return shape[0] in _SMOOTH_OPS and all(map(_smooth, shape[1:]))


def _connections(links: list[Connection], cols: Columns) -> list[Any] | str:
    """The connection sets' equations as linear rows, or why they go the scalar way."""
    index = cols.connector
    n_c = len(cols.paths)
    try:
        heads = np.fromiter(map(index.__getitem__, map(id, map(_B, links))), np.int64,
                            len(links))
        tails = np.fromiter(map(index.__getitem__, map(id, map(_A, links))), np.int64,
                            len(links))
    except KeyError:
        return "a connection uses a connector that is not part of the model"
    if (heads == tails).any():
        return "a connector is connected to itself"
    if n_c == 0:
        return []
    nodes, cuts = connection_set_arrays(n_c, 2 * heads, 2 * tails, cols.paths)
    starts = np.concatenate(([0], cuts)).astype(np.int64)
    set_of = np.repeat(np.arange(starts.size), np.diff(np.concatenate((starts, [nodes.size]))))
    kind = cols.kind_of[nodes >> 1]
    if (kind != kind[starts][set_of]).any():
        return "a connection set joins connectors of different kinds"
    out: list[Any] = []
    for k, (keys, flows) in enumerate(cols.kinds):
        mine = kind[starts] == k
        if not mine.any():
            continue
        keep = mine[set_of]
        sizes = np.diff(np.concatenate((starts, [nodes.size])))[mine]
        sub_cuts = np.cumsum(sizes)[:-1]
        out.extend(set_rows(nodes[keep], sub_cuts, cols.columns[:, :len(keys)], flows))
    return out
