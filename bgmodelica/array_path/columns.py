"""The columns of a model of leaf components on the array path (:mod:`.components`).

The scalar pipeline orders a model's scalars by its tree: each component, then its
connectors, each variable followed by its time derivative, the parameters apart in the same
order. Here that order is worked out per class of component and per declaration with numpy
(:class:`Columns`): no Python object per scalar beyond the symbols themselves, and the alias
traits of the columns (:class:`~.collect.Traits`) come with it.
"""

from __future__ import annotations

from itertools import repeat
from operator import add, attrgetter, is_not, itemgetter, methodcaller
from typing import Any

import numpy as np

from ..core.component import Connector
from ..core.flatten_vectorized import GROUP_FROM, _same_keys
from ..core.variables import Flow, Output, Parameter, Potential, Variable
from .collect import SOFT_STATE_SELECT, Traits

_DECL, _DER, _STATE_SELECT = attrgetter("decl"), attrgetter("der"), attrgetter("state_select")
_FIXED, _START = attrgetter("fixed"), attrgetter("start")
_VALUE, _SYMBOLS, _CHILDREN = attrgetter("value"), attrgetter("_symbols"), attrgetter("_children")
_VARIABLES = (Variable, Output, Potential, Flow)
_NUMBERS = (int, float, np.integer, np.floating)


class Columns:
    """The columns of a model of components, in the scalar pipeline's order: the tree
    (each component, then its connectors, then its subcomponents), each variable followed
    by its derivative; the parameters after them in the same order. Worked out per class
    of component and per declaration: ``pos`` (``id(symbol)`` -> column), ``order`` and
    ``names`` (variables), ``params``, ``param_names`` and ``param_owners``; the
    connectors numbered in tree order (``connector``: ``id`` -> number, ``paths``,
    ``kinds``: their variables' names and whether each is a flow, ``columns``: their
    variables' columns)."""

    def __init__(self, children: dict[str, Any], checked: list[list[Any]]) -> None:
        """``children``: the components by path in tree order (the top level first, as
        ``""``, when it declares variables or parameters; a component's connectors come
        before its subcomponents); ``checked``: groups of components known to share
        their declarations (written once)."""
        self.refused: str | None = None
        paths = list(children)
        items = list(children.values())
        by_class: dict[Any, list[int]] = {}
        by_layout: dict[Any, list[int]] = {}
        for k, child in enumerate(items):
            if paths[k] == "":          # the top level: its own declarations only
                by_layout[(None, tuple(child._symbols), ())] = [k]
                continue
            by_class.setdefault(type(child), []).append(k)
        for cls, members in by_class.items():
            group = [items[k] for k in members]
            if any(map(group.__eq__, checked)) or _same_keys(group):   # one layout per class
                by_layout[(cls, *_layout_key(group[0]))] = members
                continue
            for k in members:
                by_layout.setdefault((cls, *_layout_key(items[k])), []).append(k)
        n_children = len(items)
        self.layouts: list[_Layout] = []
        self.group_of = np.zeros(n_children, dtype=np.int64)    # each child's layout
        self.place_of = np.zeros(n_children, dtype=np.int64)    # and its place in it
        counts = np.zeros(n_children, dtype=np.int64)        # columns of each child
        p_counts = np.zeros(n_children, dtype=np.int64)      # parameters of each child
        c_counts = np.zeros(n_children, dtype=np.int64)      # connectors of each child
        slots = []
        for (_, own, subs), members in by_layout.items():
            group = [items[k] for k in members]
            at = np.asarray(members, dtype=np.int64)
            layout = self._layout(group, own, subs, [paths[k] for k in members])
            if isinstance(layout, str):
                self.refused = layout
                return
            for slot in layout:
                if slot.kind == "parameter":
                    p_counts[at] += 1
                else:
                    counts[at] += 1 + slot.has_der
            c_counts[at] = len(subs)
            slots.append((at, layout, subs))
            self.group_of[at] = len(self.layouts)
            self.place_of[at] = np.arange(at.size)
            self.layouts.append(layout)
        base = np.cumsum(counts) - counts
        p_base = np.cumsum(p_counts) - p_counts
        c_base = np.cumsum(c_counts) - c_counts
        self.n = n = int(counts.sum())
        n_p = int(p_counts.sum())
        n_c = int(c_counts.sum())
        order = np.empty(n, dtype=object)
        names = np.empty(n, dtype=object)
        params = np.empty(n_p, dtype=object)
        param_names = np.empty(n_p, dtype=object)
        param_owners = np.empty(n_p, dtype=object)
        conn_paths = np.empty(n_c, dtype=object)
        kind_ids: dict[tuple[tuple[str, ...], tuple[bool, ...]], int] = {}
        self.kind_of = np.zeros(n_c, dtype=np.int64)
        width = max((len(sub[2]) for _, _, subs in slots for sub in subs), default=0)
        self.columns = np.full((n_c, max(width, 1)), -1, dtype=np.int64)
        self.connector: dict[int, int] = {}
        pos = _Positions()
        traits = self.traits = _traits(n)
        for at, layout, subs in slots:
            col, p_col = base[at].copy(), p_base[at].copy()
            for j, (_, _, keys) in enumerate(subs):
                c = c_base[at] + j
                conn_paths[c] = layout.sub_paths[j]
                self.connector.update(zip(map(id, layout.connectors[j]), c.tolist(),
                                          strict=True))
                flows = tuple(s.kind == "flow" for s in layout if s.sub == j)
                k = kind_ids.setdefault((keys, flows), len(kind_ids))
                self.kind_of[c] = k
            for slot in layout:
                if slot.kind == "parameter":
                    params[p_col] = _objects(slot.symbols)
                    param_names[p_col] = slot.names
                    param_owners[p_col] = slot.owners
                    slot.columns = p_col + n
                    pos.add(slot.symbols, slot.columns, at.size < GROUP_FROM)
                    p_col += 1
                    continue
                order[col] = _objects(slot.symbols)
                names[col] = slot.names
                traits.fill(col, slot)
                slot.columns = col.copy()
                pos.add(slot.symbols, slot.columns, at.size < GROUP_FROM)
                if slot.sub >= 0:
                    self.columns[c_base[at] + slot.sub, slot.index] = col
                if slot.has_der.any():
                    has = slot.has_der.astype(bool)
                    traits.is_der[col[has] + 1] = True
                    ders = [d for d in slot.ders if d is not None]
                    order[col[has] + 1] = _objects(ders)
                    names[col[has] + 1] = [f"der({x})" for x in np.asarray(slot.names,
                                                                           dtype=object)[has]]
                    pos.update(zip(map(id, ders), (col[has] + 1).tolist(), strict=True))
                col += 1 + slot.has_der
        self.pos = pos
        self.order, self.names = order.tolist(), names.tolist()
        self.params, self.param_names = params.tolist(), param_names.tolist()
        self.param_owners = param_owners.tolist()
        self.paths = conn_paths.tolist()
        self.kinds = [(keys, np.array(flows, dtype=bool)) for keys, flows in kind_ids]

    @staticmethod
    def _layout(group: list[Any], own: tuple[str, ...], subs: tuple, paths: list[str]) -> Any:
        """The declarations of components of one class and shape, in tree order, each with
        its symbols across the components (or why they go the scalar way)."""
        out = _Layout()
        places: list[tuple] = [(-1, -1, key, group, paths, paths) for key in own]
        sub_names = [sub_name for sub_name, _, _ in subs]
        for j, (sub_name, _, keys) in enumerate(subs):
            conns = list(map(itemgetter(sub_name), map(_CHILDREN, group)))
            sub_paths = list(map(add, paths, repeat(f".{sub_name}")))
            out.connectors.append(conns)
            out.sub_paths.append(sub_paths)
            places += [(j, i, key, conns, sub_paths, paths) for i, key in enumerate(keys)]
        tables: dict[int, list[dict]] = {}
        for sub, index, key, holders, where, owners in places:
            table = tables.get(sub)
            if table is None:
                table = tables[sub] = list(map(_SYMBOLS, holders))
            symbols = list(map(itemgetter(key), table))
            decls = list(map(_DECL, symbols))
            decl_types = set(map(type, decls))
            if len(decl_types) != 1:
                return f"{key} is declared differently in components of one class"
            decl_type = decl_types.pop()
            if decl_type is Parameter:
                if not all(issubclass(t, _NUMBERS) and t is not bool for t in
                           set(map(type, map(_VALUE, decls)))):
                    return f"a parameter {key} is not given as a number"
                out.add(_Slot(sub, index, key, "parameter", symbols, where, owners),
                        None if sub < 0 else sub_names[sub])
                continue
            if decl_type not in _VARIABLES:
                return f"{key} is a {decl_type.__name__}"
            if set(map(_STATE_SELECT, decls)) - SOFT_STATE_SELECT:
                return "a variable has a state selection"
            slot = _Slot(sub, index, key, "flow" if decl_type is Flow else "variable", symbols,
                         where, owners)
            slot.decls = decls
            if slot.has_der.any() and any(d.der is not None for d in slot.ders if d is not None):
                return "a variable has a second derivative"
            out.add(slot, None if sub < 0 else sub_names[sub])
        return out


class _Layout(list):
    """The slots of a class of components (a list of :class:`_Slot`), with the components'
    connectors and their dotted paths, connector by connector."""

    def __init__(self) -> None:
        super().__init__()
        self.connectors: list[list[Any]] = []
        self.sub_paths: list[list[str]] = []
        self.by_key: dict[tuple[str | None, str], _Slot] = {}

    def add(self, slot: _Slot, sub_name: str | None) -> None:
        self.append(slot)
        self.by_key[(sub_name, slot.key)] = slot


def _layout_key(child: Any) -> tuple:
    """A component's declarations and connectors (with theirs); its subcomponents are
    elements of their own."""
    return (tuple(child._symbols), tuple((name, type(sub), tuple(sub._symbols))
                                         for name, sub in child._children.items()
                                         if isinstance(sub, Connector)))


class _Slot:
    """One declaration of components of one class: its symbols in every component, their
    dotted names, and which have a time derivative. ``sub``: the connector it belongs to
    (-1: the component), ``index`` its place among the connector's variables."""

    def __init__(self, sub: int, index: int, key: str, kind: str, symbols: list[Any],
                 where: list[str], owners: list[str]) -> None:
        self.sub, self.index, self.kind, self.symbols = sub, index, kind, symbols
        self.key = key
        self.columns: np.ndarray = np.zeros(0, dtype=np.int64)     # set by Columns
        self.decls: list[Any] = []                                  # (variables)
        self.names = [key] if where == [""] else list(map(add, where, repeat(f".{key}")))
        self.owners = owners
        self.ders = list(map(_DER, symbols))
        self.has_der = np.fromiter(map(is_not, self.ders, repeat(None)), np.int64,
                                   len(symbols))


def _traits(n: int) -> Traits:
    """:class:`~.collect.Traits` of ``n`` columns, to be filled slot by slot."""
    return _FillTraits(np.zeros(n, dtype=bool), np.zeros(n, dtype=bool),
                       np.zeros(n, dtype=bool), np.zeros(n, dtype=np.int64),
                       np.zeros(n, dtype=float), np.zeros(n, dtype=np.int64),
                       np.zeros(n, dtype=np.int64))


class _FillTraits(Traits):
    def fill(self, col: np.ndarray, slot: _Slot) -> None:
        """The traits of a slot's variables, at their columns ``col``."""
        k, decls, names = col.size, slot.decls, slot.names
        self.has_der[col] = slot.has_der.astype(bool)
        self.fixed[col] = np.fromiter(map(bool, map(_FIXED, decls)), bool, k)
        self.state_select[col] = np.fromiter(map(int, map(_STATE_SELECT, decls)), np.int64, k)
        self.start[col] = np.fromiter(map(float, map(_START, decls)), float, k)
        self.dots[col] = np.fromiter(map(methodcaller("count", "."), names), np.int64, k)
        self.length[col] = np.fromiter(map(len, names), np.int64, k)


class _Positions(dict):
    """``id(symbol)`` -> column. Most symbols are entered on the first lookup that misses:
    the arrays that groups of components read are found in the lowering's memo instead
    (:func:`memo_of`)."""

    def __init__(self) -> None:
        super().__init__()
        self.pending: list[tuple[list[Any], np.ndarray]] = []

    def add(self, symbols: list[Any], columns: np.ndarray, now: bool) -> None:
        """Enter the symbols' columns now, or on the first miss."""
        if now:
            self.update(zip(map(id, symbols), columns.tolist(), strict=True))
        else:
            self.pending.append((symbols, columns))

    def __missing__(self, key: int) -> int:
        if not self.pending:
            raise KeyError(key)
        for symbols, columns in self.pending:
            self.update(zip(map(id, symbols), columns.tolist(), strict=True))
        self.pending = []
        return self[key]

    def of(self, sym: Any) -> int:
        """The column of ``sym`` (KeyError for a symbol of another model)."""
        return self[id(sym)]


def memo_of(groups: list[tuple[list[Any], dict]], cols: Columns,
          children: dict[str, Any]) -> dict[int, Any]:
    """The columns of the arrays that the groups of components written once read (as
    :func:`~bgmodelica.core.flatten_arrays._rows` finds them by their base array)."""
    memo: dict[int, Any] = {}
    if not groups:
        return memo
    index = dict(zip(map(id, children.values()), range(len(children)), strict=True))
    for items, arrays in groups:
        at = np.fromiter(map(index.__getitem__, map(id, items)), np.int64, len(items))
        group = cols.group_of[at]
        if (group != group[0]).any():
            continue
        layout, place = cols.layouts[int(group[0])], cols.place_of[at]
        for name, arr in arrays.items():
            slot = layout.by_key.get(name)
            base = arr.items
            if slot is not None and base.base is None and base.shape == (len(items),):
                memo[id(base)] = (base, slot.columns[place])
    return memo


def _objects(items: list[Any]) -> np.ndarray:
    out = np.empty(len(items), dtype=object)
    out[:] = items
    return out
