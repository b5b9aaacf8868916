"""The switch of hybrid bond graphs, :class:`Sw` (Mosterman & Biswas): ``e = 0`` when on,
``f = 0`` when off, written in the resistive form ``e = s*(Ron if on else 1)``,
``f = s*(1 if on else Goff)`` so that the causality stays the same in every mode; the mode
is a Boolean expression (a time or state event, a ``when``-assigned variable, a constant)
or a Boolean input."""

from __future__ import annotations

from typing import Any

from ..core import expressions as _expressions
from ..core.expr import Expr as _Expr
from ..core.expr import to_text as _to_text
from ..core.hybrid import is_boolean as _is_boolean
from ..core.variables import (
    Boolean,
    Input,
    Parameter,
    Variable,
)
from .base import (
    BGElement,
    PowerPort,
    bond_flow,
    declare,
    element_path,
    resolve,
)
from .errors import ModulusError

__all__ = ["Sw"]


class Sw(BGElement):
    """Switch of a hybrid bond graph (Mosterman & Biswas 1998): a one-port that imposes zero
    effort when ``on`` (an ideal closed switch, ``e = 0``) and zero flow when off (an open
    switch, ``f = 0``).

    Ideal, the two modes have opposite causalities (on: an Se of value 0, off: an Sf of value
    0), so a mode change would change the causality of the graph and possibly the number of
    states. Like the ideal switch of the Modelica Standard Library, this element is written in
    a resistive form with an unknown curve parameter ``s``::

        e = s * (Ron if on else 1)        f = s * (1 if on else Goff)

    (``s`` is the flow when on and the effort when off): an on switch is a resistance ``Ron``,
    an off switch a conductance ``Goff``, both small (default 1e-5). The structure of the
    equations does not depend on the mode, the causality of the bond is assigned once (free,
    as for an R) and kept in every mode, and a mode change is an event that only changes
    coefficients. The price: on, the bond carries ``e = Ron f`` instead of 0; off,
    ``f = Goff e`` instead of 0; a storage element that the ideal mode would put in derivative
    causality (e.g. an I in series with an opening switch) gets a fast time constant
    (``I Goff``; ``C Ron`` for a C shorted by a closing switch) instead.

    The mode, a Boolean variable ``on``, is given at construction by exactly one of

    * ``on=``: a Boolean expression: a relation (``time >= t_s``: a time event; ``x > 0`` on
      continuous quantities: a zero-crossing event), a Boolean variable (e.g. one assigned
      in a ``when``), a logical combination (``&``, ``|``, ``~``), a callable receiving the
      enclosing bond graph (``lambda m: m.drive``), a string evaluated in its namespace
      (``"time >= t_s"``), or a constant ``True`` / ``False``;
    * ``signal=True``: a (Real) Input ``u`` (connect a block output to it, or leave it a model
      input); the switch is on while ``u > threshold`` (default 0.5; a zero-crossing event).

    Parameters: ``Ron`` [effort/flow] (on resistance), ``Goff`` [flow/effort] (off
    conductance). Variables: ``on`` (Boolean), ``s``. The bond's half-arrow points into the
    switch by default (power dissipated by it is ``e f >= 0``).
    """

    kind = "Sw"
    Ron = Parameter(1e-5, min=0.0, description="On resistance (effort per flow when on)")
    Goff = Parameter(1e-5, min=0.0, description="Off conductance (flow per effort when off)")
    s = Variable(description="Switch curve parameter: flow when on, effort when off")
    on = Boolean(start=False, description="Mode: True = on (closed, e = 0), False = off "
                 "(open, f = 0)")
    port = PowerPort()

    def __init__(self, name: str | None = None, *, on: Any = None, signal: bool = False,
                 threshold: float = 0.5, **kw: Any) -> None:
        if (on is None) == (not signal):
            raise ModulusError(f"Sw {name or ''}: give the mode either as on= (a Boolean "
                               "expression, callable, string or True/False) or as "
                               "signal=True (an input u, on while u > threshold)", name)
        object.__setattr__(self, "_mode", on)
        object.__setattr__(self, "_signal", signal)
        object.__setattr__(self, "_threshold", float(threshold))
        super().__init__(name, **kw)
        if signal:
            declare(self, "u", Input(description=f"Control signal: on while u > {threshold:g}"))

    def mode(self) -> Any:
        """The Boolean expression that defines ``on``."""
        if self._signal:
            return self.u > self._threshold
        m = self._mode
        if isinstance(m, bool):
            return float(m)
        if callable(m) and not isinstance(m, _Expr):
            owner = getattr(self, "_bg_owner", None)
            try:
                value = m(owner if owner is not None else self)
            except (AttributeError, NameError, KeyError) as err:
                raise ModulusError(f"Sw {element_path(self)}: the mode function refers to an "
                                   f"unknown variable ({err})", element_path(self)) from None
            if isinstance(value, bool):
                return float(value)
            m = value
        value = resolve(m, self, "mode")
        if not _is_boolean(value):
            raise ModulusError(f"Sw {element_path(self)}: the mode {_mode_repr(self._mode)} "
                               "is not a Boolean expression (use a relation such as time >= "
                               "t_s, a Boolean variable, a logical combination of these or "
                               "True/False)", element_path(self))
        return value

    def mode_text(self) -> str:
        if self._signal:
            return f"{element_path(self)}.u > {self._threshold:g}"
        m = self._mode
        if isinstance(m, bool):
            return "always on" if m else "always off"
        if isinstance(m, str):
            return m
        try:
            value = self.mode()
        except ModulusError:
            return _mode_repr(m)
        text = _to_text(value, _dotted(_paths(self)))
        if text.startswith("(") and text.endswith(")"):
            text = text[1:-1]
        return text

    def equations(self):
        e, f = self.port.e, bond_flow(self.port)
        yield self.on == self.mode()
        yield e == self.s * _expressions.if_else(self.on, self.Ron, 1.0)
        yield f == self.s * _expressions.if_else(self.on, 1.0, self.Goff)


def _mode_repr(m: Any) -> str:
    return m if isinstance(m, str) else repr(m)


def _paths(elem: Any) -> dict[int, str]:
    """id(component or connector) -> its dotted path from the outermost bond graph that owns
    ``elem`` (the root itself: "")."""
    root = elem
    while getattr(root, "_bg_owner", None) is not None:
        root = root._bg_owner
    out: dict[int, str] = {}
    stack: list[tuple[Any, str]] = [(root, "")]
    while stack:
        obj, path = stack.pop()
        if id(obj) in out:
            continue
        out[id(obj)] = path
        for name, child in getattr(obj, "_children", {}).items():
            stack.append((child, f"{path}.{name}" if path else name))
    return out


def _dotted(paths: dict[int, str]) -> Any:
    """Names of symbols by their dotted path in the bond graph (``pwm.on`` rather than
    ``on``), for :func:`~bgmodelica.core.expr.to_text`."""
    def name(sym: Any) -> str:
        owner = getattr(sym, "owner", None)
        path = paths.get(id(owner)) if owner is not None else None
        local = getattr(sym, "name", "time")
        return f"{path}.{local}" if path else local
    return name
