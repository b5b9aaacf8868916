"""Modelica modifications (:class:`Mod`): parsing from the AST, merging outer over inner,
binding to an instance environment and indexing into arrays.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .. import ast as A
from .. import scope as S
from .base import SELF, Ctx, fail, numeric_value

if TYPE_CHECKING:
    from .env import Env


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
            from .env import Env
            from .evaluate import evaluate

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
    if inner.final and outer.has_binding and inner.has_binding and outer is not inner:
        raise fail(outer.lex or inner.lex, outer.pos if outer.pos != (0, 0) else inner.pos,
                   f"the value is fixed by a final modifier (line {inner.pos[0]}) and cannot "
                   "be modified")
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


def _without_redeclare(m: Mod) -> Mod | None:
    if not m.sub and not m.has_binding:
        return None
    out = Mod(m.binding, m.scope, m.lex, m.each, dict(m.sub), None, m.pos, m.const)
    out.source, out.index = m.source, m.index
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
