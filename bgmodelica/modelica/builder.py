"""Instantiate Modelica classes as bgmodelica components.

Each Modelica class used by a model becomes a Python class created with ``type()``: a
:class:`~bgmodelica.Component` (or :class:`~bgmodelica.Connector`) subclass whose body holds
the declarations (``Parameter``, ``Variable``, ``Potential``, ``Flow``, ``Input``, ``Output``,
``Discrete``, ``Integer``, ``Boolean``; array elements as ``x[1]``, ``x[2]``...) and whose
``equations()`` / ``initial_equations()`` evaluate the class's Modelica equations (inherited
ones included) for the instance at hand. One Python class serves every instance with the same
structure (array sizes, conditional components); per-instance modifiers change the instance's
declarations, as ``Resistor(R=10)`` does in Python. Subcomponents are added to the instance,
component arrays as children named ``R[1]``, ``R[2]``...; MSL classes of :mod:`.msl` become
instances of the project's ``library`` classes.

Modelica semantics kept: modifiers are evaluated in the scope where they are written (outer
modifiers win over inner ones, ``each`` for arrays), parameters bound to expressions of other
parameters stay bound (changing one at simulation time updates the others), ``extends`` merges
the base class's elements and equations, structural values (array sizes, ``for`` ranges,
if-equations on parameters, conditional components) are evaluated when the model is built.
"""

from __future__ import annotations

import math
import re
from dataclasses import replace
from typing import Any

from ..core import expressions as X
from ..core import hybrid as H
from ..core.component import Component, Connector, Element, connect
from ..core.expr import Equation, Expr, Leaf, Op
from ..core.variables import (
    KIND_PARAMETER,
    TIME,
    Boolean,
    Discrete,
    Flow,
    Input,
    Integer,
    Output,
    Parameter,
    Potential,
    StateSelect,
    Variable,
)
from ..errors import ConnectError, DeclarationError, EquationError, ModelError
from . import ast as A
from . import scope as S
from .errors import ModelicaError

SELF = "<self>"
_NAME = re.compile(r"^(.*)\[([0-9,]+)\]$")
_RESERVED = {n for n in dir(Component) if not n.startswith("__")} | {"name"}


class NotConstant(Exception):
    """A structural expression (array size, range, parameter-only condition) uses a value that
    is not known when the model is built."""

    def __init__(self, what: str) -> None:
        super().__init__(what)
        self.what = what


class _Disabled(Exception):
    """A reference to a conditional component that is switched off."""


def _where(lex: S.ClassScope | None, pos: A.Pos) -> str:
    if lex is None:
        return "<modifier>"
    return f"{lex.cdef.file or lex.file.file}:{pos[0]}:{pos[1]}"


def fail(lex: S.ClassScope | None, node: Any, message: str) -> ModelicaError:
    pos = getattr(node, "pos", (0, 0)) if not isinstance(node, tuple) else node
    return ModelicaError(f"{_where(lex, pos)}: {message}")


# -- modifications -----------------------------------------------------------------------------


class Mod:
    """A modification: an optional binding (with the scope it is evaluated in) and nested
    modifications of elements or attributes."""

    __slots__ = ("binding", "scope", "lex", "each", "sub", "redeclare", "pos", "source",
                 "index", "const", "_memo", "final")

    def __init__(self, binding: Any = None, scope: Any = None, lex: Any = None,
                 each: bool = False, sub: dict | None = None, redeclare: Any = None,
                 pos: A.Pos = (0, 0), const: Any = None, final: bool = False) -> None:
        self.binding = binding
        self.scope = scope
        self.lex = lex
        self.each = each
        self.sub: dict[str, Mod] = sub if sub is not None else {}
        self.redeclare = redeclare
        self.pos = pos
        self.source: Mod | None = None
        self.index: tuple | None = None
        self.const = const
        self._memo: dict[bool, Any] = {}
        self.final = final

    @property
    def has_binding(self) -> bool:
        if self.source is not None:
            return self.source.has_binding
        return self.binding is not None or self.const is not None

    def value(self, numeric: bool) -> Any:
        if numeric in self._memo:
            return self._memo[numeric]
        if self.source is not None:
            whole = self.source.value(numeric)
            out = _pick(whole, self.index, self.source)
        elif self.const is not None:
            out = self.const
        else:
            env = self.scope if isinstance(self.scope, Env) else None
            out = evaluate(self.binding, Ctx(env, self.lex, {}, numeric or env is None))
            if numeric:
                out = numeric_value(out, self.lex, self.binding)
        self._memo[numeric] = out
        return out


def _pick(whole: Any, index: tuple, mod: Mod) -> Any:
    out = whole
    for i in index:
        if isinstance(out, list):
            if not 1 <= i <= len(out):
                raise fail(mod.lex, mod.pos, f"modifier value has {len(out)} elements, "
                           f"element {i} is needed (or use 'each')")
            out = out[i - 1]
        else:
            break              # a scalar for an array element: as 'each' (lenient)
    return out


def mod_from_ast(ast_mod: A.Modification | None, scope: Any,
                 lex: S.ClassScope | None) -> Mod | None:
    """The :class:`Mod` of a parsed modification, evaluated later in ``scope``."""
    if ast_mod is None:
        return None
    m = Mod(ast_mod.binding, scope, lex, pos=ast_mod.pos)
    for arg in ast_mod.args:
        if isinstance(arg, A.ElementMod):
            parts = arg.name.split(".")
            inner = mod_from_ast(arg.mod, scope, lex) if arg.mod is not None else Mod(
                None, scope, lex, pos=arg.pos)
            inner.each = arg.each
            inner.final = arg.final
            inner.pos = arg.pos
            for p in reversed(parts[1:]):
                inner = Mod(None, scope, lex, sub={p: inner}, pos=arg.pos)
            head = parts[0]
            m.sub[head] = merge(inner, m.sub.get(head)) if head in m.sub else inner
        elif isinstance(arg, A.Redeclare):
            el = arg.element
            name = el.name
            m.sub[name] = merge(Mod(None, scope, lex, redeclare=(el, lex), pos=arg.pos,
                                    each=arg.each), m.sub.get(name))
    return m


def merge(outer: Mod | None, inner: Mod | None) -> Mod | None:
    """``outer`` applied on top of ``inner`` (outer bindings win)."""
    if outer is None:
        return inner
    if inner is None:
        return outer
    base = outer if outer.has_binding else inner
    m = Mod(base.binding, base.scope, base.lex, base.each, None,
            outer.redeclare or inner.redeclare, base.pos, base.const, inner.final or outer.final)
    m.source, m.index = base.source, base.index
    if base.source is None and base.binding is not None:
        m._memo = base._memo
    sub = dict(inner.sub)
    for k, v in outer.sub.items():
        sub[k] = merge(v, sub.get(k))
    m.sub = sub
    if not outer.has_binding and inner.has_binding:
        m.each = inner.each
    return m


def bind(mod: Mod | None, env: Env) -> Mod | None:
    """``mod`` with its SELF scopes replaced by ``env``."""
    if mod is None:
        return None
    if mod.scope is not SELF and not mod.sub:
        return mod
    m = Mod(mod.binding, env if mod.scope is SELF else mod.scope, mod.lex, mod.each,
            {k: bind(v, env) for k, v in mod.sub.items()}, mod.redeclare, mod.pos, mod.const,
            mod.final)
    m.source, m.index = mod.source, mod.index
    if mod.scope is not SELF:
        m._memo = mod._memo
    return m


def index_mod(mod: Mod | None, index: tuple) -> Mod | None:
    """The modification of one element of an array."""
    if mod is None:
        return None
    if mod.each:
        if not mod.sub:
            return mod
    m = Mod(None, mod.scope, mod.lex, mod.each, None, mod.redeclare, mod.pos, None, mod.final)
    if mod.has_binding:
        if mod.each:
            m.source, m.index = mod, ()
        else:
            m.source, m.index = mod, index
    m.sub = {k: index_mod(v, index) for k, v in mod.sub.items()}
    return m


# -- class views -------------------------------------------------------------------------------


class TypeRef:
    """What a component's type is: a scalar (predefined type with attribute modifiers, maybe a
    signal connector ``= input Real``), a Modelica class, or a mapped MSL class."""

    __slots__ = ("kind", "base", "mod", "prefix", "dims", "scope", "msl", "literals", "name")

    def __init__(self, kind: str, name: str, base: str = "", mod: Mod | None = None,
                 prefix: str = "", dims: tuple = (), scope: Any = None, msl: Any = None,
                 literals: tuple = ()) -> None:
        self.kind = kind            # "scalar" | "class" | "msl"
        self.name = name
        self.base = base            # Real Integer Boolean String enum
        self.mod = mod
        self.prefix = prefix        # input / output of a signal connector type
        self.dims = dims            # (dims AST, lex) pairs of the type
        self.scope = scope
        self.msl = msl
        self.literals = literals


class ElemInfo:
    __slots__ = ("comp", "lex", "mod", "tref", "category", "static", "defaults", "connector")

    def __init__(self, comp: A.Component, lex: S.ClassScope, mod: Mod | None) -> None:
        self.comp = comp
        self.lex = lex
        self.mod = mod
        self.tref: TypeRef | None = None
        self.category = ""
        self.static: bool | None = None
        self.defaults: dict[tuple, Any] = {}
        self.connector = False


class ClassView:
    """A class with its ``extends`` expanded: elements, equations, experiment annotation."""

    def __init__(self, scope: S.ClassScope) -> None:
        self.scope = scope
        self.cdef = scope.cdef
        self.kind = scope.cdef.kind
        self.elements: dict[str, ElemInfo] = {}
        self.equations: list[tuple[Any, S.ClassScope]] = []
        self.initial: list[tuple[Any, S.ClassScope]] = []
        self.classes: dict[tuple, type] = {}
        self.description = scope.cdef.description
        self.unsupported: list[tuple[A.Unsupported, S.ClassScope]] = []
        self.plan: tuple | None = None
        self.checked = False
        self.validated = False


def class_view(scope: S.ClassScope, _stack: tuple = ()) -> ClassView:
    """The (cached) expanded view of a class."""
    if scope._view is not None:
        return scope._view
    if scope in _stack:
        raise fail(scope, scope.cdef.pos, f"class {scope.full_name} extends itself")
    view = ClassView(scope)
    cdef = scope.cdef
    if cdef.short is not None:
        prefix, base_name, dims, ast_mod = cdef.short
        base = resolve_class(scope.parent, base_name, cdef.pos, scope)
        if not isinstance(base, S.ClassScope):
            raise fail(scope, cdef.pos, f"{cdef.name} = {base_name}: only classes can be "
                       "renamed with a short class definition here")
        bview = class_view(base, _stack + (scope,))
        _inherit(view, bview, mod_from_ast(ast_mod, SELF, scope.parent or scope))
        view.kind = cdef.kind
        scope._view = view
        return view
    for el in cdef.elements:
        if isinstance(el, A.Extends):
            base = resolve_class(scope, el.type_name, el.pos, scope, extends=True)
            if base is None:
                continue                        # Modelica.Icons.*: nothing to inherit
            if isinstance(base, S.MslClass):
                raise fail(scope, el.pos, f"extends {el.type_name}: extending a mapped "
                           "Modelica Standard Library component is not supported (extend its "
                           "partial base class from *.Interfaces instead)")
            if not isinstance(base, S.ClassScope):
                raise fail(scope, el.pos, f"extends {el.type_name}: not a class")
            if base.cdef.short is not None and _scalar_base(base):
                raise fail(scope, el.pos, f"extends {el.type_name}: extending a predefined "
                           "type in a long class is not supported")
            bview = class_view(base, _stack + (scope,))
            _inherit(view, bview, mod_from_ast(el.mod, SELF, scope))
        elif isinstance(el, A.Component):
            view.elements[el.name] = ElemInfo(el, scope, mod_from_ast(el.mod, SELF, scope))
    for eq in cdef.equations:
        view.equations.append((eq, scope))
    for eq in cdef.initial_equations:
        view.initial.append((eq, scope))
    for u in cdef.unsupported:
        view.unsupported.append((u, scope))
    scope._view = view
    return view


def _scalar_base(scope: S.ClassScope) -> bool:
    s = scope
    seen = 0
    while s is not None and s.cdef.short is not None and seen < 50:
        name = s.cdef.short[1]
        if name in S.BUILTIN_TYPES:
            return True
        s2 = resolve_class(s.parent, name, s.cdef.pos, s)
        s = s2 if isinstance(s2, S.ClassScope) else None
        seen += 1
    return bool(s is not None and s.cdef.enum is not None)


def _inherit(view: ClassView, base: ClassView, ext_mod: Mod | None) -> None:
    for name, info in base.elements.items():
        outer = ext_mod.sub.get(name) if ext_mod is not None else None
        new = ElemInfo(info.comp, info.lex, merge(outer, info.mod))
        if outer is not None and outer.redeclare is not None:
            el, lex = outer.redeclare
            new = ElemInfo(el, lex, merge(_without_redeclare(outer), mod_from_ast(el.mod, SELF,
                                                                                   lex)))
        view.elements[name] = new
    if ext_mod is not None:
        for name, m in ext_mod.sub.items():
            if name not in base.elements:
                raise fail(m.lex, m.pos, f"extends {base.scope.full_name}: the base class has "
                           f"no element {name!r} to modify")
    view.equations.extend(base.equations)
    view.initial.extend(base.initial)
    view.unsupported.extend(base.unsupported)


def _without_redeclare(m: Mod) -> Mod | None:
    if not m.sub and not m.has_binding:
        return None
    out = Mod(m.binding, m.scope, m.lex, m.each, dict(m.sub), None, m.pos, m.const)
    out.source, out.index = m.source, m.index
    return out


def resolve_class(lex: S.ClassScope | None, dotted: str, pos: A.Pos, where: S.ClassScope,
                  extends: bool = False) -> Any:
    """Look up a type name; raises a positioned error if unknown (None for MSL icons)."""
    parts = dotted.split(".")
    if lex is None:
        head = S.lookup_top(where.file, parts[0])
    else:
        head = S.lookup(lex, parts[0])
    got = S.walk(head, parts[1:]) if head is not None else None
    if got is None and dotted.startswith("Modelica.Icons."):
        return None
    if got is None:
        if parts[0] == "Modelica" or (head is not None and isinstance(head, S.MslNamespace)):
            from . import msl
            raise fail(where, pos, f"{dotted}: this Modelica Standard Library class is not in "
                       f"bgmodelica's MSL subset (it maps {len(msl.MAPPING)} component classes, "
                       "e.g. Modelica.Electrical.Analog.Basic.Resistor; see "
                       "bgmodelica.modelica.msl)")
        raise fail(where, pos, f"unknown class {dotted!r}")
    if isinstance(got, S.ClassScope) and got.cdef.kind == "package" and not extends:
        raise fail(where, pos, f"{dotted} is a package, not a type")
    return got


def type_ref(info: ElemInfo) -> TypeRef:
    """Resolve (once) the type of a component declaration."""
    if info.tref is not None:
        return info.tref
    comp = info.comp
    name = comp.type_name
    if name in S.BUILTIN_TYPES and S.lookup(info.lex, name) is S.BUILTINS[name]:
        tref = TypeRef("scalar", name, base=name)
    else:
        got = resolve_class(info.lex, name, comp.pos, info.lex)
        tref = _tref_of(got, name, comp.pos, info.lex)
    info.tref = tref
    return tref


def _tref_of(got: Any, name: str, pos: A.Pos, where: S.ClassScope, depth: int = 0) -> TypeRef:
    if depth > 50:
        raise fail(where, pos, f"type {name}: circular type definitions")
    if isinstance(got, S.Builtin):
        if got.literals:
            return TypeRef("scalar", got.name, base="enum", literals=got.literals)
        return TypeRef("scalar", got.name, base=got.name)
    if isinstance(got, S.MslClass):
        return TypeRef("msl", name, msl=got)
    if isinstance(got, S.ClassScope):
        cdef = got.cdef
        if cdef.enum is not None:
            return TypeRef("scalar", got.full_name, base="enum", literals=cdef.enum)
        if cdef.short is not None:
            prefix, base_name, dims, ast_mod = cdef.short
            parent = got.parent
            if base_name in S.BUILTIN_TYPES and S.lookup(parent, base_name) in (
                    S.BUILTINS[base_name], None):
                base_ref = TypeRef("scalar", base_name, base=base_name)
            else:
                inner = resolve_class(parent, base_name, cdef.pos, got)
                base_ref = _tref_of(inner, base_name, cdef.pos, got, depth + 1)
            if base_ref.kind != "scalar":
                return TypeRef("class", got.full_name, scope=got)
            own = mod_from_ast(ast_mod, None, parent or got)
            return TypeRef("scalar", got.full_name, base=base_ref.base,
                           mod=merge(own, base_ref.mod), prefix=prefix or base_ref.prefix,
                           dims=tuple((d, parent or got) for d in dims) + base_ref.dims,
                           literals=base_ref.literals)
        if cdef.kind in ("package", "function"):
            raise fail(where, pos, f"{name} is a {cdef.kind}, not a type of components")
        return TypeRef("class", got.full_name, scope=got)
    if isinstance(got, tuple) and got and got[0] == "function":
        raise fail(where, pos, f"{name} is a function, not a type")
    raise fail(where, pos, f"{name} is not a type")


# -- environments ------------------------------------------------------------------------------


class Env:
    """An instance being built: its class view, the modifications it received, its
    Python element once created, and memoized values of its parameters."""

    __slots__ = ("view", "mods", "parent", "inst", "path", "_num", "_emod", "disabled",
                 "_busy", "cached")

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


def _default_value(tref: TypeRef) -> Any:
    return {"Real": 0.0, "Integer": 0, "Boolean": False, "String": "", "enum": 1}.get(
        tref.base, 0.0)


def _category(info: ElemInfo, tref: TypeRef) -> str:
    if info.category:
        return info.category
    pre = info.comp.prefixes
    if tref.kind != "scalar":
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


def _dims(info: ElemInfo, env: Env | None, numeric: bool = True) -> tuple[int, ...]:
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
    return tuple(out)


def _size_from_binding(info: ElemInfo, env: Env | None, k: int) -> int:
    if env is None:
        raise NotConstant(f"size of {info.comp.name}")
    m = env.emod(info.comp.name)
    if m is None or not m.has_binding:
        raise fail(info.lex, info.comp, f"{info.comp.name}: an array size ':' needs a binding "
                   "to take its size from")
    v = m.value(True)
    for _ in range(k):
        v = v[0] if isinstance(v, list) and v else v
    if not isinstance(v, list):
        raise fail(info.lex, info.comp, f"{info.comp.name}: the binding is not an array")
    return len(v)


class Ctx:
    """Evaluation context: the instance environment (or None for static values), the lexical
    class scope, loop variables, and whether values must be known numbers."""

    __slots__ = ("env", "lex", "loops", "numeric")

    def __init__(self, env: Env | None, lex: S.ClassScope | None, loops: dict,
                 numeric: bool) -> None:
        self.env = env
        self.lex = lex
        self.loops = loops
        self.numeric = numeric


# -- expression evaluation ---------------------------------------------------------------------


def evaluate(node: Any, ctx: Ctx) -> Any:
    """The value of an expression: a number, bool, string, enumeration value, expression
    (:class:`~bgmodelica.core.expr.Expr`), element, or a (nested) list for arrays."""
    fn = _EVAL.get(type(node))
    if fn is None:
        raise fail(ctx.lex, node, f"unsupported expression {type(node).__name__}")
    return fn(node, ctx)


def _ev_num(node: A.Num, ctx: Ctx) -> Any:
    return node.value


def _ev_str(node: A.Str, ctx: Ctx) -> Any:
    return node.value


def _ev_bool(node: A.Bool, ctx: Ctx) -> Any:
    return node.value


def _ev_ref(node: A.Ref, ctx: Ctx) -> Any:
    parts = node.parts
    name, subs = parts[0]
    env = ctx.env
    rest = 1
    if not ctx.numeric and env is not None and env.inst is not None and name not in ctx.loops:
        hit = env.inst.__dict__["_mo_members"].get(name)
        if hit is not None:
            val = hit
            if subs:
                val = _subscript(val, subs, ctx, node)
            for name, subs in parts[1:]:
                if isinstance(val, Element):
                    val = member(val, name, False, ctx.lex, node)
                elif isinstance(val, list):
                    val = _map_member(val, name, ctx, node)
                else:
                    raise fail(ctx.lex, node, f"{node.dotted}: cannot select {name!r} from a "
                               f"{type(val).__name__}")
                if subs:
                    val = _subscript(val, subs, ctx, node)
            return val
    if name in ctx.loops:
        val = ctx.loops[name]
    elif env is None and len(parts) == 1:
        # static evaluation (no instance): only literals and dotted constants / enumeration
        # literals are known; a bare name may be an element of the instance
        raise NotConstant(name)
    elif env is not None and name in env.view.elements:
        val = _env_member(env, name, ctx, node)
    elif env is not None and env.inst is not None and (
            name in env.inst._symbols or name in env.inst._children):
        val = member(env.inst, name, ctx.numeric)
    elif name == "time" and S.lookup(ctx.lex, "time") is None:
        if ctx.numeric:
            raise NotConstant("time")
        val = X.time
    else:
        found = S.lookup(ctx.lex, name) if ctx.lex is not None else None
        if found is None:
            raise fail(ctx.lex, node, f"unknown name {node.dotted!r}"
                       + (f" in {env.view.cdef.name}" if env is not None else ""))
        k = 1
        while k < len(parts) and not _is_value(found):
            if parts[k - 1][1]:
                raise fail(ctx.lex, node, f"subscripts on the class name {parts[k - 1][0]}")
            found = S.walk(found, [parts[k][0]])
            if found is None:
                raise fail(ctx.lex, node, f"unknown name {node.dotted!r}")
            k += 1
        val = _lexical_value(found, ctx, node)
        subs = parts[k - 1][1]
        rest = k
    if subs:
        val = _subscript(val, subs, ctx, node)
    for name, subs in parts[rest:]:
        if isinstance(val, Element):
            val = member(val, name, ctx.numeric, ctx.lex, node)
        elif isinstance(val, list):
            val = _map_member(val, name, ctx, node)
        else:
            raise fail(ctx.lex, node, f"{node.dotted}: cannot select {name!r} from a "
                       f"{type(val).__name__}")
        if subs:
            val = _subscript(val, subs, ctx, node)
    return val


def _map_member(val: list, name: str, ctx: Ctx, node: Any) -> list:
    return [(_map_member(v, name, ctx, node) if isinstance(v, list)
             else member(v, name, ctx.numeric, ctx.lex, node)) for v in val]


def _is_value(found: Any) -> bool:
    return isinstance(found, (S.ConstRef, S.EnumValue))


def _lexical_value(found: Any, ctx: Ctx, node: Any) -> Any:
    if isinstance(found, S.EnumValue):
        return found
    if isinstance(found, S.ConstRef):
        return static_env(found.scope).numeric(found.name)
    raise fail(ctx.lex, node, f"{node.dotted} names a class, not a value")


def static_env(scope: S.ClassScope) -> Env:
    """An environment without instance for reading constants of a package or class."""
    env = scope._static
    if env is None:
        env = Env(class_view(scope), {}, None, scope.full_name)
        scope._static = env
    return env


def _env_member(env: Env, name: str, ctx: Ctx, node: Any) -> Any:
    info = env.view.elements[name]
    cat = _category(info, type_ref(info))
    if name in env.disabled:
        raise _Disabled(name)
    if cat in ("const", "string"):
        return env.numeric(name)
    if ctx.numeric:
        if cat == "param":
            return env.numeric(name)
        if cat == "child" and env.inst is not None:
            return member(env.inst, name, True, ctx.lex, node)
        raise NotConstant(f"{name} is a variable")
    if env.inst is None:
        raise NotConstant(f"{name} (the instance does not exist yet)")
    return member(env.inst, name, False, ctx.lex, node)


def member(elem: Element, name: str, numeric: bool = False, lex: Any = None,
           node: Any = None) -> Any:
    """Element ``name`` of an instance: a leaf, a child, an array of them, or a constant."""
    d = elem.__dict__
    cache = d.get("_mo_members")
    if cache is None:
        cache = {}
        object.__setattr__(elem, "_mo_members", cache)
    if not numeric:
        hit = cache.get(name)
        if hit is not None:
            return hit
        val = _member(elem, name, False, lex, node)
        cache[name] = val
        return val
    return _member(elem, name, numeric, lex, node)


def _member(elem: Element, name: str, numeric: bool, lex: Any, node: Any) -> Any:
    env = elem.__dict__.get("_mo_env")
    if env is not None and name in env.view.elements:
        if name in env.disabled:
            raise _Disabled(name)
        info = env.view.elements[name]
        cat = _category(info, type_ref(info))
        if cat in ("const", "string") or (numeric and cat == "param"):
            return env.numeric(name)
    rename = elem.__dict__.get("_mo_rename")
    if rename:
        name = rename.get(name, name)
    sym = elem._symbols.get(name)
    if sym is not None:
        return numeric_value(sym.leaf, lex, node) if numeric else sym.leaf
    child = elem._children.get(name)
    if child is not None:
        return child
    arrays = elem.__dict__.get("_mo_arrays")
    if arrays and name in arrays:
        cache = elem.__dict__.setdefault("_mo_array_cache", {})
        val = cache.get(name)
        if val is None:
            val = _assemble(elem, name, arrays[name])
            cache[name] = val
        return numeric_value(val, lex, node) if numeric else val
    where = f"{elem.name or type(elem).__name__}"
    have = [n for n in list(elem._symbols) + list(elem._children) if "[" not in n]
    have += list(arrays or ())
    raise fail(lex, node if node is not None else (0, 0),
               f"{where} ({type(elem).__name__}) has no element {name!r}; it has: "
               f"{', '.join(have) or 'none'}")


def _assemble(elem: Element, name: str, dims: tuple[int, ...]) -> list:
    def build(prefix: tuple) -> Any:
        if len(prefix) == len(dims):
            key = f"{name}[{','.join(map(str, prefix))}]"
            sym = elem._symbols.get(key)
            return sym.leaf if sym is not None else elem._children[key]
        return [build(prefix + (i,)) for i in range(1, dims[len(prefix)] + 1)]

    return build(())


def _subscript(val: Any, subs: tuple, ctx: Ctx, node: Any) -> Any:
    idx = []
    for s in subs:
        if type(s) is A.Num and type(s.value) is int:
            idx.append(s.value)
            continue
        if type(s) is A.Ref and len(s.parts) == 1 and s.parts[0][1] is None \
                and s.parts[0][0] in ctx.loops:
            v = ctx.loops[s.parts[0][0]]
            if type(v) is int:
                idx.append(v)
                continue
        if isinstance(s, A.Colon):
            idx.append(None)
            continue
        v = evaluate(s, Ctx(ctx.env, ctx.lex, ctx.loops, True))
        v = numeric_value(v, ctx.lex, s)
        if isinstance(v, S.EnumValue):
            v = v.index
        if isinstance(v, list):
            idx.append([int(x) for x in _flatten(v)])
            continue
        if isinstance(v, bool) or not isinstance(v, (int, float)) or v != int(v):
            raise fail(ctx.lex, s, f"subscript of {node.dotted if hasattr(node, 'dotted') else ''}"
                       f" must be an Integer, got {v!r}")
        idx.append(int(v))

    def apply(v: Any, k: int) -> Any:
        if k == len(idx):
            return v
        if not isinstance(v, list):
            raise fail(ctx.lex, node, f"too many subscripts for {getattr(node, 'dotted', '')}")
        i = idx[k]
        if i is None:
            return [apply(x, k + 1) for x in v]
        if isinstance(i, list):
            return [apply(_at(v, j, ctx, node), k + 1) for j in i]
        return apply(_at(v, i, ctx, node), k + 1)

    return apply(val, 0)


def _at(v: list, i: int, ctx: Ctx, node: Any) -> Any:
    if not 1 <= i <= len(v):
        raise fail(ctx.lex, node, f"index {i} out of range 1:{len(v)} in "
                   f"{getattr(node, 'dotted', 'expression')}")
    return v[i - 1]


def _flatten(v: Any) -> list:
    if isinstance(v, list):
        out = []
        for x in v:
            out.extend(_flatten(x))
        return out
    return [v]


def _num_or_expr(v: Any, ctx: Ctx, node: Any) -> Any:
    if isinstance(v, S.EnumValue):
        return v.index
    if isinstance(v, (Element, str)) and not ctx.numeric:
        raise fail(ctx.lex, node, f"{v!r} cannot be used in arithmetic")
    return v


def _arith(op: str, a: Any, b: Any, ctx: Ctx, node: Any) -> Any:
    if isinstance(a, list) or isinstance(b, list):
        return _array_arith(op, a, b, ctx, node)
    if isinstance(a, str) and isinstance(b, str) and op == "+":
        return a + b
    a = _num_or_expr(a, ctx, node)
    b = _num_or_expr(b, ctx, node)
    try:
        if op in ("+", ".+"):
            return a + b
        if op in ("-", ".-"):
            return a - b
        if op in ("*", ".*"):
            return a * b
        if op in ("/", "./"):
            if not isinstance(b, Expr) and not isinstance(a, Expr) and b == 0:
                raise fail(ctx.lex, node, "division by zero")
            return a / b
        if op in ("^", ".^"):
            if isinstance(a, (int, float)) and isinstance(b, (int, float)):
                return a ** b if not (isinstance(a, int) and isinstance(b, int) and b < 0) \
                    else float(a) ** b
            return a ** b
    except TypeError:
        raise fail(ctx.lex, node, f"cannot apply {op!r} to {a!r} and {b!r}") from None
    raise fail(ctx.lex, node, f"unknown operator {op}")


def _shape(v: Any) -> tuple:
    out = []
    while isinstance(v, list):
        out.append(len(v))
        v = v[0] if v else None
    return tuple(out)


def _array_arith(op: str, a: Any, b: Any, ctx: Ctx, node: Any) -> Any:
    la, lb = isinstance(a, list), isinstance(b, list)
    if op == "*" and la and lb:
        sa, sb = _shape(a), _shape(b)
        if len(sa) == 1 and len(sb) == 1:              # scalar product
            if sa != sb:
                raise fail(ctx.lex, node, f"vector sizes {sa[0]} and {sb[0]} differ")
            return _sum([_arith("*", x, y, ctx, node) for x, y in zip(a, b, strict=True)])
        if len(sa) == 2 and len(sb) == 1:
            return [_arith("*", row, b, ctx, node) for row in a]
        if len(sa) == 1 and len(sb) == 2:
            cols = [[r[j] for r in b] for j in range(sb[1])]
            return [_arith("*", a, c, ctx, node) for c in cols]
        if len(sa) == 2 and len(sb) == 2:
            cols = [[r[j] for r in b] for j in range(sb[1])]
            return [[_arith("*", row, c, ctx, node) for c in cols] for row in a]
        raise fail(ctx.lex, node, "unsupported array product")
    if op in ("+", "-", ".+", ".-", ".*", "./", ".^") and la and lb:
        if len(a) != len(b):
            raise fail(ctx.lex, node, f"array sizes {len(a)} and {len(b)} differ")
        return [_arith(op, x, y, ctx, node) for x, y in zip(a, b, strict=True)]
    if la and lb:
        raise fail(ctx.lex, node, f"operator {op} on two arrays is not supported")
    if op in ("+", "-") and not (op in ("+", "-") and (la and lb)):
        # Modelica forbids array + scalar; accept it elementwise
        pass
    if la:
        return [_arith(op, x, b, ctx, node) for x in a]
    return [_arith(op, a, y, ctx, node) for y in b]


def _sum(items: list) -> Any:
    if not items:
        return 0
    out = items[0]
    for x in items[1:]:
        out = out + x
    return out


def _ev_binop(node: A.BinOp, ctx: Ctx) -> Any:
    op = node.op
    if op == "and" or op == "or":
        a = evaluate(node.a, ctx)
        if isinstance(a, bool) or (isinstance(a, (int, float)) and not isinstance(a, Expr)):
            if op == "and" and not a:
                return False
            if op == "or" and a:
                return True
            b = evaluate(node.b, ctx)
            if isinstance(b, (bool, int, float)):
                return bool(b)
            return b
        b = evaluate(node.b, ctx)
        if isinstance(b, (bool, int, float)):
            if op == "and":
                return a if b else False
            return True if b else a
        return (a & b) if op == "and" else (a | b)
    a = evaluate(node.a, ctx)
    b = evaluate(node.b, ctx)
    if op in ("<", "<=", ">", ">=", "==", "<>"):
        return _relation(op, a, b, ctx, node)
    return _arith(op, a, b, ctx, node)


def _relation(op: str, a: Any, b: Any, ctx: Ctx, node: Any) -> Any:
    if isinstance(a, S.EnumValue) and isinstance(b, S.EnumValue):
        if op == "==":
            return a == b
        if op == "<>":
            return not a == b
        a, b = a.index, b.index
    if isinstance(a, str) and isinstance(b, str):
        return {"==": a == b, "<>": a != b, "<": a < b, "<=": a <= b, ">": a > b,
                ">=": a >= b}[op]
    a = _num_or_expr(a, ctx, node)
    b = _num_or_expr(b, ctx, node)
    if isinstance(a, list) or isinstance(b, list):
        raise fail(ctx.lex, node, "relations compare scalars, not arrays")
    if isinstance(a, Expr) or isinstance(b, Expr):
        if op == "==":
            return H.eq(a, b)
        if op == "<>":
            if not isinstance(a, Expr):
                a, b = b, a
            return a != b
        if op == "<":
            return a < b if isinstance(a, Expr) else b > a
        if op == "<=":
            return a <= b if isinstance(a, Expr) else b >= a
        if op == ">":
            return a > b if isinstance(a, Expr) else b < a
        return a >= b if isinstance(a, Expr) else b <= a
    return {"==": a == b, "<>": a != b, "<": a < b, "<=": a <= b, ">": a > b,
            ">=": a >= b}[op]


def _ev_unary(node: A.Unary, ctx: Ctx) -> Any:
    a = evaluate(node.a, ctx)
    if node.op == "not":
        if isinstance(a, Expr):
            return ~a
        if isinstance(a, list):
            raise fail(ctx.lex, node, "'not' of an array")
        return not a
    if node.op == "+":
        return a
    return _neg(a, ctx, node)


def _neg(a: Any, ctx: Ctx, node: Any) -> Any:
    if isinstance(a, list):
        return [_neg(x, ctx, node) for x in a]
    a = _num_or_expr(a, ctx, node)
    return -a


def _ev_if(node: A.IfExpr, ctx: Ctx) -> Any:
    conds = []
    for cond, val in node.branches:
        c = evaluate(cond, ctx)
        if isinstance(c, (bool, int, float)) and not isinstance(c, Expr):
            if c:
                if not conds:
                    return evaluate(val, ctx)
                conds.append((True, val))
                break
            continue
        conds.append((c, val))
    else:
        conds.append((True, node.otherwise))
    out = evaluate(conds[-1][1], ctx)
    for c, val in reversed(conds[:-1]):
        out = _if_else(c, evaluate(val, ctx), out, ctx, node)
    return out


def _if_else(c: Any, a: Any, b: Any, ctx: Ctx, node: Any) -> Any:
    if isinstance(a, list) or isinstance(b, list):
        if not (isinstance(a, list) and isinstance(b, list) and len(a) == len(b)):
            raise fail(ctx.lex, node, "if-expression branches of different sizes")
        return [_if_else(c, x, y, ctx, node) for x, y in zip(a, b, strict=True)]
    return X.if_else(c, _num_or_expr(a, ctx, node), _num_or_expr(b, ctx, node))


def _ev_range(node: A.Range, ctx: Ctx) -> Any:
    num = Ctx(ctx.env, ctx.lex, ctx.loops, True)
    start = numeric_value(evaluate(node.start, num), ctx.lex, node)
    stop = numeric_value(evaluate(node.stop, num), ctx.lex, node)
    step = 1 if node.step is None else numeric_value(evaluate(node.step, num), ctx.lex, node)
    if isinstance(start, S.EnumValue):
        raise fail(ctx.lex, node, "ranges of enumerations are not supported")
    if all(isinstance(v, int) and not isinstance(v, bool) for v in (start, stop, step)):
        if step == 0:
            raise fail(ctx.lex, node, "range step is zero")
        return list(range(start, stop + (1 if step > 0 else -1), step))
    if step == 0:
        raise fail(ctx.lex, node, "range step is zero")
    n = int(math.floor((stop - start) / step + 1e-12)) + 1
    return [start + k * step for k in range(max(n, 0))]


def _ev_array(node: A.ArrayLit, ctx: Ctx) -> Any:
    return [evaluate(x, ctx) for x in node.items]


def _ev_matrix(node: A.Matrix, ctx: Ctx) -> Any:
    rows = []
    for row in node.rows:
        vals = [evaluate(x, ctx) for x in row]
        if all(isinstance(v, list) for v in vals):      # [A, B] of column blocks
            rows.extend([sum((v[i] if isinstance(v[i], list) else [v[i]] for v in vals), [])
                         for i in range(len(vals[0]))])
        else:
            rows.append(vals)
    return rows


def _iterate(indices: tuple, ctx: Ctx, node: Any):
    """Yield loop dictionaries for ``for i in r, j in s``."""
    def rec(k: int, loops: dict):
        if k == len(indices):
            yield loops
            return
        name, rng = indices[k]
        if rng is None:
            raise fail(ctx.lex, node, f"for {name}: an iteration range is needed (implicit "
                       "ranges are not supported)")
        vals = evaluate(rng, Ctx(ctx.env, ctx.lex, loops, True))
        vals = numeric_value(vals, ctx.lex, rng)
        if not isinstance(vals, list):
            vals = [vals]
        for v in vals:
            inner = dict(loops)
            inner[name] = v
            yield from rec(k + 1, inner)

    return rec(0, ctx.loops)


def _ev_comp(node: A.ArrayComp, ctx: Ctx) -> Any:
    return _comprehension(node.expr, node.indices, ctx, node)


def _comprehension(expr: Any, indices: tuple, ctx: Ctx, node: Any) -> list:
    if len(indices) > 1:
        # {e for i in r, j in s}: the last iterator is the outermost
        outer = indices[-1]
        out = []
        for loops in _iterate((outer,), ctx, node):
            out.append(_comprehension(expr, indices[:-1],
                                      Ctx(ctx.env, ctx.lex, loops, ctx.numeric), node))
        return out
    return [evaluate(expr, Ctx(ctx.env, ctx.lex, loops, ctx.numeric))
            for loops in _iterate(indices, ctx, node)]


def _ev_call(node: A.Call, ctx: Ctx) -> Any:
    fname = _function_name(node, ctx)
    handler = _FUNCTIONS.get(fname)
    if handler is None:
        raise fail(ctx.lex, node, f"{node.func.dotted}() is not supported here")
    return handler(node, ctx)


def _function_name(node: A.Call, ctx: Ctx) -> str:
    ref = node.func
    parts = [p for p, _ in ref.parts]
    if len(parts) == 1:
        name = parts[0]
        found = S.lookup(ctx.lex, name) if ctx.lex is not None else None
        if found is None or isinstance(found, S.Builtin):
            if name in _FUNCTIONS:
                return name
            raise fail(ctx.lex, node, f"unknown function {name}()")
        if isinstance(found, S.ClassScope):
            return _user_function(found, node, ctx)
        raise fail(ctx.lex, node, f"{name} is not a function")
    found = S.lookup(ctx.lex, parts[0]) if ctx.lex is not None else None
    got = S.walk(found, parts[1:]) if found is not None else None
    if isinstance(got, tuple) and got and got[0] == "function":
        return got[1]
    if isinstance(got, S.ClassScope):
        return _user_function(got, node, ctx)
    raise fail(ctx.lex, node, f"unknown function {ref.dotted}()")


def _user_function(found: S.ClassScope, node: A.Call, ctx: Ctx) -> str:
    kind = found.cdef.kind
    if kind == "function":
        raise fail(ctx.lex, node, f"unsupported Modelica construct: call of the user-defined "
                   f"function {found.full_name}() (only the built-in functions are supported)")
    if kind == "record":
        raise fail(ctx.lex, node, f"unsupported Modelica construct: record constructor "
                   f"{found.full_name}()")
    if found.cdef.short is not None or found.cdef.enum is not None:
        name = found.cdef.name
        if name in ("Real", "Integer"):
            return name
    raise fail(ctx.lex, node, f"{found.full_name} is a {kind}, not a function")


def _args(node: A.Call, ctx: Ctx, n: int | tuple[int, ...], name: str) -> list:
    if node.iterator is not None:
        raise fail(ctx.lex, node, f"{name}() does not take an iterator")
    counts = (n,) if isinstance(n, int) else n
    if len(node.args) not in counts or node.kwargs:
        raise fail(ctx.lex, node, f"{name}() takes {' or '.join(map(str, counts))} "
                   f"positional argument(s), got {len(node.args)}"
                   + (f" and named {', '.join(node.kwargs)}" if node.kwargs else ""))
    return [evaluate(a, ctx) for a in node.args]


def _elementwise(fn):
    def apply(x):
        if isinstance(x, list):
            return [apply(v) for v in x]
        if isinstance(x, S.EnumValue):
            x = x.index
        return fn(x)
    return apply


def _unary_fn(name: str, fn):
    def handler(node: A.Call, ctx: Ctx) -> Any:
        (x,) = _args(node, ctx, 1, name)
        try:
            return _elementwise(fn)(x)
        except (ValueError, OverflowError) as err:
            raise fail(ctx.lex, node, f"{name}({x!r}): {err}") from None
    return handler


def _log10(x: Any) -> Any:
    if isinstance(x, Expr):
        return X.log(x) / math.log(10.0)
    return math.log10(x)


def _floor(x: Any) -> Any:
    if isinstance(x, Expr):
        return Op("floor", (x,))
    return math.floor(x)


def _ceil(x: Any) -> Any:
    if isinstance(x, Expr):
        return Op("ceil", (x,))
    return math.ceil(x)


def _symbolic(ctx: Ctx, node: Any, name: str) -> None:
    if ctx.numeric:
        raise NotConstant(f"{name}()")


def _fn_der(node: A.Call, ctx: Ctx) -> Any:
    _symbolic(ctx, node, "der")
    (x,) = _args(node, ctx, 1, "der")
    try:
        return _elementwise(X.der)(x)
    except ModelError as err:
        raise fail(ctx.lex, node, str(err)) from None


def _leaf_arg(x: Any, ctx: Ctx, node: Any, name: str) -> Any:
    if isinstance(x, list):
        return [_leaf_arg(v, ctx, node, name) for v in x]
    if not isinstance(x, Leaf):
        raise fail(ctx.lex, node, f"{name}() takes a variable, got {x!r}")
    return x


def _fn_pre(node: A.Call, ctx: Ctx) -> Any:
    _symbolic(ctx, node, "pre")
    (x,) = _args(node, ctx, 1, "pre")
    x = _leaf_arg(x, ctx, node, "pre")
    return _elementwise(H.pre)(x)


def _fn_edge(node: A.Call, ctx: Ctx) -> Any:
    _symbolic(ctx, node, "edge")
    (x,) = _args(node, ctx, 1, "edge")
    return _elementwise(H.edge)(_leaf_arg(x, ctx, node, "edge"))


def _fn_change(node: A.Call, ctx: Ctx) -> Any:
    _symbolic(ctx, node, "change")
    (x,) = _args(node, ctx, 1, "change")
    return _elementwise(H.change)(_leaf_arg(x, ctx, node, "change"))


def _fn_initial(node: A.Call, ctx: Ctx) -> Any:
    _symbolic(ctx, node, "initial")
    _args(node, ctx, 0, "initial")
    return H.initial()


def _fn_terminal(node: A.Call, ctx: Ctx) -> Any:
    _symbolic(ctx, node, "terminal")
    _args(node, ctx, 0, "terminal")
    return H.terminal()


def _fn_sample(node: A.Call, ctx: Ctx) -> Any:
    _symbolic(ctx, node, "sample")
    if node.kwargs:
        args = [evaluate(node.kwargs.get("start", A.Num(0)), ctx),
                evaluate(node.kwargs["interval"], ctx)] if "interval" in node.kwargs else []
    else:
        args = _args(node, ctx, 2, "sample")
    if len(args) != 2:
        raise fail(ctx.lex, node, "sample(start, interval) takes two arguments")
    start, interval = (a.index if isinstance(a, S.EnumValue) else a for a in args)
    try:
        return H.sample(start, interval)
    except ModelError as err:
        raise fail(ctx.lex, node, str(err)) from None


def _fn_noevent(node: A.Call, ctx: Ctx) -> Any:
    (x,) = _args(node, ctx, 1, "noEvent")
    return _elementwise(H.no_event)(x)


def _fn_smooth(node: A.Call, ctx: Ctx) -> Any:
    _, x = _args(node, ctx, 2, "smooth")
    return x


def _fn_homotopy(node: A.Call, ctx: Ctx) -> Any:
    if node.kwargs:
        if "actual" not in node.kwargs:
            raise fail(ctx.lex, node, "homotopy() needs actual=")
        return evaluate(node.kwargs["actual"], ctx)
    actual, _ = _args(node, ctx, 2, "homotopy")
    return actual


def _minmax(name: str):
    pick2 = X.fmin if name == "min" else X.fmax

    def handler(node: A.Call, ctx: Ctx) -> Any:
        if node.iterator is not None:
            items = _comprehension(node.iterator[0], node.iterator[1], ctx, node)
            items = _flatten(items)
        else:
            args = _args(node, ctx, (1, 2), name)
            items = _flatten(args[0]) if len(args) == 1 else args
            if len(args) == 2 and (isinstance(args[0], list) or isinstance(args[1], list)):
                raise fail(ctx.lex, node, f"{name}(a, b) of arrays: use {name}(array)")
        if not items:
            raise fail(ctx.lex, node, f"{name}() of an empty array")
        items = [_num_or_expr(v, ctx, node) for v in items]
        out = items[0]
        for v in items[1:]:
            out = pick2(out, v)
        return out
    return handler


def _reduction(name: str):
    def handler(node: A.Call, ctx: Ctx) -> Any:
        if node.iterator is not None:
            items = _flatten(_comprehension(node.iterator[0], node.iterator[1], ctx, node))
        else:
            (a,) = _args(node, ctx, 1, name)
            items = _flatten(a)
        if name == "sum":
            return _sum(items)
        out: Any = 1
        for v in items:
            out = out * v
        return out
    return handler


def _fn_abs(x: Any) -> Any:
    return X.fabs(x) if isinstance(x, Expr) else abs(x)


def _fn_sign(x: Any) -> Any:
    return X.sign(x) if isinstance(x, Expr) else (x > 0) - (x < 0)


def _fn_atan2(node: A.Call, ctx: Ctx) -> Any:
    y, x = _args(node, ctx, 2, "atan2")
    return X.atan2(y, x)


def _fn_mod(node: A.Call, ctx: Ctx) -> Any:
    x, y = _args(node, ctx, 2, "mod")
    if isinstance(x, Expr) or isinstance(y, Expr):
        return x - _floor(x / y) * y
    return x - math.floor(x / y) * y


def _fn_rem(node: A.Call, ctx: Ctx) -> Any:
    x, y = _args(node, ctx, 2, "rem")
    if isinstance(x, Expr) or isinstance(y, Expr):
        q = x / y
        return x - X.if_else(q < 0, _ceil(q), _floor(q)) * y
    return math.fmod(x, y)


def _fn_div(node: A.Call, ctx: Ctx) -> Any:
    x, y = _args(node, ctx, 2, "div")
    if isinstance(x, Expr) or isinstance(y, Expr):
        q = x / y
        return X.if_else(q < 0, _ceil(q), _floor(q))
    q = x / y
    return math.trunc(q)


def _fn_size(node: A.Call, ctx: Ctx) -> Any:
    args = _args(node, ctx, (1, 2), "size")
    shape = _shape(args[0])
    if len(args) == 1:
        return list(shape)
    k = numeric_value(args[1], ctx.lex, node)
    if not 1 <= k <= len(shape):
        raise fail(ctx.lex, node, f"size(a, {k}): a has {len(shape)} dimension(s)")
    return shape[int(k) - 1]


def _sizes(node: A.Call, ctx: Ctx, name: str, first: int = 0) -> tuple[list, list[int]]:
    if node.kwargs or node.iterator is not None:
        raise fail(ctx.lex, node, f"{name}() takes positional arguments")
    vals = [evaluate(a, ctx) for a in node.args]
    dims = []
    for v in vals[first:]:
        v = numeric_value(v, ctx.lex, node)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or v != int(v) or v < 0:
            raise fail(ctx.lex, node, f"{name}(): sizes must be non-negative Integers")
        dims.append(int(v))
    return vals, dims


def _filled(value: Any, dims: list[int]) -> Any:
    if not dims:
        return value
    return [_filled(value, dims[1:]) for _ in range(dims[0])]


def _fn_zeros(node: A.Call, ctx: Ctx) -> Any:
    return _filled(0, _sizes(node, ctx, "zeros")[1])


def _fn_ones(node: A.Call, ctx: Ctx) -> Any:
    return _filled(1, _sizes(node, ctx, "ones")[1])


def _fn_fill(node: A.Call, ctx: Ctx) -> Any:
    vals, dims = _sizes(node, ctx, "fill", 1)
    return _filled(vals[0], dims)


def _fn_identity(node: A.Call, ctx: Ctx) -> Any:
    _, (n,) = _sizes(node, ctx, "identity")
    return [[1 if i == j else 0 for j in range(n)] for i in range(n)]


def _fn_linspace(node: A.Call, ctx: Ctx) -> Any:
    a, b, n = _args(node, ctx, 3, "linspace")
    n = int(numeric_value(n, ctx.lex, node))
    if n < 2:
        raise fail(ctx.lex, node, "linspace(x1, x2, n) needs n >= 2")
    return [a + (b - a) * k / (n - 1) for k in range(n)]


def _fn_transpose(node: A.Call, ctx: Ctx) -> Any:
    (m,) = _args(node, ctx, 1, "transpose")
    if len(_shape(m)) != 2:
        raise fail(ctx.lex, node, "transpose() of a matrix")
    return [list(r) for r in zip(*m, strict=True)]


def _fn_vector(node: A.Call, ctx: Ctx) -> Any:
    (m,) = _args(node, ctx, 1, "vector")
    return _flatten(m)


def _fn_scalar(node: A.Call, ctx: Ctx) -> Any:
    (m,) = _args(node, ctx, 1, "scalar")
    flat = _flatten(m)
    if len(flat) != 1:
        raise fail(ctx.lex, node, "scalar() of an array with more than one element")
    return flat[0]


def _fn_integer(node: A.Call, ctx: Ctx) -> Any:
    (x,) = _args(node, ctx, 1, "integer")
    if isinstance(x, S.EnumValue):
        return x.index
    return _floor(x) if isinstance(x, Expr) else int(math.floor(x))


def _fn_real(node: A.Call, ctx: Ctx) -> Any:
    (x,) = _args(node, ctx, 1, "Real")
    return float(x) if isinstance(x, (int, float)) else x


def _fn_cross(node: A.Call, ctx: Ctx) -> Any:
    a, b = _args(node, ctx, 2, "cross")
    if _shape(a) != (3,) or _shape(b) != (3,):
        raise fail(ctx.lex, node, "cross() of two 3-vectors")
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _fn_unsupported(name: str, what: str):
    def handler(node: A.Call, ctx: Ctx) -> Any:
        raise fail(ctx.lex, node, f"unsupported Modelica construct: {what}")
    return handler


def _fn_statement(name: str):
    def handler(node: A.Call, ctx: Ctx) -> Any:
        raise fail(ctx.lex, node, f"{name}() is a statement of an equation section, not an "
                   "expression")
    return handler


_FUNCTIONS: dict[str, Any] = {
    "der": _fn_der, "pre": _fn_pre, "edge": _fn_edge, "change": _fn_change,
    "initial": _fn_initial, "terminal": _fn_terminal, "sample": _fn_sample,
    "noEvent": _fn_noevent, "smooth": _fn_smooth, "homotopy": _fn_homotopy,
    "abs": _unary_fn("abs", _fn_abs), "sign": _unary_fn("sign", _fn_sign),
    "sqrt": _unary_fn("sqrt", X.sqrt), "sin": _unary_fn("sin", X.sin),
    "cos": _unary_fn("cos", X.cos), "tan": _unary_fn("tan", X.tan),
    "asin": _unary_fn("asin", X.asin), "acos": _unary_fn("acos", X.acos),
    "atan": _unary_fn("atan", X.atan), "sinh": _unary_fn("sinh", X.sinh),
    "cosh": _unary_fn("cosh", X.cosh), "tanh": _unary_fn("tanh", X.tanh),
    "exp": _unary_fn("exp", X.exp), "log": _unary_fn("log", X.log),
    "log10": _unary_fn("log10", _log10), "floor": _unary_fn("floor", _floor),
    "ceil": _unary_fn("ceil", _ceil), "atan2": _fn_atan2,
    "min": _minmax("min"), "max": _minmax("max"), "sum": _reduction("sum"),
    "product": _reduction("product"), "mod": _fn_mod, "rem": _fn_rem, "div": _fn_div,
    "size": _fn_size, "zeros": _fn_zeros, "ones": _fn_ones, "fill": _fn_fill,
    "identity": _fn_identity, "linspace": _fn_linspace, "transpose": _fn_transpose,
    "vector": _fn_vector, "scalar": _fn_scalar, "integer": _fn_integer,
    "Integer": _fn_integer, "Real": _fn_real, "cross": _fn_cross,
    "delay": _fn_unsupported("delay", "delay() (time delays)"),
    "spatialDistribution": _fn_unsupported("spatialDistribution", "spatialDistribution()"),
    "cardinality": _fn_unsupported("cardinality", "cardinality()"),
    "inStream": _fn_unsupported("inStream", "stream connectors (inStream)"),
    "actualStream": _fn_unsupported("actualStream", "stream connectors (actualStream)"),
    "String": _fn_unsupported("String", "String() conversions"),
    "connect": _fn_statement("connect"), "reinit": _fn_statement("reinit"),
    "assert": _fn_statement("assert"), "terminate": _fn_statement("terminate"),
}

_EVAL: dict[type, Any] = {
    A.Num: _ev_num, A.Str: _ev_str, A.Bool: _ev_bool, A.Ref: _ev_ref, A.BinOp: _ev_binop,
    A.Unary: _ev_unary, A.IfExpr: _ev_if, A.Range: _ev_range, A.ArrayLit: _ev_array,
    A.ArrayComp: _ev_comp, A.Matrix: _ev_matrix, A.Call: _ev_call,
}


# -- numeric values ----------------------------------------------------------------------------


_NUM_OPS = {
    "+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b,
    "/": lambda a, b: a / b, "**": lambda a, b: a ** b, "<": lambda a, b: a < b,
    "<=": lambda a, b: a <= b, "!=": lambda a, b: a != b, "==": lambda a, b: a == b,
    "and": lambda a, b: bool(a) and bool(b), "or": lambda a, b: bool(a) or bool(b),
    "neg": lambda a: -a, "not": lambda a: not a, "noEvent": lambda a: a,
    "fabs": abs, "sign": lambda a: (a > 0) - (a < 0), "floor": math.floor, "ceil": math.ceil,
    "atan2": math.atan2, "fmin": min, "fmax": max,
    "if_else": lambda c, a, b: a if c else b,
    **{n: getattr(math, n) for n in ("sin", "cos", "tan", "exp", "log", "sqrt", "asin", "acos",
                                     "atan", "sinh", "cosh", "tanh")},
}


def numeric_value(v: Any, lex: Any = None, node: Any = None) -> Any:
    """``v`` with parameters replaced by their values (raises :class:`NotConstant` if it
    depends on variables or time)."""
    if isinstance(v, (bool, int, float, str, S.EnumValue)):
        return v
    if isinstance(v, list):
        return [numeric_value(x, lex, node) for x in v]
    if isinstance(v, Leaf):
        sym = v.sym
        if sym is TIME:
            raise NotConstant("time")
        decl = getattr(sym, "decl", None)
        if decl is None or decl.kind != KIND_PARAMETER:
            raise NotConstant(f"{getattr(sym, 'name', sym)} is not a parameter")
        owner = getattr(sym, "owner", None)
        env = owner.__dict__.get("_mo_env") if owner is not None else None
        if env is not None:
            if sym.name in env.view.elements:
                return env.numeric(sym.name)
            m = _NAME.match(sym.name)
            if m is not None and m.group(1) in env.view.elements:
                whole = env.numeric(m.group(1))
                for i in (int(x) for x in m.group(2).split(",")):
                    whole = whole[i - 1] if isinstance(whole, list) else whole
                return whole
        return numeric_value(decl.value, lex, node)
    if isinstance(v, Op):
        args = [numeric_value(a, lex, node) for a in v.args]
        fn = _NUM_OPS.get(v.op)
        if fn is None:
            raise NotConstant(f"operation {v.op}")
        return fn(*args)
    if isinstance(v, Element):
        raise NotConstant(f"component {v.name}")
    raise NotConstant(repr(v))


# -- equations ---------------------------------------------------------------------------------


def _is_number(v: Any) -> bool:
    return isinstance(v, (bool, int, float)) and not isinstance(v, Expr)


def _equation(a: Any, b: Any, ctx: Ctx, node: Any, out: list) -> None:
    if isinstance(a, list) or isinstance(b, list):
        if not (isinstance(a, list) and isinstance(b, list)):
            if isinstance(a, list) and _is_number(b) or isinstance(b, list) and _is_number(a):
                raise fail(ctx.lex, node, "array equation with a scalar side")
            raise fail(ctx.lex, node, "array equation with a scalar side")
        if len(a) != len(b):
            raise fail(ctx.lex, node, f"array equation of sizes {len(a)} and {len(b)}")
        for x, y in zip(a, b, strict=True):
            _equation(x, y, ctx, node, out)
        return
    a = a.index if isinstance(a, S.EnumValue) else a
    b = b.index if isinstance(b, S.EnumValue) else b
    if isinstance(a, Element) or isinstance(b, Element):
        raise fail(ctx.lex, node, "an equation between components: use connect(a, b)")
    if isinstance(a, Expr):
        out.append(Equation(a, b))
    elif isinstance(b, Expr):
        out.append(Equation(b, a))
    else:
        raise fail(ctx.lex, node, f"equation {a!r} = {b!r} has no variables")


def equations_of(env: Env, eqs: list, initial: bool = False) -> list:
    """The bgmodelica equations of the Modelica equations ``eqs`` for instance ``env``."""
    out: list = []
    for eq, lex in eqs:
        _eval_equation(eq, Ctx(env, lex, {}, False), out, initial)
    return out


def _eval_equation(eq: Any, ctx: Ctx, out: list, initial: bool) -> None:
    try:
        if isinstance(eq, A.EqSimple):
            try:
                a = evaluate(eq.lhs, ctx)
                b = evaluate(eq.rhs, ctx)
            except NotConstant as err:
                raise fail(ctx.lex, eq, f"cannot evaluate: {err.what}") from None
            _equation(a, b, ctx, eq, out)
        elif isinstance(eq, A.EqCall):
            _eval_call_equation(eq, ctx, out, initial)
        elif isinstance(eq, A.EqFor):
            for loops in _iterate(eq.indices, ctx, eq):
                inner = Ctx(ctx.env, ctx.lex, loops, False)
                for sub in eq.body:
                    _eval_equation(sub, inner, out, initial)
        elif isinstance(eq, A.EqIf):
            _eval_if_equation(eq, ctx, out, initial)
        elif isinstance(eq, A.EqWhen):
            if initial:
                raise fail(ctx.lex, eq, "when-equations are not allowed in initial equations")
            out.append(_eval_when(eq, ctx))
        elif isinstance(eq, A.Unsupported):
            raise fail(ctx.lex, eq, f"unsupported Modelica construct: {eq.what}")
        else:
            raise fail(ctx.lex, eq, f"unsupported equation {type(eq).__name__}")
    except _Disabled:
        if isinstance(eq, A.EqCall) and eq.call.func.dotted == "connect":
            return
        raise fail(ctx.lex, eq, "the equation uses a conditional component that is switched "
                   "off") from None
    except (ConnectError, EquationError, DeclarationError) as err:
        if isinstance(err, ModelicaError):
            raise
        raise fail(ctx.lex, eq, str(err)) from None


def _eval_call_equation(eq: A.EqCall, ctx: Ctx, out: list, initial: bool) -> None:
    call = eq.call
    name = call.func.dotted
    if name == "connect":
        if len(call.args) != 2 or call.kwargs:
            raise fail(ctx.lex, eq, "connect(a, b) takes two connectors")
        a = evaluate(call.args[0], ctx)
        b = evaluate(call.args[1], ctx)
        _connect(a, b, ctx, eq, out)
        return
    if name == "assert":
        return
    if name == "reinit":
        raise fail(ctx.lex, eq, "reinit() is allowed only inside a when-equation")
    if name == "terminate":
        raise fail(ctx.lex, eq, "unsupported Modelica construct: terminate()")
    raise fail(ctx.lex, eq, f"{name}(...) is not an equation (write 'expression = "
               "expression')")


def _connect(a: Any, b: Any, ctx: Ctx, node: Any, out: list) -> None:
    if isinstance(a, list) or isinstance(b, list):
        if not (isinstance(a, list) and isinstance(b, list) and len(a) == len(b)):
            raise fail(ctx.lex, node, "connect() of arrays of different sizes")
        for x, y in zip(a, b, strict=True):
            _connect(x, y, ctx, node, out)
        return
    out.append(connect(a, b))


def _eval_if_equation(eq: A.EqIf, ctx: Ctx, out: list, initial: bool) -> None:
    symbolic = []
    for cond, body in eq.branches:
        try:
            c = numeric_value(evaluate(cond, Ctx(ctx.env, ctx.lex, ctx.loops, True)), ctx.lex,
                              cond)
        except NotConstant:
            c = None
        if c is None:
            symbolic.append((evaluate(cond, ctx), body))
            continue
        if c:
            if not symbolic:
                for sub in body:
                    _eval_equation(sub, ctx, out, initial)
                return
            symbolic.append((True, body))
            break
    else:
        if not symbolic:
            for sub in eq.otherwise:
                _eval_equation(sub, ctx, out, initial)
            return
        symbolic.append((True, eq.otherwise))
    branches = []
    for c, body in symbolic:
        eqs: list = []
        for sub in body:
            _eval_equation(sub, ctx, eqs, initial)
        for e in eqs:
            if not isinstance(e, Equation):
                raise fail(ctx.lex, eq, "an if-equation with a condition that changes during "
                           "the simulation may hold only equations 'a = b'")
        branches.append((c, eqs))
    otherwise = branches.pop()[1] if branches[-1][0] is True else []
    first_c, first = branches[0]
    try:
        out.append(H.if_equation(first_c, first, otherwise, *branches[1:]))
    except ModelError as err:
        raise fail(ctx.lex, eq, str(err)) from None


def _eval_when(eq: A.EqWhen, ctx: Ctx) -> Any:
    result = None
    for cond, body in eq.branches:
        c = evaluate(cond, ctx)
        stmts: list = []
        for st in body:
            if isinstance(st, A.EqSimple):
                a = evaluate(st.lhs, ctx)
                b = evaluate(st.rhs, ctx)
                _equation(a, b, ctx, st, stmts)
            elif isinstance(st, A.EqCall) and st.call.func.dotted == "reinit":
                if len(st.call.args) != 2:
                    raise fail(ctx.lex, st, "reinit(x, value) takes two arguments")
                x = evaluate(st.call.args[0], ctx)
                v = evaluate(st.call.args[1], ctx)
                xs, vs = (x, v) if isinstance(x, list) else ([x], [v])
                for xi, vi in zip(xs, vs if isinstance(vs, list) else [vs] * len(xs),
                                  strict=True):
                    try:
                        stmts.append(H.reinit(xi, vi))
                    except ModelError as err:
                        raise fail(ctx.lex, st, str(err)) from None
            elif isinstance(st, A.EqCall) and st.call.func.dotted in ("assert",):
                continue
            elif isinstance(st, A.EqCall) and st.call.func.dotted == "terminate":
                raise fail(ctx.lex, st, "unsupported Modelica construct: terminate()")
            else:
                raise fail(ctx.lex, st, "unsupported Modelica construct in a when-equation "
                           "(supported: 'v = expression' and reinit(x, value))")
        try:
            if result is None:
                result = H.when(c, *stmts)
            else:
                result.elsewhen(c, *stmts)
        except ModelError as err:
            raise fail(ctx.lex, eq, str(err)) from None
    return result


# -- instantiation -----------------------------------------------------------------------------


_ATTRS = ("start", "fixed", "min", "max", "nominal", "stateSelect", "unit", "quantity",
          "displayUnit", "unbounded")


def _attr_values(m: Mod | None, numeric_ctx: bool, lex: Any, comp: A.Component) -> dict:
    out: dict[str, Any] = {}
    if m is None:
        return out
    for k, sub in m.sub.items():
        if k not in _ATTRS:
            raise fail(sub.lex or lex, sub.pos, f"{comp.name}: {k!r} is not an attribute of a "
                       f"{comp.type_name} (attributes: start, fixed, min, max, nominal, "
                       "stateSelect, unit)")
        if sub.has_binding and k not in ("quantity", "displayUnit", "unbounded"):
            out[k] = sub.value(True)
    return out


def _make_decl(info: ElemInfo, tref: TypeRef, attrs: dict, value: Any, connector: bool,
               lex: Any) -> Any:
    comp = info.comp
    pre = comp.prefixes | ({tref.prefix} if tref.prefix else set())
    desc = comp.description
    unit = attrs.get("unit", "")
    if not isinstance(unit, str):
        raise fail(lex, comp, f"{comp.name}: unit must be a string")
    if tref.base != "Real":
        unit = ""
    kw: dict[str, Any] = {"unit": unit, "description": desc}
    for k in ("min", "max"):
        if k in attrs and attrs[k] is not None:
            v = attrs[k]
            kw[k] = float(v.index if isinstance(v, S.EnumValue) else v)
    if "stream" in pre:
        raise fail(lex, comp, "unsupported Modelica construct: stream variables")
    if "parameter" in pre:
        if isinstance(value, S.EnumValue):
            value = float(value.index)
        elif _is_number(value):
            value = float(value)
        return Parameter(value=value, **kw)
    start = attrs.get("start")
    if start is not None:
        start = start.index if isinstance(start, S.EnumValue) else start
        if isinstance(start, list) or not _is_number(start):
            raise fail(lex, comp, f"{comp.name}: start value {start!r} is not a number")
        kw["start"] = start if tref.base == "Boolean" and isinstance(start, bool) \
            else float(start) if tref.base == "Real" else start
    if "fixed" in attrs:
        kw["fixed"] = bool(attrs["fixed"])
    if "nominal" in attrs and tref.base == "Real":
        kw["nominal"] = float(attrs["nominal"])
    if "stateSelect" in attrs:
        ss = attrs["stateSelect"]
        if not isinstance(ss, S.EnumValue) or ss.literal not in StateSelect.__members__.keys() \
                and ss.literal.upper() not in StateSelect.__members__:
            raise fail(lex, comp, f"{comp.name}: stateSelect must be a StateSelect value")
        kw["state_select"] = StateSelect[ss.literal.upper()]
    if connector and "flow" in pre:
        return Flow(**kw)
    if "flow" in pre:
        raise fail(lex, comp, f"{comp.name}: flow variables belong in connectors")
    if "input" in pre:
        return Input(**kw)
    if "output" in pre:
        return Output(**kw)
    if connector:
        return Potential(**kw)
    if tref.base == "Boolean":
        kw.pop("unit")
        kw.pop("nominal", None)
        kw.pop("state_select", None)
        return Boolean(**kw)
    if tref.base in ("Integer", "enum"):
        kw.pop("unit")
        kw.pop("nominal", None)
        kw.pop("state_select", None)
        return Integer(**kw)
    if "discrete" in pre:
        return Discrete(**kw)
    return Variable(**kw)


def _indices(dims: tuple[int, ...]) -> list[tuple]:
    out: list[tuple] = [()]
    for d in dims:
        out = [t + (i,) for t in out for i in range(1, d + 1)]
    return out


def _elem_name(name: str, idx: tuple) -> str:
    return f"{name}[{','.join(map(str, idx))}]" if idx else name


def _static_decl(info: ElemInfo, tref: TypeRef, idx: tuple, connector: bool) -> tuple[Any, bool]:
    """The class-level declaration of one scalar (attributes that need no instance), and
    whether it is complete (no per-instance evaluation needed without outer modifiers)."""
    key = idx
    if key in info.defaults:
        return info.defaults[key]
    m = merge(info.mod, tref.mod)
    m = index_mod(m, idx) if idx else m
    static = "parameter" in info.comp.prefixes or m is None or not m.has_binding
    try:
        attrs = _attr_values(_static_only(m), True, info.lex, info.comp)
        value = None
        if "parameter" in info.comp.prefixes:
            if m is not None and m.has_binding:
                value = _static_value(m)
            elif "start" in attrs:
                value = attrs["start"]
            else:
                value = _default_value(tref)
    except (NotConstant, ModelicaError):       # needs the instance (or its modifiers)
        static = False
        attrs = {}
        value = _default_value(tref) if "parameter" in info.comp.prefixes else None
        try:
            attrs = {k: v for k, v in _attr_values(_static_only(m, keep_units=True), True,
                                                   info.lex, info.comp).items()
                     if k == "unit"}
        except (NotConstant, ModelicaError):
            attrs = {}
    decl = _make_decl(info, tref, attrs, value, connector, info.lex)
    info.defaults[key] = (decl, static)
    return decl, static


def _static_only(m: Mod | None, keep_units: bool = False) -> Mod | None:
    """``m`` with SELF scopes evaluated statically (no instance): names raise NotConstant."""
    if m is None:
        return None
    if keep_units:
        sub = {k: v for k, v in m.sub.items() if k == "unit"}
        out = Mod(None, None, m.lex, sub={k: _static_only(v) for k, v in sub.items()})
        return out
    out = Mod(m.binding, None, m.lex, m.each, {k: _static_only(v) for k, v in m.sub.items()},
              None, m.pos, m.const)
    if m.source is not None:
        src = _static_only(m.source)
        out.source, out.index = src, m.index
    return out


def _static_value(m: Mod) -> Any:
    return _static_only(m).value(True)


def _instance_decl(env: Env, info: ElemInfo, tref: TypeRef, idx: tuple,
                   connector: bool) -> Any:
    m = env.emod(info.comp.name)
    m = index_mod(m, idx) if idx else m
    try:
        attrs = _attr_values(m, True, info.lex, info.comp)
    except NotConstant as err:
        raise fail(info.lex, info.comp, f"{info.comp.name}: attribute values must be known "
                   f"when the model is built ({err.what})") from None
    value = None
    if "parameter" in info.comp.prefixes:
        if m is not None and m.has_binding:
            try:
                value = m.value(False)
            except NotConstant as err:
                raise fail(info.lex, info.comp, f"{info.comp.name}: {err.what}") from None
            if isinstance(value, list):
                raise fail(info.lex, info.comp, f"parameter {_elem_name(info.comp.name, idx)}"
                           f" is bound to an array")
            if isinstance(value, Element):
                raise fail(info.lex, info.comp, f"parameter {info.comp.name} is bound to a "
                           "component")
        elif "start" in attrs:
            value = attrs["start"]
        else:
            value = _default_value(tref)
    return _make_decl(info, tref, attrs, value, connector, info.lex)


def _check_supported(view: ClassView, where: S.ClassScope) -> None:
    if view.unsupported:
        u, lex = view.unsupported[0]
        raise fail(lex, u, f"unsupported Modelica construct: {u.what} in "
                   f"{lex.full_name}")
    kind = view.kind
    if kind in ("function",):
        raise fail(where, view.cdef, f"{view.scope.full_name} is a function, not a model")
    if kind == "package":
        raise fail(where, view.cdef, f"{view.scope.full_name} is a package, not a model")
    if kind == "expandable connector":
        raise fail(where, view.cdef, "unsupported Modelica construct: expandable connectors")
    if kind == "operator":
        raise fail(where, view.cdef, "unsupported Modelica construct: operator classes")


def instantiate(view: ClassView, mods: dict[str, Mod], parent: Env | None, path: str,
                where: S.ClassScope | None = None, pos: A.Pos = (0, 0)) -> Element:
    """Build the bgmodelica element of ``view`` with modifications ``mods``."""
    if not view.checked:
        _check_supported(view, where or view.scope)
        view.checked = True
    env = Env(view, mods, parent, path)
    connector = "connector" in view.kind
    for name in mods:
        if name not in view.elements:
            m = mods[name]
            raise fail(m.lex or where, m.pos if m.pos != (0, 0) else pos,
                       f"{view.scope.full_name} has no element {name!r} to modify; it has: "
                       f"{', '.join(view.elements) or 'none'}")
    plan = view.plan
    if plan is not None and not any(m.redeclare is not None for m in mods.values()):
        arrays, scalars, children, cls = plan
        arrays = dict(arrays)
    else:
        arrays, scalars, children, cls = _plan(view, env, connector)
        view = env.view
    try:
        inst = cls()
    except ModelError as err:
        raise fail(where or view.scope, pos, str(err)) from None
    env.inst = inst
    object.__setattr__(inst, "_mo_env", env)
    object.__setattr__(inst, "_mo_members", {})
    if arrays:
        object.__setattr__(inst, "_mo_arrays", arrays)
    # subcomponents (their modifiers may refer to this instance's parameters)
    for info, tref, dims in children:
        name = info.comp.name
        m = env.emod(name)
        for idx in _indices(dims):
            cname = _elem_name(name, idx)
            cm = index_mod(m, idx) if idx else m
            child = _make_child(tref, cm, env, _join(path, cname), info)
            _add_child(inst, cname, child, info)
        if dims:
            arrays_of = inst.__dict__.get("_mo_arrays")
            if arrays_of is None:
                arrays_of = {}
                object.__setattr__(inst, "_mo_arrays", arrays_of)
            arrays_of[name] = dims
    # instance-specific declarations
    emods = env.mods
    bindings: list[tuple[Any, Mod, ElemInfo]] = []
    for info, tref, idx, ename in scalars:
        name = info.comp.name
        default, static = info.defaults[idx]
        sym = inst._symbols[ename]
        if static:
            outer = emods.get(name)
            if outer is None:
                continue
            m = index_mod(outer, idx) if idx else outer
            sym.decl = _override(default, m, info, tref)
        else:
            sym.decl = _instance_decl(env, info, tref, idx, connector)
            m = env.emod(name)
            m = index_mod(m, idx) if idx and m is not None else m
        if m is not None and m.has_binding and sym.decl.kind != KIND_PARAMETER:
            bindings.append((sym, m, info))
    if bindings:
        _declaration_equations(inst, bindings, connector)
    if not view.validated:
        # evaluate the equations of the first instance of each class now, so that unknown
        # names, bad calls and wrong connects are reported when the model is loaded
        view.validated = True
        if not connector:
            # kept for the first flattening (it would evaluate them again otherwise)
            env.cached = (equations_of(env, view.equations),
                          equations_of(env, view.initial, initial=True))
    return inst


def _declaration_equations(inst: Element, bindings: list, connector: bool) -> None:
    """``Real x = expr`` (in the class or from a modifier): the equation ``x = expr``,
    evaluated where the binding is written."""
    eqs: list = []
    for sym, m, info in bindings:
        lex = m.lex or info.lex
        if connector:
            raise fail(lex, m.pos, f"{info.comp.name}: a connector variable cannot have a "
                       "declaration equation")
        try:
            value = m.value(False)
        except NotConstant as err:
            raise fail(lex, m.pos, f"{info.comp.name}: {err.what}") from None
        _equation(sym.leaf, value, Ctx(None, lex, {}, False), m, eqs)
    inst._equations.extend(eqs)


_FIELDS = {"start": "start", "fixed": "fixed", "min": "min", "max": "max",
           "nominal": "nominal", "stateSelect": "state_select", "unit": "unit"}


def _override(decl: Any, m: Mod, info: ElemInfo, tref: TypeRef) -> Any:
    """``decl`` (complete without instance) with an outer modification applied."""
    changes: dict[str, Any] = {}
    comp = info.comp
    if m.has_binding and decl.kind == KIND_PARAMETER:
        try:
            value = m.value(False)
        except NotConstant as err:
            raise fail(m.lex or info.lex, m.pos, f"{comp.name}: {err.what}") from None
        if isinstance(value, S.EnumValue):
            value = float(value.index)
        elif _is_number(value):
            value = float(value)
        elif isinstance(value, (list, Element, str)):
            raise fail(m.lex or info.lex, m.pos, f"parameter {comp.name} is bound to "
                       f"{type(value).__name__} {value!r}")
        changes["value"] = value
    if m.sub:
        attrs = _attr_values(m, True, info.lex, comp)
        for k, v in attrs.items():
            f = _FIELDS.get(k)
            if f is None or (decl.kind == KIND_PARAMETER and k not in ("min", "max", "start",
                                                                       "unit")):
                continue
            if k == "start" and decl.kind == KIND_PARAMETER:
                if "value" not in changes and not m.has_binding:
                    changes["value"] = float(v)
                continue
            if k == "stateSelect":
                if not isinstance(v, S.EnumValue):
                    raise fail(info.lex, comp, f"{comp.name}: stateSelect must be a "
                               "StateSelect value")
                v = StateSelect[v.literal.upper()]
            elif k == "fixed":
                v = bool(v)
            elif k == "unit":
                if tref.base != "Real":
                    continue
            elif k == "start" and tref.base == "Boolean" and isinstance(v, bool):
                pass
            else:
                v = v.index if isinstance(v, S.EnumValue) else v
                if not _is_number(v):
                    raise fail(info.lex, comp, f"{comp.name}: {k} = {v!r} is not a number")
                v = float(v)
            changes[f] = v
    return replace(decl, **changes) if changes else decl


def _plan(view: ClassView, env: Env, connector: bool) -> tuple:
    """The structure of one instance: declarations (array sizes and conditional components
    evaluated), subcomponents, and the Python class. Cached on the view when it cannot depend
    on the instance (no arrays, no conditions)."""
    decls: dict[str, Any] = {}
    arrays: dict[str, tuple[int, ...]] = {}
    scalars: list[tuple[ElemInfo, TypeRef, tuple, str]] = []
    children: list[tuple[ElemInfo, TypeRef, tuple]] = []
    consts: list[str] = []
    cacheable = True
    for name, info in view.elements.items():
        comp = info.comp
        bad = comp.element_prefixes & {"inner", "outer"}
        if bad:
            raise fail(info.lex, comp, f"unsupported Modelica construct: {'/'.join(sorted(bad))}"
                       f" ({comp.name})")
        if comp.condition is not None:
            cacheable = False
            try:
                on = numeric_value(evaluate(comp.condition, Ctx(env, info.lex, {}, True)),
                                   info.lex, comp.condition)
            except NotConstant as err:
                raise fail(info.lex, comp.condition, f"the condition of {name} must be a "
                           f"parameter expression ({err.what})") from None
            if not on:
                env.disabled.add(name)
                continue
        m = env.mods.get(name)
        if m is not None and m.redeclare is not None:
            el, lex = m.redeclare
            info = ElemInfo(el, lex, merge(_without_redeclare(m), mod_from_ast(el.mod, SELF,
                                                                                 lex)))
            cacheable = False
            env.view = view = _with_element(view, name, info, env)
            env.mods = {k: v for k, v in env.mods.items() if k != name}
            env._emod.pop(name, None)
        tref = type_ref(info)
        cat = _category(info, tref)
        if name in _RESERVED and cat in ("param", "var"):
            raise fail(info.lex, comp, f"the name {name!r} is reserved by bgmodelica's "
                       "Component class; rename the variable")
        if cat in ("const", "string"):
            consts.append(name)
            continue
        if comp.dims or (tref.kind == "scalar" and tref.dims):
            cacheable = False
        try:
            dims = _dims(info, env)
        except NotConstant as err:
            raise fail(info.lex, comp, f"array size of {name} must be known when the model "
                       f"is built ({err.what})") from None
        if cat == "child":
            children.append((info, tref, dims))
            continue
        if dims:
            arrays[name] = dims
        for idx in _indices(dims):
            ename = _elem_name(name, idx)
            decl, _static = _static_decl(info, tref, idx, connector)
            decls[ename] = decl
            scalars.append((info, tref, idx, ename))
    key = tuple(decls) + tuple(sorted(env.disabled)) + (view.kind,)
    cls = view.classes.get(key)
    if cls is None:
        cls = _make_class(view, decls, connector)
        view.classes[key] = cls
    plan = (arrays, scalars, children, cls)
    if cacheable:
        view.plan = plan
    return plan


def _with_element(view: ClassView, name: str, info: ElemInfo, env: Env) -> ClassView:
    """A copy of ``view`` where element ``name`` is redeclared."""
    new = ClassView.__new__(ClassView)
    new.__dict__.update(view.__dict__)
    new.elements = dict(view.elements)
    new.elements[name] = info
    new.classes = {}
    new.plan = None
    new.validated = False
    return new


def _join(path: str, name: str) -> str:
    return f"{path}.{name}" if path else name


def _add_child(inst: Element, name: str, child: Element, info: ElemInfo) -> None:
    if name.isidentifier():
        try:
            inst.add(name, child)
        except ModelError as err:
            raise fail(info.lex, info.comp, str(err)) from None
        return
    object.__setattr__(child, "_name", name)
    inst._children[name] = child
    object.__setattr__(inst, name, child)


def _make_class(view: ClassView, decls: dict[str, Any], connector: bool) -> type:
    body: dict[str, Any] = dict(decls)
    body["__module__"] = "bgmodelica.modelica.generated"
    body["__qualname__"] = view.scope.full_name
    body["__doc__"] = view.description or None
    if not connector:
        eqs = view.equations
        ieqs = view.initial

        def equations(self):
            env = self.__dict__["_mo_env"]
            if env.cached is not None and env.cached[0] is not None:
                out = env.cached[0]
                env.cached = (None, env.cached[1])
                return out
            return equations_of(env, eqs)

        def initial_equations(self):
            env = self.__dict__["_mo_env"]
            if env.cached is not None and env.cached[1] is not None:
                out = env.cached[1]
                env.cached = (env.cached[0], None)
                return out
            return equations_of(env, ieqs, initial=True)

        body["equations"] = equations
        if ieqs:
            body["initial_equations"] = initial_equations
    elif view.equations:
        eq, lex = view.equations[0]
        raise fail(lex, eq, "a connector cannot have equations")
    base = Connector if connector else Component
    try:
        return type(view.cdef.name, (base,), body)
    except ModelError as err:
        raise fail(view.scope, view.cdef, str(err)) from None


def _make_child(tref: TypeRef, m: Mod | None, env: Env, path: str, info: ElemInfo) -> Element:
    if m is not None and m.has_binding:
        raise fail(m.lex or info.lex, m.pos, f"{info.comp.name}: a component cannot be bound "
                   "with '=' (records and their constructors are not supported)")
    if tref.kind == "class":
        view = class_view(tref.scope)
        if view.kind == "package":
            raise fail(info.lex, info.comp, f"{tref.name} is a package, not a type")
        return instantiate(view, dict(m.sub) if m is not None else {}, env, path, info.lex,
                           info.comp.pos)
    if tref.kind == "msl":
        return _make_msl(tref.msl, m, path, info)
    raise fail(info.lex, info.comp, f"{info.comp.name}: cannot instantiate {tref.name}")


def _make_msl(msl: S.MslClass, m: Mod | None, path: str, info: ElemInfo) -> Element:
    entry = msl.entry
    cls = entry.load()
    sub = dict(m.sub) if m is not None else {}
    for low, high in entry.negated.items():         # MSL: yMin = -yMax unless given
        if low not in sub and high in sub and sub[high].has_binding:
            sub[low] = Mod(const=_neg(sub[high].value(False), Ctx(None, info.lex, {}, False),
                                      info.comp))
    kwargs: dict[str, Any] = {}
    rest: dict[str, Mod] = {}
    for name, sm in sub.items():
        if sm.redeclare is not None:
            raise fail(sm.lex or info.lex, sm.pos, f"redeclare inside {msl.path} is not "
                       "supported")
        if name in entry.ctor or name in entry.enum_ctor or name in entry.ignore:
            try:
                v = sm.value(True) if sm.has_binding else None
            except NotConstant as err:
                raise fail(sm.lex or info.lex, sm.pos, f"{msl.path}: {name} must be known "
                           f"when the model is built ({err.what})") from None
            if name in entry.ctor:
                kwargs[entry.ctor[name]] = v
            elif name in entry.enum_ctor:
                if not isinstance(v, S.EnumValue):
                    raise fail(sm.lex or info.lex, sm.pos, f"{msl.path}: {name} must be an "
                               "enumeration value")
                kwargs[entry.enum_ctor[name]] = v.literal
            else:
                default = entry.ignore[name]
                if default is not None and v is not None and v != default:
                    raise fail(sm.lex or info.lex, sm.pos,
                               f"{msl.path}: {name} = {v!r} is not supported by bgmodelica's "
                               f"mapping onto {entry.module}.{entry.cls} (only the default "
                               f"{default!r})")
            continue
        rest[entry.rename.get(name, name)] = sm
    try:
        inst = cls(**kwargs)
    except ModelError as err:
        raise fail(info.lex, info.comp, f"{msl.path}: {err}") from None
    except (TypeError, ValueError) as err:
        raise fail(info.lex, info.comp, f"{msl.path}: {err}") from None
    if entry.rename:
        object.__setattr__(inst, "_mo_rename", dict(entry.rename))
    apply_mods(inst, rest, info, msl.path)
    return inst


def apply_mods(elem: Element, mods: dict[str, Mod], info: ElemInfo, what: str) -> None:
    """Apply Modelica modifications to an element built from a Python class."""
    for name, m in mods.items():
        sym = elem._symbols.get(name)
        if sym is not None:
            decl = sym.decl
            for k in m.sub:
                if k not in _ATTRS:
                    raise fail(m.sub[k].lex or info.lex, m.sub[k].pos,
                               f"{what}: {k!r} is not an attribute of {name}")
            attrs = _attr_values(m, True, info.lex, info.comp)
            changes: dict[str, Any] = {}
            if decl.kind == KIND_PARAMETER:
                if m.has_binding:
                    try:
                        v = m.value(False)
                    except NotConstant as err:
                        raise fail(m.lex or info.lex, m.pos, f"{what}.{name}: {err.what}") \
                            from None
                    if isinstance(v, S.EnumValue):
                        v = v.index
                    changes["value"] = float(v) if _is_number(v) else v
                for k in ("min", "max"):
                    if k in attrs:
                        changes[k] = float(attrs[k])
            else:
                if m.has_binding:
                    raise fail(m.lex or info.lex, m.pos, f"{what}: {name} is a variable; set "
                               f"its start value with {name}(start=..., fixed=true)")
                for k, f in (("start", "start"), ("fixed", "fixed"), ("nominal", "nominal"),
                             ("min", "min"), ("max", "max")):
                    if k in attrs:
                        v = attrs[k]
                        changes[f] = bool(v) if k == "fixed" else float(v)
                if "stateSelect" in attrs:
                    changes["state_select"] = StateSelect[attrs["stateSelect"].literal.upper()]
            if "unit" in attrs and attrs["unit"] != decl.unit:
                raise fail(m.lex or info.lex, m.pos, f"{what}: {name} has unit "
                           f"{decl.unit!r}, not {attrs['unit']!r}")
            if changes:
                sym.decl = replace(decl, **changes)
            continue
        child = elem._children.get(name)
        if child is not None:
            if m.has_binding:
                raise fail(m.lex or info.lex, m.pos, f"{what}: {name} is a component")
            apply_mods(child, m.sub, info, f"{what}.{name}")
            continue
        have = [n for n in list(elem._symbols) + list(elem._children)]
        raise fail(m.lex or info.lex, m.pos, f"{what} has no parameter, variable or connector "
                   f"{name!r} in bgmodelica's mapping (it has: {', '.join(have)})")


# -- entry points ------------------------------------------------------------------------------


def find_class(file: S.FileScope, name: str) -> S.ClassScope:
    """The class ``name`` (dotted) of a parsed file."""
    got = file.find_full(name)
    if got is None:
        parts = name.split(".")
        head = S.lookup_top(file, parts[0])
        got = S.walk(head, parts[1:]) if head is not None and not isinstance(
            head, S.Builtin) else None
    if not isinstance(got, S.ClassScope):
        models = list_models(file)
        raise ModelicaError(f"{file.file}: no class {name!r}; it defines: "
                            f"{', '.join(models) or 'no models'}")
    return got


def list_models(file: S.FileScope) -> list[str]:
    """Dotted names of the models and blocks a file defines (not partial)."""
    out: list[str] = []

    def walk(scope: S.ClassScope, prefix: str) -> None:
        for el in scope.cdef.elements:
            if isinstance(el, A.ClassDef):
                name = f"{prefix}.{el.name}"
                if el.kind in ("model", "block", "class") and not el.partial:
                    out.append(name)
                if el.kind == "package":
                    walk(scope.nested(el.name), name)

    for name, scope in file.classes.items():
        if scope.cdef.kind in ("model", "block", "class") and not scope.cdef.partial:
            out.append(name)
        elif scope.cdef.kind == "package":
            walk(scope, name)
    return out


def top_mods(kwargs: dict[str, Any]) -> dict[str, Mod]:
    """Modifications of the top-level class from Python values (``n=100``,
    ``{"R1.R": 2.0}``)."""
    out: dict[str, Mod] = {}
    for key, value in kwargs.items():
        parts = key.split(".")
        m = Mod(const=value)
        for p in reversed(parts[1:]):
            m = Mod(sub={p: m})
        out[parts[0]] = merge(m, out.get(parts[0]))
    return out


def experiment(scope: S.ClassScope) -> dict[str, float]:
    """``annotation(experiment(StartTime=, StopTime=, Interval=, Tolerance=))`` of a class
    (inherited through ``extends``)."""
    out: dict[str, float] = {}
    cdef = scope.cdef
    if cdef.annotation is not None:
        for arg in cdef.annotation.args:
            if isinstance(arg, A.ElementMod) and arg.name == "experiment" and arg.mod:
                for sub in arg.mod.args:
                    if isinstance(sub, A.ElementMod) and sub.mod is not None \
                            and sub.mod.binding is not None:
                        try:
                            v = numeric_value(evaluate(sub.mod.binding,
                                                       Ctx(None, scope, {}, True)))
                        except (NotConstant, ModelicaError):
                            continue
                        if isinstance(v, (int, float)) and not isinstance(v, bool):
                            out[sub.name] = float(v)
    if not out:
        for el in cdef.elements:
            if isinstance(el, A.Extends):
                try:
                    base = resolve_class(scope, el.type_name, el.pos, scope)
                except ModelicaError:
                    continue
                if isinstance(base, S.ClassScope):
                    out = experiment(base)
                    if out:
                        break
    return out
