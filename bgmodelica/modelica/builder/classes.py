"""Class views: a Modelica class with its ``extends`` merged, the type of each element, and
class lookup by dotted name.
"""

from __future__ import annotations

from typing import Any

from .. import ast as A
from .. import scope as S
from ..errors import ModelicaError
from .base import SELF, fail
from .mods import Mod, _without_redeclare, merge, mod_from_ast


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
            _check_new_name(scope, el, view)
            view.elements[el.name] = ElemInfo(el, scope, mod_from_ast(el.mod, SELF, scope))
    for eq in cdef.equations:
        view.equations.append((eq, scope))
    for eq in cdef.initial_equations:
        view.initial.append((eq, scope))
    if cdef.kind not in ("function", "operator function"):
        view.equations.extend((s, scope) for s in cdef.algorithms)
        view.initial.extend((s, scope) for s in cdef.initial_algorithms)
    for u in refused(cdef):
        view.unsupported.append((u, scope))
    _discrete_by_when(view)
    scope._view = view
    return view


def _check_new_name(scope: S.ClassScope, el: A.Component, view: ClassView) -> None:
    """A component declared twice in one class, or named like a class declared there, is an
    error (specification 5.6.1); an inherited element of that name is redeclared only if
    the declarations are identical, which bgmodelica does not compare: the local one wins."""
    first = view.elements.get(el.name)
    if first is not None and first.lex is scope:
        raise fail(scope, el, f"component {el.name} is declared twice in {scope.cdef.name} "
                   f"(first at line {first.comp.pos[0]})")
    if any(isinstance(c, A.ClassDef) and c.name == el.name for c in scope.cdef.elements):
        raise fail(scope, el, f"component {el.name} has the name of a class declared in "
                   f"{scope.cdef.name}")


def check_not_final(info: ElemInfo, m: Mod) -> None:
    """A modifier (or redeclaration) of an element declared ``final`` is an error
    (specification 7.2.6)."""
    if "final" in info.comp.element_prefixes and (m.has_binding or m.sub or m.redeclare):
        raise fail(m.lex or info.lex, m.pos if m.pos != (0, 0) else info.comp,
                   f"{info.comp.name} is declared final (line {info.comp.pos[0]}) and cannot "
                   "be modified")


def constraining_mod(info: ElemInfo) -> Any:
    """The modifiers a redeclaration of ``info`` keeps: those of a ``replaceable``
    declaration without ``constrainedby`` (its type and modifiers constrain the new one,
    specification 7.3.2); none for other declarations."""
    comp = info.comp
    if "replaceable" in comp.element_prefixes and comp.constrainedby is None:
        return info.mod
    return None


def _discrete_by_when(view: ClassView) -> None:
    """A Real variable assigned in a when-equation or when-statement is discrete
    (specification 3.8.3): mark its declaration so."""
    import dataclasses

    names: set[str] = set()

    def lhs(eq: Any) -> None:
        if isinstance(eq, A.EqSimple) and isinstance(eq.lhs, A.Ref):
            names.add(eq.lhs.parts[0][0])
        elif isinstance(eq, A.EqSimple) and isinstance(eq.lhs, A.TupleExpr):
            names.update(i.parts[0][0] for i in eq.lhs.items if isinstance(i, A.Ref))
        elif isinstance(eq, A.Assign) and isinstance(eq.target, A.Ref):
            names.add(eq.target.parts[0][0])
        elif isinstance(eq, A.Assign) and isinstance(eq.target, A.TupleExpr):
            names.update(i.parts[0][0] for i in eq.target.items if isinstance(i, A.Ref))
        elif isinstance(eq, (A.EqIf, A.StmtIf, A.EqWhen, A.StmtWhen)):
            for _, body in eq.branches:
                for sub in body:
                    lhs(sub)
            for sub in getattr(eq, "otherwise", ()):
                lhs(sub)
        elif isinstance(eq, (A.EqFor, A.StmtFor)):
            for sub in eq.body:
                lhs(sub)

    def walk(items: Any) -> None:
        for eq in items:
            if isinstance(eq, (A.EqWhen, A.StmtWhen)):
                lhs(eq)
            elif isinstance(eq, (A.EqIf, A.StmtIf)):
                for _, body in eq.branches:
                    walk(body)
                walk(getattr(eq, "otherwise", ()))
            elif isinstance(eq, (A.EqFor, A.StmtFor, A.StmtWhile)):
                walk(eq.body)
            elif isinstance(eq, A.Statements):
                walk(eq)

    walk(eq for eq, _ in view.equations)
    for name in names:
        info = view.elements.get(name)
        if info is None:
            continue
        pre = info.comp.prefixes
        if pre & {"parameter", "constant", "discrete", "input", "output", "flow"}:
            continue
        info.comp = dataclasses.replace(info.comp, prefixes=pre | {"discrete"})


def refused(cdef: A.ClassDef) -> list[A.Unsupported]:
    """What a class holds that the builder does not implement yet (refused when a model is
    instantiated): algorithm sections, external clauses, ``model extends``."""
    out = list(cdef.unsupported)
    if cdef.external is not None:
        out.append(A.Unsupported("external function", cdef.external.pos))
    if cdef.class_extends is not None:
        out.append(A.Unsupported("class extends ('model extends B')", cdef.pos))
    return out


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
            new = ElemInfo(el, lex, merge(_without_redeclare(outer),
                                          merge(mod_from_ast(el.mod, SELF, lex),
                                                constraining_mod(info))))
        view.elements[name] = new
    if ext_mod is not None:
        for name, m in ext_mod.sub.items():
            if name not in base.elements:
                raise fail(m.lex, m.pos, f"extends {base.scope.full_name}: the base class has "
                           f"no element {name!r} to modify")
            check_not_final(base.elements[name], m)
    view.equations.extend(base.equations)
    view.initial.extend(base.initial)
    view.unsupported.extend(base.unsupported)


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
            from .. import msl
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
        raise ModelicaError(f"{file.file}:1:1: no class {name!r}; it defines: "
                            f"{', '.join(models) or 'no models'}"
                            + ("" if file.classes else " (the file declares no class)"))
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
