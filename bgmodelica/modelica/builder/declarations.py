"""Declarations: Modelica component declarations and their modifiers turned into bgmodelica
variables and parameters.
"""

from __future__ import annotations

import re
from typing import Any

from ...core.component import Element
from ...core.units import UnitParseError
from ...core.units import parse as parse_unit
from ...core.variables import (
    KIND_PARAMETER,
    Boolean,
    BooleanInput,
    BooleanOutput,
    Discrete,
    Flow,
    Input,
    Integer,
    IntegerInput,
    IntegerOutput,
    Output,
    Parameter,
    Potential,
    StateSelect,
    Variable,
)
from .. import ast as A
from .. import scope as S
from ..errors import ModelicaError
from .base import NotConstant, _is_number, fail
from .classes import ElemInfo, TypeRef
from .env import Env, _default_value
from .mods import Mod, index_mod, merge

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


#: unit names of the Modelica Standard Library outside the SI that the unit registry does
#: not define (reactive power, Rankine, loudness): accepted, as a tool may
_NON_SI = re.compile(r"^[A-Za-z]*(var|degRk|phon|sone)$")


def _check_unit(unit: str, lex: Any, comp: A.Component) -> None:
    """A unit string that is not a unit is an error (specification 19.1), named at the
    declaration."""
    try:
        parse_unit(unit)
    except UnitParseError as err:
        if all(_NON_SI.match(w) for w in re.findall(r"[A-Za-z]+", unit)):
            return
        raise fail(lex, comp, f"{comp.name}: {err}") from None


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
    elif unit:
        _check_unit(unit, lex, comp)
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
        if "fixed" in attrs and not attrs["fixed"]:
            kw["fixed"] = False
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
    if "input" in pre or "output" in pre:
        if tref.base in ("Boolean", "Integer", "enum"):
            kw.pop("unit")
            kw.pop("nominal", None)
            kw.pop("state_select", None)
            boolean = tref.base == "Boolean"
            if "input" in pre:
                return BooleanInput(**kw) if boolean else IntegerInput(**kw)
            return BooleanOutput(**kw) if boolean else IntegerOutput(**kw)
        return Input(**kw) if "input" in pre else Output(**kw)
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
            what = {"str": "the String", "list": "the array"}.get(type(value).__name__,
                                                                   "the component")
            raise fail(m.lex or info.lex, m.pos, f"parameter {comp.name} is a number and "
                       f"cannot be given {what} {value!r}")
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
    return decl.evolve(**changes) if changes else decl


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
                sym.decl = decl.evolve(**changes)
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
