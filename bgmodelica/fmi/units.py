"""Modelica unit strings -> FMI ``<BaseUnit>`` exponents.

A unit string is parsed with the Modelica unit grammar subset ``"1"``, ``factor('.'factor)*``
optionally followed by ``'/' term`` (``"N.m"``, ``"kg.m2"``, ``"rad/s2"``, ``"1/s"``,
``"m/s"``), where a factor is a known symbol with an optional SI prefix and integer exponent.
Anything else (parentheses as in ``"V/(rad.s)"``, ``"rpm"``, other units pint knows) is
parsed with pint (:mod:`bgmodelica.core.units`). Unknown unit strings are still declared
(without ``<BaseUnit>``) so the modelDescription stays valid.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

BASE = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")

# symbol -> (exponents over BASE, factor, offset)
_SYMBOLS: dict[str, tuple[dict[str, int], float, float]] = {
    "kg": ({"kg": 1}, 1.0, 0.0),
    "g": ({"kg": 1}, 1e-3, 0.0),
    "m": ({"m": 1}, 1.0, 0.0),
    "s": ({"s": 1}, 1.0, 0.0),
    "min": ({"s": 1}, 60.0, 0.0),
    "h": ({"s": 1}, 3600.0, 0.0),
    "A": ({"A": 1}, 1.0, 0.0),
    "K": ({"K": 1}, 1.0, 0.0),
    "degC": ({"K": 1}, 1.0, 273.15),
    "mol": ({"mol": 1}, 1.0, 0.0),
    "cd": ({"cd": 1}, 1.0, 0.0),
    "rad": ({"rad": 1}, 1.0, 0.0),
    "deg": ({"rad": 1}, math.pi / 180.0, 0.0),
    "rev": ({"rad": 1}, 2.0 * math.pi, 0.0),
    "Hz": ({"s": -1}, 1.0, 0.0),
    "N": ({"kg": 1, "m": 1, "s": -2}, 1.0, 0.0),
    "J": ({"kg": 1, "m": 2, "s": -2}, 1.0, 0.0),
    "W": ({"kg": 1, "m": 2, "s": -3}, 1.0, 0.0),
    "Pa": ({"kg": 1, "m": -1, "s": -2}, 1.0, 0.0),
    "bar": ({"kg": 1, "m": -1, "s": -2}, 1e5, 0.0),
    "C": ({"A": 1, "s": 1}, 1.0, 0.0),
    "V": ({"kg": 1, "m": 2, "s": -3, "A": -1}, 1.0, 0.0),
    "Ohm": ({"kg": 1, "m": 2, "s": -3, "A": -2}, 1.0, 0.0),
    "S": ({"kg": -1, "m": -2, "s": 3, "A": 2}, 1.0, 0.0),
    "F": ({"kg": -1, "m": -2, "s": 4, "A": 2}, 1.0, 0.0),
    "H": ({"kg": 1, "m": 2, "s": -2, "A": -2}, 1.0, 0.0),
    "Wb": ({"kg": 1, "m": 2, "s": -2, "A": -1}, 1.0, 0.0),
    "T": ({"kg": 1, "s": -2, "A": -1}, 1.0, 0.0),
    "l": ({"m": 3}, 1e-3, 0.0),
}
_PREFIXES = {"p": 1e-12, "n": 1e-9, "u": 1e-6, "m": 1e-3, "c": 1e-2, "d": 1e-1, "k": 1e3,
             "M": 1e6, "G": 1e9}
_FACTOR = re.compile(r"^([A-Za-z]+)(-?\d+)?$")


@dataclass
class UnitDefinition:
    """A ``<Unit>``: ``exponents`` is None for an unknown unit string."""

    name: str
    exponents: dict[str, int] | None = field(default=None)
    factor: float = 1.0
    offset: float = 0.0


def _symbol(sym: str) -> tuple[dict[str, int], float, float] | None:
    if sym in _SYMBOLS:
        return _SYMBOLS[sym]
    if len(sym) > 1 and sym[0] in _PREFIXES and sym[1:] in _SYMBOLS:
        exps, factor, offset = _SYMBOLS[sym[1:]]
        if offset:
            return None
        return exps, factor * _PREFIXES[sym[0]], 0.0
    return None


def _term(term: str) -> tuple[dict[str, int], float, float, int] | None:
    """Parse ``factor('.'factor)*``; returns exponents, factor, offset, number of factors."""
    if term == "1":
        return {}, 1.0, 0.0, 0
    exps: dict[str, int] = {}
    factor, offset, count = 1.0, 0.0, 0
    for part in term.split("."):
        m = _FACTOR.match(part)
        if not m:
            return None
        sym = _symbol(m.group(1))
        if sym is None:
            return None
        power = int(m.group(2)) if m.group(2) else 1
        e, f, o = sym
        for k, v in e.items():
            exps[k] = exps.get(k, 0) + v * power
        factor *= f ** power
        offset = o if power == 1 else (math.nan if o else 0.0)
        count += 1
    return exps, factor, offset, count


def parse_unit(unit: str) -> UnitDefinition:
    """Return the :class:`UnitDefinition` of ``unit`` (``exponents=None`` if unknown)."""
    out = _parse_simple(unit)
    return out if out.exponents is not None or not unit else _parse_pint(unit)


def _parse_pint(unit: str) -> UnitDefinition:
    """Exponents over :data:`BASE` through pint, the angle counted from the symbols."""
    from ..core.units import SI_SYMBOLS, UnitParseError, angle_exponent, parse

    try:
        u = parse(unit)
    except UnitParseError:
        return UnitDefinition(unit)
    if any(d.denominator != 1 for d in u.dims):
        return UnitDefinition(unit)
    exps = {k: int(d) for k, d in zip(SI_SYMBOLS, u.dims, strict=True) if d}
    rad = angle_exponent(unit)
    if rad:
        exps["rad"] = rad
    # pint folds angles into the factor (deg = pi/180): keep it, as for "deg" above
    return UnitDefinition(unit, exps, u.factor, u.offset)


def _parse_simple(unit: str) -> UnitDefinition:
    parts = unit.split("/")
    if not unit or any(not p for p in parts):
        return UnitDefinition(unit)
    first = _term(parts[0])
    if first is None:
        return UnitDefinition(unit)
    exps, factor, offset, count = first
    for den in parts[1:]:
        parsed = _term(den)
        if parsed is None or parsed[3] == 0:
            return UnitDefinition(unit)
        e, f, o, n = parsed
        if o:
            return UnitDefinition(unit)
        for k, v in e.items():
            exps[k] = exps.get(k, 0) - v
        factor /= f
        count += n
    if offset and (count != 1 or math.isnan(offset)):
        return UnitDefinition(unit)
    return UnitDefinition(unit, {k: v for k, v in exps.items() if v}, factor, offset)


def derivative_unit(unit: str) -> str:
    """Unit of the time derivative of a quantity in ``unit`` (``""`` stays ``""``)."""
    if not unit:
        return ""
    if unit == "1":
        return "1/s"
    m = re.match(r"^([^/]*)/s(\d*)$", unit)
    if m:
        return f"{m.group(1)}/s{int(m.group(2) or '1') + 1}"
    return f"{unit}/s"


def unit_definitions(units: list[str]) -> list[UnitDefinition]:
    """Unique, sorted definitions of the non-empty unit strings in ``units``."""
    return [parse_unit(u) for u in sorted({u for u in units if u})]
