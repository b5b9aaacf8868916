"""Subcomponents and connectors a component class declares, built for each instance.

A class attribute ``p = Pin()`` is a template: every instance gets its own copy, built with
the template's constructor arguments (``template.clone()``). The connectors of a component,
built by the thousand in a large model, are made directly when their class needs nothing of
the general constructor (:func:`_fresh_connector`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .variables import Symbol

if TYPE_CHECKING:
    from .component import Element


def build_child(key: str, template: Element) -> Element:
    """``template.clone()``; an exception of user code names the subcomponent path."""
    if _plain_connector(type(template)) and template._init_call == _NO_CALL:
        return _fresh_connector(type(template))
    try:
        return template.clone()
    except Exception as err:  # noqa: BLE001 -- user code: say where, no traceback
        from ..errors import ModelError, UserCodeError
        from ..validate import nested_user_error, user_error

        if isinstance(err, UserCodeError):
            raise nested_user_error(err, key, type(template).__name__) from err.__cause__
        if isinstance(err, ModelError):
            raise
        raise nested_user_error(user_error(err, f"{type(template).__name__}()"), key,
                                type(template).__name__) from err


_NO_CALL: tuple[tuple, dict] = ((), {})
_PLAIN_CONNECTORS: dict[type, bool] = {}


def _plain_connector(cls: type) -> bool:
    """Whether ``cls()`` is a connector built by :class:`Element`'s constructor alone, of
    scalar declarations and no subconnectors (then :func:`_fresh_connector` makes it);
    worked out once per class."""
    found = _PLAIN_CONNECTORS.get(cls)
    if found is None:
        from .component import Connector, Element

        found = _PLAIN_CONNECTORS[cls] = (
            issubclass(cls, Connector) and cls.__init__ is Element.__init__
            and cls.__new__ is Element.__new__ and not cls._templates
            and all(d.shape == () for d in cls._declarations.values()))
    return found


def _fresh_connector(cls: type) -> Element:
    """``cls()`` for a plain connector class (:func:`_plain_connector`), without the
    constructor's general machinery: a component's connectors are built by the thousand."""
    self = object.__new__(cls)
    attrs = self.__dict__
    attrs["_init_call"] = _NO_CALL
    attrs["_name"] = None
    symbols: dict[str, Symbol] = {}
    attrs["_symbols"] = symbols
    attrs["_children"] = {}
    attrs["_equations"] = []
    for key, decl in cls._declarations.items():
        sym = Symbol(key, decl, self)
        symbols[key] = sym
        attrs[key] = sym.leaf
    return self
