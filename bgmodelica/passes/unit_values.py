"""Unit values of the dimensional analysis (:mod:`bgmodelica.passes.units`) and their
algebra: a concrete unit with the text it reads as (:class:`Known`), or a value that adapts
to what it meets (:class:`Adaptive`: a literal number, an undeclared unit).
"""

from __future__ import annotations

from fractions import Fraction
from typing import Any

from ..core.units import ONE, Unit, name_of


class Adaptive:
    """A value whose unit adapts to what it meets: a literal, or an undeclared unit."""

    __slots__ = ("name",)

    def __init__(self, name: str) -> None:
        self.name = name

    def __repr__(self) -> str:
        return self.name


LIT = Adaptive("a number")          # a literal: takes the unit its context needs
FREE = Adaptive("no unit")          # undeclared, or a product with a literal factor: adapts


class Known:
    """A concrete unit: how it reads from the declarations (``"Ohm.A"``) and its value."""

    __slots__ = ("text", "unit")

    def __init__(self, text: str, unit: Unit) -> None:
        self.text = text
        self.unit = unit

    def __str__(self) -> str:
        name = name_of(self.unit)
        return self.text if name == self.text else f"{self.text} ({name})"


DIMLESS = Known("1", ONE)


class Mismatch(Exception):
    """Units that must agree do not (the message says which)."""


def _outside_parentheses(text: str, chars: str) -> bool:
    depth = 0
    for c in text:
        depth += (c == "(") - (c == ")")
        if depth == 0 and c in chars:
            return True
    return False


def _wrap(text: str) -> str:
    return f"({text})" if _outside_parentheses(text, "/") else text


def _simple(text: str) -> bool:
    return not _outside_parentheses(text, "./")


def _mul_text(a: str, b: str) -> str:
    if a == "1":
        return b
    if b == "1":
        return a
    return f"{_wrap(a)}.{_wrap(b)}"


def _div_text(a: str, b: str) -> str:
    if b == "1":
        return a
    return f"{_wrap(a)}/{b if _simple(b) else f'({b})'}"


def _pow_text(a: str, p: Fraction) -> str:
    if p == 1:
        return a
    if a == "1":
        return a
    if _simple(a) and p.denominator == 1:
        return f"{a}{p}"
    return f"({a})^{p if p.denominator == 1 else f'({p})'}"


def der_text(a: str, n: int) -> str:
    """How the unit ``a`` reads after ``n`` time derivatives (``m/s`` -> ``m/s2``)."""
    if a == "1":
        return "1/s" if n == 1 else f"1/s{n}"
    head, sep, tail = a.rpartition("/s")
    if sep and (tail == "" or tail.isdigit()) and "(" not in head and "/" not in head:
        return f"{head}/s{int(tail or 1) + n}"
    return _div_text(a, "s" if n == 1 else f"s{n}")


def combine(a: Any, b: Any, message: str) -> Any:
    """The common unit of ``a`` and ``b`` (which must agree)."""
    if isinstance(a, Adaptive):
        return a if b is LIT else b
    if isinstance(b, Adaptive):
        return a
    if a.unit.same(b.unit):
        return a
    if _affine(a.unit, b.unit):
        return a
    raise Mismatch(message.format(a, b))


def _affine(u: Any, v: Any) -> bool:
    """Units that differ by their zero only (degC and K): an equation between them writes
    the conversion out (``T_degC = T - 273.15``), as the MSL's conversion functions do."""
    return u.dims == v.dims and u.offset != v.offset \
        and abs(u.factor - v.factor) <= 1e-9 * abs(u.factor)


def dimensionless(a: Any, what: str) -> None:
    """Raise :class:`Mismatch` unless ``a`` is a pure number (``what`` names the place)."""
    if isinstance(a, Known) and not (a.unit.dimensionless
                                  and abs(a.unit.factor - 1.0) <= 1e-12):
        raise Mismatch(f"{what} needs a dimensionless argument, got {a}")


def mul(a: Any, b: Any) -> Any:
    """The unit of ``a*b``; a literal factor may carry any unit (as in Modelica: ``3.0*time``
    can be an angle), so a product with one adapts (FREE); two literals stay a literal."""
    if a is LIT and b is LIT:
        return LIT
    if isinstance(a, Adaptive) or isinstance(b, Adaptive):
        return FREE
    return Known(_mul_text(a.text, b.text), a.unit * b.unit)


def div(a: Any, b: Any) -> Any:
    """The unit of ``a/b`` (a literal numerator or divisor adapts, as in :func:`mul`)."""
    if a is LIT and b is LIT:
        return LIT
    if isinstance(a, Adaptive) or isinstance(b, Adaptive):
        return FREE
    return Known(_div_text(a.text, b.text), a.unit / b.unit)


def power(a: Any, p: float) -> Any:
    """The unit of ``a**p`` for a literal exponent ``p``."""
    if isinstance(a, Adaptive):
        return a
    q = Fraction(p).limit_denominator(1000)
    if a.unit.dimensionless and a.unit.factor == 1.0:
        return a
    return Known(_pow_text(a.text, q), a.unit ** p)
