"""The instance environment (:class:`Env`): the values of an instance's elements as seen by its
equations and modifiers, and array sizes.
"""

from __future__ import annotations

import math
from typing import Any

from ...core.component import Element
from .. import ast as A
from .. import scope as S
from .base import Ctx, NotConstant, check_array_size, fail, numeric_value
from .classes import ClassView, ElemInfo, TypeRef, class_view, type_ref
from .mods import Mod, bind, merge


class Env:
    """An instance being built: its class view, the modifications it received, its
    Python element once created, and memoized values of its parameters."""

    __slots__ = ("view", "mods", "parent", "inst", "path", "_num", "_emod", "disabled",
                 "_busy", "cached", "pending", "buses")

    def __init__(self, view: ClassView, mods: dict[str, Mod], parent: Env | None,
                 path: str) -> None:
        self.view = view
        self.mods = mods
        self.parent = parent
        self.inst: Element | None = None
        self.path = path
        self._num: dict[str, Any] = {}
        self._emod: dict[str, Mod | None] = {}
        self.disabled: set[str] = set()
        self._busy: set[str] = set()
        self.cached: tuple | None = None
        #: declaration equations of the instances below, evaluated once all are built
        self.pending: list[tuple] = []
        #: the expandable connectors built below (at the root)
        self.buses: list[Element] = []

    def emod(self, name: str) -> Mod | None:
        """The merged modification of element ``name``: the outer one on top of the
        declaration's (and its type's)."""
        if name in self._emod:
            return self._emod[name]
        info = self.view.elements[name]
        own = bind(info.mod, self)
        tref = info.tref
        if tref is not None and tref.kind == "scalar" and tref.mod is not None:
            own = merge(own, tref.mod)
        m = merge(self.mods.get(name), own)
        self._emod[name] = m
        return m

    def numeric(self, name: str) -> Any:
        """The value of parameter / constant ``name`` when the model is built."""
        if name in self._num:
            return self._num[name]
        info = self.view.elements.get(name)
        if info is None:
            raise KeyError(name)
        if name in self._busy:
            raise fail(info.lex, info.comp, f"the binding of {name} depends on itself")
        tref = type_ref(info)
        category = _category(info, tref)
        if category not in ("param", "const", "string"):
            raise NotConstant(f"{name} is a variable")
        self._busy.add(name)
        try:
            m = self.emod(name)
            if m is not None and m.has_binding:
                value = m.value(True)
            elif category == "param" and self._solved_initially(name, m):
                return self._num[name]
            elif m is not None and "start" in m.sub and m.sub["start"].has_binding:
                value = m.sub["start"].value(True)
            else:
                value = _default_value(tref)
                dims = _dims(info, self, numeric=True)
                for d in reversed(dims):
                    value = [value] * d
        finally:
            self._busy.discard(name)
        self._num[name] = value
        return value


    def _solved_initially(self, name: str, m: Mod | None) -> bool:
        """Whether parameter ``name``, declared ``fixed = false``, took its value from the
        initial equations and algorithms of the instance (run now when they can be)."""
        fixed = m.sub.get("fixed") if m is not None else None
        if fixed is None or not fixed.has_binding or fixed.value(True) is not False \
                or self.inst is None or not self.view.initial \
                or f"{name} (initial)" in self._busy:
            return False
        from .equations import equations_of

        self._busy.discard(name)
        self._busy.add(f"{name} (initial)")
        try:
            equations_of(self, self.view.initial, initial=True)
        finally:
            self._busy.discard(f"{name} (initial)")
        return name in self._num


def _default_value(tref: TypeRef) -> Any:
    return {"Real": 0.0, "Integer": 0, "Boolean": False, "String": "", "enum": 1}.get(
        tref.base, 0.0)


def _category(info: ElemInfo, tref: TypeRef) -> str:
    if info.category:
        return info.category
    pre = info.comp.prefixes
    if tref.kind == "class" and _external_object(tref.scope):
        cat = "const"             # an ExternalObject (a table): a value made when built
    elif tref.kind != "scalar":
        cat = "child"
    elif "constant" in pre:
        cat = "const"
    elif tref.base == "String":
        cat = "string"
    elif "parameter" in pre:
        cat = "param"
    else:
        cat = "var"
    info.category = cat
    return cat


def _external_object(scope: Any) -> bool:
    """Whether class ``scope`` is an ExternalObject (it has a constructor function)."""
    ctor = getattr(scope, "nested", lambda _: None)("constructor")
    return ctor is not None and ctor.cdef.kind.endswith("function")


def _dims(info: ElemInfo, env: Env | None, numeric: bool = True) -> tuple[int, ...]:
    from .evaluate import evaluate

    tref = type_ref(info)
    exprs = [(d, tref_lex) for d, tref_lex in tref.dims] if tref.kind == "scalar" else []
    exprs = [(d, info.lex) for d in info.comp.dims] + exprs
    out = []
    for k, (d, lex) in enumerate(exprs):
        if isinstance(d, A.Colon):
            size = _size_from_binding(info, env, k)
        else:
            v = evaluate(d, Ctx(env, lex, {}, True))
            v = numeric_value(v, lex, d)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or v != int(v) or v < 0:
                raise fail(lex, d, f"array size of {info.comp.name} must be a non-negative "
                           f"Integer, got {v!r}")
            size = int(v)
        out.append(size)
    check_array_size(math.prod(out), info.lex, info.comp, info.comp.name)
    return tuple(out)


def _size_from_binding(info: ElemInfo, env: Env | None, k: int) -> int:
    if env is None:
        raise NotConstant(f"size of {info.comp.name}")
    m = env.emod(info.comp.name)
    if m is None or not m.has_binding:
        raise fail(info.lex, info.comp, f"{info.comp.name}: an array size ':' needs a binding "
                   "to take its size from")
    lit = m.binding
    for _ in range(k):
        lit = lit.items[0] if isinstance(lit, A.ArrayLit) and lit.items else None
    if isinstance(lit, A.ArrayLit):
        # an array constructor's size needs no values (``reset={other.on}`` may name a
        # sibling built later)
        return len(lit.items)
    v = m.value(True)
    for _ in range(k):
        v = v[0] if isinstance(v, list) and v else v
    if not isinstance(v, list):
        raise fail(info.lex, info.comp, f"{info.comp.name}: the binding is not an array")
    return len(v)


def static_env(scope: S.ClassScope) -> Env:
    """An environment without instance for reading constants of a package or class."""
    env = scope._static
    if env is None:
        env = Env(class_view(scope), {}, None, scope.full_name)
        scope._static = env
    return env


def _unbuilt_child(env: Env, name: str) -> bool:
    """Whether ``name`` is a subcomponent of ``env`` not built yet (a sibling's modifier
    reads its parameters: ``startTime = -vIn.rising``)."""
    if name in env.disabled:
        return False
    info = env.view.elements[name]
    if _category(info, type_ref(info)) != "child" or info.comp.dims:
        return False
    inst = env.inst
    return inst is None or name not in inst._children


def sibling_parameter(env: Env, name: str, rest: tuple) -> tuple | None:
    """``(value,)`` of a parameter of subcomponent ``name`` of ``env`` not built yet (a
    sibling's modifier reads it: ``startTime = -vIn.rising``): its modifier here, else its
    class's value; None when ``name`` is built (or switched off) or ``rest`` names no
    parameter."""
    if not _unbuilt_child(env, name):
        return None
    (pname, subs), more = rest[0], rest[1:]
    if more or subs:
        return None
    try:
        m = env.emod(name)
        sub = m.sub.get(pname) if m is not None else None
        if sub is not None and sub.has_binding:
            return (sub.value(True),)
        tref = type_ref(env.view.elements[name])
        if tref.kind != "class" or tref.scope is None:
            return None
        if m is None or not m.sub:
            return (static_env(tref.scope).numeric(pname),)
        # its class's binding, read with the sibling's other modifiers (``data(C1=...)``
        # for ``v = if C1 == "D" then 1 else 2``)
        return (Env(class_view(tref.scope), m.sub, env, f"{env.path}.{name}").numeric(pname),)
    except (NotConstant, KeyError):
        return None
