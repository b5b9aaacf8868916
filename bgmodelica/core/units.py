"""Unit strings in Modelica spelling, parsed and converted with pint.

Modelica writes units as ``factor('.'factor)*('/'term)*`` with integer exponents glued to the
symbol: ``"N.m"``, ``"kg.m2"``, ``"rad/s2"``, ``"1/s"``, ``"V/(rad.s)"``, ``"Ohm"``. They are
rewritten into pint syntax (``N*m``, ``kg*m**2``, ``ohm``) and pint does the rest: SI prefixes,
derived units (V, A, Ohm, F, H, N, W, J, Wb, S, Hz...), rpm, degrees, percent.

A :class:`Unit` is the value of one unit in SI base units: a ``factor``, an ``offset`` (degC)
and the exponents of the seven base dimensions. ``rad`` is dimensionless, as in pint and SI
(``rad/s`` and ``Hz`` are the same unit); :func:`angle_exponent` counts angles separately for
FMI ``<BaseUnit rad=...>``. ``""`` is *no unit declared*; ``"1"`` is dimensionless.

The pint registry is created on first use (about 0.1-0.4 s, once per process), and only
for unit strings not yet in the disk memo of earlier answers.
"""

from __future__ import annotations

import importlib.metadata
import json
import math
import os
import re
import tempfile
from dataclasses import dataclass
from fractions import Fraction
from functools import cache
from pathlib import Path
from typing import Any

#: pint's base dimensions and the SI base unit of each, in FMI's order
DIMENSIONS = ("[mass]", "[length]", "[time]", "[current]", "[temperature]", "[substance]",
              "[luminosity]")
SI_SYMBOLS = ("kg", "m", "s", "A", "K", "mol", "cd")

#: Modelica / common spellings pint does not know under that name
_SPELLINGS = {"Ohm": "ohm", "Ω": "ohm", "rev": "revolution", "%": "percent",
              "degF": "degF", "deg": "degree"}
_PREFIXES = ("da", "y", "z", "a", "f", "p", "n", "u", "µ", "m", "c", "d", "h", "k", "M", "G",
             "T", "P", "E", "Z", "Y")
_ANGLES = {"rad": 1, "deg": 1, "degree": 1, "rev": 1, "revolution": 1, "rpm": 1, "turn": 1,
           "arcmin": 1, "arcsec": 1}
_TOKEN = re.compile(r"\s*(?:(?P<sym>[A-Za-z_%Ωµ][A-Za-z_Ωµ]*)(?P<exp>[-+]?\d+)?"
                    r"|(?P<num>\d+(?:\.\d*)?)|(?P<op>[./*()]))")


class UnitParseError(ValueError):
    """A unit string that neither the Modelica grammar nor pint understands."""


@dataclass(frozen=True)
class Unit:
    """One unit: ``value_SI = factor * value + offset``; ``dims`` are the exponents of
    :data:`DIMENSIONS` (fractions after a square root)."""

    factor: float
    dims: tuple[Fraction, ...]
    offset: float = 0.0

    @property
    def dimensionless(self) -> bool:
        return not any(self.dims)

    def same(self, other: Unit) -> bool:
        """Equal dimensions and scale (numbers in one mean the same as numbers in the other)."""
        return (self.dims == other.dims and self.offset == other.offset
                and math.isclose(self.factor, other.factor, rel_tol=1e-9))

    def compatible(self, other: Unit) -> bool:
        """Same dimensions (convertible)."""
        return self.dims == other.dims

    def __mul__(self, other: Unit) -> Unit:
        return Unit(self.factor * other.factor,
                    tuple(a + b for a, b in zip(self.dims, other.dims, strict=True)))

    def __truediv__(self, other: Unit) -> Unit:
        return Unit(self.factor / other.factor,
                    tuple(a - b for a, b in zip(self.dims, other.dims, strict=True)))

    def __pow__(self, p: float) -> Unit:
        q = Fraction(p).limit_denominator(1000)
        return Unit(self.factor ** float(p), tuple(a * q for a in self.dims))

    def si_text(self) -> str:
        """The unit in SI base units, Modelica spelling (``"kg.m2.s-3.A-1"``)."""
        parts = []
        for sym, e in zip(SI_SYMBOLS, self.dims, strict=True):
            if e == 1:
                parts.append(sym)
            elif e:
                parts.append(f"{sym}{e}" if e.denominator == 1 else f"{sym}^({e})")
        text = ".".join(parts) or "1"
        if not math.isclose(self.factor, 1.0, rel_tol=1e-12):
            text = f"{self.factor:g}*{text}" if text != "1" else f"{self.factor:g}"
        return text


ONE = Unit(1.0, (Fraction(0),) * len(DIMENSIONS))
SECOND = Unit(1.0, tuple(Fraction(1 if d == "[time]" else 0) for d in DIMENSIONS))

_REGISTRY: list[Any] = []


def registry() -> Any:
    """The shared pint ``UnitRegistry`` (created on first use)."""
    if not _REGISTRY:
        import pint

        try:
            reg = pint.UnitRegistry(cache_folder=":auto:")
        except Exception:   # an unwritable or broken cache: parse the definitions again
            reg = pint.UnitRegistry()
        _REGISTRY.append(reg)
    return _REGISTRY[0]


def _pint_symbol(sym: str) -> str:
    if sym in _SPELLINGS:
        return _SPELLINGS[sym]
    for p in _PREFIXES:
        rest = sym[len(p):]
        if sym.startswith(p) and rest in ("Ohm", "Ω"):
            return ("u" if p == "µ" else p) + "ohm"
    return sym


def _tokens(unit: str) -> list[tuple[str, str, int]]:
    out = []
    pos, text = 0, unit.strip()
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if m is None or m.end() == pos:
            raise UnitParseError(f"cannot read unit {unit!r} at {text[pos:]!r}")
        pos = m.end()
        if m.group("sym"):
            out.append(("sym", m.group("sym"), int(m.group("exp") or 1)))
        elif m.group("num"):
            out.append(("num", m.group("num"), 1))
        else:
            out.append(("op", m.group("op"), 0))
    return out


def exponents(unit: str) -> tuple[float, dict[str, int]]:
    """A Modelica unit string as ``(number, {symbol: exponent})``: ``"N.m.s/rad"`` ->
    ``(1, {"N": 1, "m": 1, "s": 1, "rad": -1})``. ``a/b.c`` is ``a/(b.c)`` (the denominator is
    the whole product), parentheses group, ``"1"`` is the number 1."""
    toks = _tokens(unit)
    pos = 0

    def peek() -> tuple[str, str, int] | None:
        return toks[pos] if pos < len(toks) else None

    def factor(num: list[float], out: dict[str, int], sign: int) -> None:
        nonlocal pos
        tok = peek()
        if tok is None:
            raise UnitParseError(f"unit {unit!r} ends too early")
        pos += 1
        if tok[0] == "sym":
            out[tok[1]] = out.get(tok[1], 0) + sign * tok[2]
        elif tok[0] == "num":
            num[0] *= float(tok[1]) ** sign
        elif tok[1] == "(":
            expr(num, out, sign)
            close = peek()
            if close is None or close[1] != ")":
                raise UnitParseError(f"unit {unit!r}: missing ')'")
            pos += 1
        else:
            raise UnitParseError(f"unit {unit!r}: unexpected {tok[1]!r}")

    def product(num: list[float], out: dict[str, int], sign: int) -> None:
        nonlocal pos
        factor(num, out, sign)
        while (tok := peek()) is not None and tok[1] in (".", "*"):
            pos += 1
            factor(num, out, sign)

    def expr(num: list[float], out: dict[str, int], sign: int) -> None:
        nonlocal pos
        product(num, out, sign)
        while (tok := peek()) is not None and tok[1] == "/":
            pos += 1
            product(num, out, -sign)

    num, out = [1.0], {}
    expr(num, out, 1)
    if pos != len(toks):
        raise UnitParseError(f"unit {unit!r}: unexpected {toks[pos][1]!r}")
    return num[0], {k: v for k, v in out.items() if v}


def to_pint(unit: str) -> str:
    """Rewrite a Modelica unit string into pint syntax (``"kg.m2/s"`` -> ``"kg*m**2*s**-1"``)."""
    number, exps = exponents(unit)
    parts = [] if number == 1.0 else [repr(number)]
    parts += [_pint_symbol(k) if e == 1 else f"{_pint_symbol(k)}**{e}" for k, e in exps.items()]
    return "*".join(parts) or "dimensionless"


@cache
def parse(unit: str) -> Unit:
    """The :class:`Unit` of a Modelica unit string (``"1"`` and ``""`` are dimensionless);
    :class:`UnitParseError` if pint does not know it.

    pint's answers are remembered on disk (see :func:`_memo_path`), so a process whose units
    were all seen before does not import pint at all."""
    if unit in ("", "1"):
        return ONE
    known = _disk_memo().get(unit)
    if known is not None:
        try:
            factor, offset, dims = known
            return Unit(float(factor), tuple(Fraction(d) for d in dims), float(offset))
        except (TypeError, ValueError):
            pass
    out = _parse_pint(unit)
    _remember(unit, out)
    return out


def _parse_pint(unit: str) -> Unit:
    reg = registry()
    try:
        units = reg.parse_units(to_pint(unit))
        zero = float(reg.Quantity(0.0, units).to_base_units().magnitude)
        one = float(reg.Quantity(1.0, units).to_base_units().magnitude)
        dim = reg.get_dimensionality(units)
    except UnitParseError:
        raise
    except Exception as err:
        raise UnitParseError(f"unknown unit {unit!r}: {err}") from None
    for key in dim:
        if key not in DIMENSIONS:
            raise UnitParseError(f"unit {unit!r} has a dimension {key} outside SI")
    dims = tuple(Fraction(dim.get(d, 0)).limit_denominator(1000) for d in DIMENSIONS)
    factor = one - zero
    if math.isclose(factor, round(factor), rel_tol=1e-12) and round(factor) != 0:
        factor = float(round(factor))
    return Unit(factor, dims, zero)


# -- a small disk memo of pint's answers --------------------------------------------------------

_MEMO_FORMAT = 1
_DISK: list[dict[str, Any]] = []


def _memo_path() -> Path | None:
    """``$BGMODELICA_CACHE`` (or ``$XDG_CACHE_HOME/bgmodelica``, ``~/.cache/bgmodelica``)
    ``/units-<format>-pint<version>.json``; None when pint is not installed."""
    try:
        version = importlib.metadata.version("pint")
    except importlib.metadata.PackageNotFoundError:
        return None
    base = os.environ.get("BGMODELICA_CACHE")
    if not base:
        xdg = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"),
                                                               ".cache")
        base = os.path.join(xdg, "bgmodelica")
    return Path(base) / f"units-{_MEMO_FORMAT}-pint{version}.json"


def _disk_memo() -> dict[str, Any]:
    if not _DISK:
        memo: dict[str, Any] = {}
        path = _memo_path()
        if path is not None:
            try:
                loaded = json.loads(path.read_text())
                if isinstance(loaded, dict):
                    memo = loaded
            except (OSError, ValueError):
                pass
        _DISK.append(memo)
    return _DISK[0]


def _remember(unit: str, u: Unit) -> None:
    """Add ``unit`` to the disk memo (written atomically; any failure is ignored)."""
    memo = _disk_memo()
    memo[unit] = [u.factor, u.offset, [str(d) for d in u.dims]]
    path = _memo_path()
    if path is None:
        return
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".tmp")
        with os.fdopen(fd, "w") as f:
            json.dump(memo, f)
        os.replace(tmp, path)
    except OSError:
        pass


def angle_exponent(unit: str) -> int:
    """Exponent of the angle (rad, deg, rev, rpm...) in a Modelica unit string, for FMI
    ``<BaseUnit rad=...>`` (pint, like SI, makes angles dimensionless); 0 if unreadable."""
    try:
        _, exps = exponents(unit)
    except UnitParseError:
        return 0
    total = 0
    for sym, e in exps.items():
        base = sym
        if sym not in _ANGLES:
            base = next((sym[len(p):] for p in _PREFIXES
                         if sym.startswith(p) and sym[len(p):] == "rad"), sym)
        if base in _ANGLES:
            total += e
    return total


#: derived units to name a product in messages ("Ohm.A (V)"), in order of preference
_NAMED = ("V", "A", "Ohm", "S", "F", "H", "Wb", "T", "W", "J", "N", "Pa", "C", "1/s", "kg",
          "m", "s", "K", "mol", "cd", "m/s", "m/s2", "1/s2", "kg.m2", "N.s/m", "N/m")


@cache
def _named() -> dict[tuple[Fraction, ...], str]:
    out: dict[tuple[Fraction, ...], str] = {}
    for name in _NAMED:
        out.setdefault(parse(name).dims, name)
    return out


def name_of(u: Unit) -> str:
    """A short name for ``u``: a derived SI unit when one matches, else SI base units."""
    if u.dimensionless and math.isclose(u.factor, 1.0, rel_tol=1e-12):
        return "1"
    named = _named().get(u.dims) if u.offset == 0.0 else None
    if named is None:
        return u.si_text()
    if math.isclose(u.factor, 1.0, rel_tol=1e-12):
        return named
    return f"{u.factor:g}*{named}"


def describe(unit: str) -> str:
    """``unit`` followed by its short name when that differs: ``"H.A (Wb)"``."""
    try:
        name = name_of(parse(unit))
    except UnitParseError:
        return repr(unit)
    return unit if name == unit else f"{unit} ({name})"


_QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*?)\s*$")


def split_quantity(text: str) -> tuple[float, str] | None:
    """``"2 kOhm"`` -> ``(2.0, "kOhm")``; None when ``text`` does not start with a number."""
    m = _QUANTITY.match(text)
    if m is None:
        return None
    return float(m.group(1)), m.group(2)


def convert(value: float, from_unit: str, to_unit: str) -> float:
    """``value`` in ``from_unit`` expressed in ``to_unit``; ``ValueError`` if the dimensions
    differ (the message names both units)."""
    a, b = parse(from_unit), parse(to_unit)
    if not a.compatible(b):
        raise ValueError(f"{describe(from_unit)} cannot be converted to {describe(to_unit)}")
    return ((value * a.factor + a.offset) - b.offset) / b.factor


def quantity_value(name: str, value: Any, unit: str | None) -> Any:
    """``value`` for a parameter / variable ``name`` declared in ``unit``: a string with a
    unit (``"2 kOhm"``) is converted to ``unit``; anything else is returned as it is.
    ``ValueError`` (naming ``name`` and both units) if it cannot be converted."""
    if not isinstance(value, str):
        return value
    try:
        return float(value)
    except ValueError:
        pass
    q = split_quantity(value)
    if q is None or not q[1]:
        return value
    number, given = q
    if unit is None:
        raise ValueError(f"{name}: {value!r} has a unit, but {name} is not a parameter, "
                         "input or variable with a declared unit")
    if unit == "":
        raise ValueError(f"{name}: {value!r} has a unit, but {name} declares none; give a "
                         "plain number")
    try:
        return convert(number, given, unit)
    except UnitParseError as err:
        raise ValueError(f"{name}: {err}") from None
    except ValueError:
        raise ValueError(f"{name} is declared in {describe(unit)}; {value!r} is in "
                         f"{describe(given)}, which cannot be converted to it") from None


def declared_units(compiled: Any) -> dict[str, str]:
    """Dotted name -> declared unit of every variable, parameter, input and discrete of a
    compiled model (aliases included)."""
    flat = compiled.declarations
    out = {v.name: v.decl.unit for group in (flat.variables, flat.parameters, flat.inputs,
                                             flat.discretes) for v in group}
    for alias, (kept, _) in flat.aliases.items():
        out.setdefault(alias, out.get(kept, ""))
    return out


def with_units(params: dict[str, Any], compiled: Any) -> dict[str, Any]:
    """``params`` with every value given with a unit (``"2 kOhm"``) converted to the declared
    unit of what it names; :class:`~bgmodelica.errors.UnitError` names the parameter and both
    units when that is impossible. Names that are not in the model are left to the caller."""
    if not any(isinstance(v, str) for v in params.values()):
        return params
    from ..errors import UnitError

    units = declared_units(compiled)
    out = {}
    for name, value in params.items():
        if isinstance(value, str) and name in units:
            try:
                value = quantity_value(name, value, units[name])
            except ValueError as err:
                raise UnitError(str(err)) from None
        out[name] = value
    return out
