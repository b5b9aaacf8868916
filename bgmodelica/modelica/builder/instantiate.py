"""Instantiation: a Modelica class becomes a Python component class (one per structure), and an
instance of it is built with its subcomponents, arrays and modifiers.
"""

from __future__ import annotations

from typing import Any

from ...core.component import Component, Connector, Element
from ...core.variables import (
    KIND_PARAMETER,
)
from ...errors import ModelError
from .. import ast as A
from .. import scope as S
from ..errors import ModelicaError
from .arith import _neg
from .base import _RESERVED, SELF, Ctx, NotConstant, fail, numeric_value
from .classes import (
    ClassView,
    ElemInfo,
    TypeRef,
    check_not_final,
    class_view,
    constraining_mod,
    resolve_class,
    type_ref,
)
from .declarations import _elem_name, _indices, _instance_decl, _override, _static_decl, apply_mods
from .env import Env, _category, _dims
from .equations import _declaration_equations, equations_of
from .evaluate import evaluate
from .expandable import evaluate_all, make_bus
from .mods import Mod, _without_redeclare, index_mod, merge, mod_from_ast
from .templates import EquationTemplate


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
    if kind == "operator":
        raise fail(where, view.cdef, "unsupported Modelica construct: operator classes")


def instantiate(view: ClassView, mods: dict[str, Mod], parent: Env | None, path: str,
                where: S.ClassScope | None = None, pos: A.Pos = (0, 0)) -> Element:
    """Build the bgmodelica element of ``view`` with modifications ``mods``."""
    if not view.checked:
        _check_supported(view, where or view.scope)
        view.checked = True
    env = Env(view, mods, parent, path)
    if view.kind == "expandable connector":
        if mods:
            raise fail(where or view.scope, pos, "unsupported Modelica construct: modifiers "
                       "of an expandable connector")
        return make_bus(view, env)
    connector = "connector" in view.kind
    for name in mods:
        if name not in view.elements:
            m = mods[name]
            raise fail(m.lex or where, m.pos if m.pos != (0, 0) else pos,
                       f"{view.scope.full_name} has no element {name!r} to modify; it has: "
                       f"{', '.join(view.elements) or 'none'}")
        check_not_final(view.elements[name], mods[name])
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
        owner = parent.inst if parent is not None else None
        root = env
        while root.parent is not None:
            root = root.parent
        # evaluated once the whole model is built: a modifier may read a later sibling
        root.pending.append((inst, bindings, connector, owner))
    if parent is None:
        for args in env.pending:
            _declaration_equations(*args)
        env.pending.clear()
        if env.buses:
            view.validated = True
            evaluate_all(inst, equations_of)
    if not view.validated:
        # evaluate the equations of the first instance of each class now, so that unknown
        # names, bad calls and wrong connects are reported when the model is loaded
        view.validated = True
        if not connector:
            # kept for the first flattening (it would evaluate them again otherwise)
            env.cached = (equations_of(env, view.equations),
                          equations_of(env, view.initial, initial=True))
    return inst


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
            info = ElemInfo(el, lex, merge(_without_redeclare(m),
                                           merge(mod_from_ast(el.mod, SELF, lex),
                                                 constraining_mod(info))))
            cacheable = False
            env.view = view = _with_element(view, name, info, env)
            env.mods = {k: v for k, v in env.mods.items() if k != name}
            env._emod.pop(name, None)
        tref = type_ref(info)
        cat = _category(info, tref)
        if name in _RESERVED and cat in ("param", "var"):
            raise fail(info.lex, comp, f"the name {name!r} is reserved by bgmodelica's "
                       "Component class; rename the variable")
        if cat in ("const", "string") or (connector and cat == "param"):
            # a connector's parameters are values when built, not connection variables
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
    if name.isidentifier() and not hasattr(type(inst), name):
        try:
            inst.add(name, child)
        except ModelError as err:
            raise fail(info.lex, info.comp, str(err)) from None
        return
    # an array element (R[1]) or a Modelica name that a Component method has (add): kept in
    # the children only (Modelica references find it there); no attribute hides the method
    if name in inst._children or name in inst._symbols:
        raise fail(info.lex, info.comp, f"{name!r} is declared twice")
    object.__setattr__(child, "_name", name)
    inst._children[name] = child
    if not hasattr(type(inst), name):
        object.__setattr__(inst, name, child)


def _make_class(view: ClassView, decls: dict[str, Any], connector: bool) -> type:
    body: dict[str, Any] = dict(decls)
    body["__module__"] = "bgmodelica.modelica.generated"
    body["__qualname__"] = view.scope.full_name
    body["__doc__"] = view.description or None
    if not connector:
        eqs = view.equations
        ieqs = view.initial
        template = EquationTemplate(view)        # shared by the instances of this class

        def equations(self):
            env = self.__dict__["_mo_env"]
            if env.cached is not None and env.cached[0] is not None:
                out = env.cached[0]
                env.cached = (None, env.cached[1])
            else:
                out = template.make(self)
                if out is not None:
                    return out
                out = equations_of(env, eqs)
            template.learn(self, out)
            return out

        def initial_equations(self):
            env = self.__dict__["_mo_env"]
            if env.cached is not None and env.cached[1] is not None:
                out = env.cached[1]
                env.cached = (env.cached[0], None)
                return out
            return equations_of(env, ieqs, initial=True)

        body["equations"] = equations
        body["_group_equations"] = staticmethod(template.group)
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


def _check_not_recursive(tref: TypeRef, env: Env, info: ElemInfo) -> None:
    """A component of a class that encloses it (``model M  M m; end M;``) would be infinite."""
    e: Env | None = env
    while e is not None:
        if e.view.scope is tref.scope:
            raise fail(info.lex, info.comp, f"component {info.comp.name} is recursive: its "
                       f"class {tref.scope.full_name} contains it")
        e = e.parent


def _make_child(tref: TypeRef, m: Mod | None, env: Env, path: str, info: ElemInfo) -> Element:
    if m is not None and m.has_binding:
        raise fail(m.lex or info.lex, m.pos, f"{info.comp.name}: a component cannot be bound "
                   "with '=' (records and their constructors are not supported)")
    if tref.kind == "class":
        view = class_view(tref.scope)
        if view.kind == "package":
            raise fail(info.lex, info.comp, f"{tref.name} is a package, not a type")
        _check_not_recursive(tref, env, info)
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


_EXPERIMENT = ("StartTime", "StopTime", "Interval", "Tolerance")


def _experiment_value(sub: A.ElementMod, scope: S.ClassScope) -> float | None:
    """The number of one ``experiment`` setting (None for settings of other tools); a value
    of a standard setting that is not a number is an error."""
    try:
        v = numeric_value(evaluate(sub.mod.binding, Ctx(None, scope, {}, True)))
    except NotConstant:
        v = None
    except ModelicaError:
        if sub.name in _EXPERIMENT:
            raise
        return None
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        return float(v)
    if sub.name in _EXPERIMENT:
        raise fail(scope, sub.mod.binding, f"experiment {sub.name} must be a number, got "
                   + (repr(v) if v is not None else "an expression not known before "
                      "simulation"))
    return None


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
                        v = _experiment_value(sub, scope)
                        if v is not None:
                            out[sub.name] = v
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
