"""Models made of components and connections, on the array path.

A ladder of resistors and capacitors, a discretized line or shaft, a ladder of sections
each holding a resistor and a capacitor: a tree of components (each declaring its
connectors before its subcomponents) joined by ``connect`` statements at any level. Such a
model is collected without a Python object per scalar:

- the equations of many leaf components of one class are written once for all of them,
  wherever they sit in the tree (:func:`~bgmodelica.core.flatten_vectorized.tree_groups`,
  :func:`~bgmodelica.core.flatten_vectorized.array_equations`), the others are asked one
  by one and their scalar equations grouped by shape (:mod:`.scalars`);
- the columns follow the scalar pipeline's order (the tree, each variable followed by its
  derivative), computed per class and per declaration with numpy (:mod:`.columns`);
- the connection sets of every level become linear rows (:mod:`.connections`), a
  connector connected inside its own component counted from outside, as Modelica does.

Anything else (signal connections, connectors of the top level, initial equations,
events) goes the scalar way.
"""

from __future__ import annotations

from operator import attrgetter
from typing import Any, NamedTuple

import numpy as np

from ..core.arrays import _SMOOTH_OPS, ArrayEquation
from ..core.component import Component, Connection, Connector, _own_methods
from ..core.expr import Equation
from ..core.flatmodel import EquationSources
from ..core.flatten import _side_shape
from ..core.flatten_connections import connection_set_arrays
from ..core.flatten_vectorized import (
    _class_groups,
    array_equations,
    group_connections,
    tree_groups,
)
from ..core.variables import TIME
from .collect import Collected
from .columns import Columns, memo_of
from .connections import set_rows
from .scalars import ScalarGroup

_A, _B = attrgetter("a"), attrgetter("b")


def collect_components(model: Component, minimum: int) -> Any:
    """The :class:`~.collect.Collected` of a model of components, or why it goes the
    scalar way."""
    tree = _tree(model, minimum)
    if isinstance(tree, str):
        return tree
    name = model.name or type(model).__name__
    where = f"top level ({type(model).__name__})"
    equations = _Equations(model, tree, where)
    if equations.refused is not None:
        return equations.refused
    elements = {"": model, **tree.components} if model._symbols else tree.components
    cols = Columns(elements, [items for items, _ in equations.groups])
    if cols.refused is not None:
        return cols.refused
    rows = _connections(equations.ends, equations.sides, cols)
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


class _Tree(NamedTuple):
    """The components below the top level by path, in tree order (``components``), and
    the components holding components, the top level first (``parents``, by path)."""

    components: dict[str, Component]
    parents: list[tuple[str, Component]]


def _tree(model: Component, minimum: int) -> _Tree | str:
    """The model's tree, or why it is not components joined by ``connect`` (connectors
    before subcomponents in each component, none at the top level), or "small"."""
    if "_arrays" in model.__dict__ and any(not isinstance(c, Component)
                                           for c in model._children.values()):
        return "it has arrays of connectors"
    initial = (Component.initial_equations,)
    if _own_methods(type(model), "initial_equations") != initial \
            or model.__dict__.get("_initial_equations"):
        return "it has initial equations"
    components: dict[str, Component] = {}
    parents: list[tuple[str, Component]] = []
    size = len(model._symbols)
    stack: list[tuple[str, Any]] = [("", model)]
    while stack:                            # each element read once
        path, elem = stack.pop()
        if elem is not model:
            components[path] = elem
            if elem.__dict__.get("_initial_equations"):
                return "a subcomponent has initial equations"
        below: list[tuple[str, Any]] = []
        for key, sub in elem._children.items():
            if isinstance(sub, Connector):
                if elem is model:
                    return "it has connectors of its own"
                if below:
                    return f"{path} declares a connector after a subcomponent"
                if sub._children:
                    return "a connector has connectors of its own"
                size += len(sub._symbols)
            elif isinstance(sub, Component):
                below.append((f"{path}.{key}" if path else key, sub))
                size += len(sub._symbols)
            else:
                return "it has connectors of its own"
        if below:
            parents.append((path, elem))
            stack.extend(reversed(below))
    for cls in set(map(type, components.values())):
        if cls is Component:
            return "a subcomponent is a plain Component"
        if _own_methods(cls, "initial_equations") != initial:
            return "a subcomponent has initial equations"
    return "small" if size < minimum else _Tree(components, parents)


class _Equations:
    """The model's equations in the scalar pipeline's order: the groups of components
    written once, then the others' one by one in tree order; the connections of every
    level in tree order, as their ends (``ends``: two lists) and whether each end is seen
    from outside its component, i.e. connected inside it (``sides``); the connections of
    many composites of one class are written once too. ``refused`` says why the model goes
    the scalar way."""

    def __init__(self, model: Component, tree: _Tree, where: str) -> None:
        from ..validate import guarded_equations

        self.items: list[Any] = []
        self.shapes: dict[Any, ScalarGroup] = {}     # scalar equations by shape
        self.arrays: list[tuple[ArrayEquation, str, list[str] | None]] = []
        self.refused: str | None = None
        self.groups: list[tuple[list[Any], dict]] = []     # (components, arrays they read)
        self.ends: tuple[list[Any], list[Any]] = ([], [])
        self.sides: list[tuple[bool, bool]] = []
        self._rank: list[np.ndarray] = []           # each link's (component, place)
        place = {id(c): k for k, c in enumerate(tree.components.values(), start=1)}
        if not self._level(model, guarded_equations(model, where, "", blocks=True), where, 0):
            return
        done: set[int] = set()
        for names, items in tree_groups(tree.components, tree.parents):
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
        for _, items in _class_groups((path, c) for path, c in tree.parents if c is not model):
            pairs = group_connections(items)
            if pairs is None:
                continue
            at = np.fromiter(map(place.__getitem__, map(id, items)), np.int64, len(items))
            own = items[0]._children
            for j, (a, b) in enumerate(pairs):
                self.ends[0].extend(a._items)
                self.ends[1].extend(b._items)
                ends = (own.get(a._items[0]._name) is a._items[0],
                        own.get(b._items[0]._name) is b._items[0])
                self.sides.extend([ends] * len(items))
                self._rank.append(np.column_stack((at, np.full(at.size, j))))
            done.update(map(id, items))
        for path, child in tree.components.items():
            if id(child) in done:
                continue
            where = f"{path} ({type(child).__name__})"
            if not self._level(child, guarded_equations(child, where, path, blocks=True),
                               where, place[id(child)]):
                return
        self._tree_order()

    def _level(self, elem: Component, equations: list[Any], where: str, at: int) -> bool:
        """Add the connections and equations of one component, ``at`` its place in the tree
        (False, with ``refused`` set, if they are not for the array path)."""
        links = [eq for eq in equations if type(eq) is Connection]
        if not links:
            return self._take(equations, where)
        if not _connectors_only(links):
            self.refused = "the top level connects signals" if not elem._name else \
                f"{where} connects signals"
            return False
        own = elem._children
        self.ends[0].extend(map(_A, links))
        self.ends[1].extend(map(_B, links))
        self.sides.extend((own.get(eq.a._name) is eq.a, own.get(eq.b._name) is eq.b)
                          for eq in links)
        self._rank.append(np.column_stack((np.full(len(links), at),
                                           np.arange(len(links)))))
        return len(links) == len(equations) or self._take(
            [eq for eq in equations if type(eq) is not Connection], where)

    def _tree_order(self) -> None:
        """The connections in the order the scalar pipeline meets them: by component in
        tree order, then as written."""
        if not self._rank:
            return
        rank = np.concatenate(self._rank)
        order = np.lexsort((rank[:, 1], rank[:, 0]))
        if (order[1:] > order[:-1]).all():
            return
        self.ends = (list(map(self.ends[0].__getitem__, order)),
                     list(map(self.ends[1].__getitem__, order)))
        self.sides = list(map(self.sides.__getitem__, order))

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


def _connections(ends: tuple[list[Any], list[Any]], sides: list[tuple[bool, bool]],
                 cols: Columns) -> list[Any] | str:
    """The connection sets' equations as linear rows, or why they go the scalar way
    (``ends``: the connections' first and second connectors; ``sides``: whether each is
    connected from inside its component)."""
    index = cols.connector
    n_c = len(cols.paths)
    n_links = len(sides)
    try:
        heads = np.fromiter(map(index.__getitem__, map(id, ends[1])), np.int64, n_links)
        tails = np.fromiter(map(index.__getitem__, map(id, ends[0])), np.int64, n_links)
    except KeyError:
        return "a connection uses a connector that is not part of the model"
    if (heads == tails).any():
        return "a connector is connected to itself"
    if n_c == 0:
        return []
    side = np.array(sides, dtype=np.int64).reshape(-1, 2)
    nodes, cuts = connection_set_arrays(n_c, 2 * heads + side[:, 1], 2 * tails + side[:, 0],
                                        cols.paths)
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
