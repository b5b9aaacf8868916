"""Re-implementation of the ModelicaStrings_* functions of ModelicaExternalC.

Indices are 1-based as in Modelica. Scanning functions skip white space first; on success
they return the index after the token, on failure ``startIndex`` and an empty value. Output
arguments of the external call (``nextIndex``, ``number``...) may be passed as placeholders
(ignored) or omitted; the outputs come back as a tuple in their order in the call.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any

#: Modelica.Utilities.Types.Compare
LESS, EQUAL, GREATER = 1, 2, 3
_WHITE = " \t\n\v\f\r"
_REAL = re.compile(r"[+-]?\d+(\.\d*)?([eE][+-]?\d+)?")
_UREAL = re.compile(r"\d+(\.\d*)?([eE][+-]?\d+)?")
_INT = re.compile(r"[+-]?\d+")
_UINT = re.compile(r"\d+")
_IDENT = re.compile(r"[A-Za-z][A-Za-z0-9_]*")


def length(string: str) -> int:
    """``ModelicaStrings_length``: number of characters."""
    return len(string)


def substring(string: str, start: int, end: int) -> str:
    """``ModelicaStrings_substring``: characters ``start..end`` (inclusive, clipped as the
    MSL documents: start < 1 -> 1; end < 0 -> start; end < start -> ''; end > length ->
    length)."""
    start, end = max(int(start), 1), int(end)
    if end < 0:
        end = start
    if start > len(string) or end < start:
        return ""
    return string[start - 1:min(end, len(string))]


def compare(string1: str, string2: str, case_sensitive: bool = True) -> int:
    """``ModelicaStrings_compare``: Less=1, Equal=2, Greater=3 (character codes)."""
    a, b = (string1, string2) if case_sensitive else (string1.lower(), string2.lower())
    return LESS if a < b else EQUAL if a == b else GREATER


def skip_white_space(string: str, start: int = 1) -> int:
    """``ModelicaStrings_skipWhiteSpace``: index of the first non-blank character at or after
    ``start`` (length + 1 if none)."""
    i = max(int(start), 1)
    while i <= len(string) and string[i - 1] in _WHITE:
        i += 1
    return i


def _scan(pattern: re.Pattern, string: str, start: int, follow_ok: str = "") -> tuple:
    i = skip_white_space(string, start)
    m = pattern.match(string, i - 1)
    if m is None:
        return None
    nxt = m.end()
    if nxt < len(string) and string[nxt] in follow_ok:
        return None
    return nxt + 1, m.group(0)


def scan_real(string: str, start: int = 1, unsigned: bool = False, next_index: Any = 0,
              number: Any = 0.0) -> tuple[int, float]:
    """``ModelicaStrings_scanReal``: (nextIndex, number)."""
    found = _scan(_UREAL if unsigned else _REAL, string, start)
    return (found[0], float(found[1])) if found else (int(start), 0.0)


def scan_integer(string: str, start: int = 1, unsigned: bool = False, next_index: Any = 0,
                 number: Any = 0) -> tuple[int, int]:
    """``ModelicaStrings_scanInteger``: (nextIndex, number); a Real such as ``1.5`` or
    ``1e3`` is not an Integer."""
    found = _scan(_UINT if unsigned else _INT, string, start, follow_ok=".eE")
    return (found[0], int(found[1])) if found else (int(start), 0)


def scan_string(string: str, start: int = 1, next_index: Any = 0,
                string2: Any = "") -> tuple[int, str]:
    """``ModelicaStrings_scanString``: (nextIndex, contents of a double-quoted string)."""
    i = skip_white_space(string, start)
    if i > len(string) or string[i - 1] != '"':
        return int(start), ""
    out, j = [], i
    while j < len(string):
        ch = string[j]
        if ch == "\\" and j + 1 < len(string):
            out.append({"n": "\n", "t": "\t"}.get(string[j + 1], string[j + 1]))
            j += 2
            continue
        if ch == '"':
            return j + 2, "".join(out)
        out.append(ch)
        j += 1
    return int(start), ""


def scan_identifier(string: str, start: int = 1, next_index: Any = 0,
                    identifier: Any = "") -> tuple[int, str]:
    """``ModelicaStrings_scanIdentifier``: (nextIndex, identifier)."""
    found = _scan(_IDENT, string, start)
    return (found[0], found[1]) if found else (int(start), "")


REGISTRY: dict[str, Callable[..., Any]] = {
    "ModelicaStrings_length": length,
    "ModelicaStrings_substring": substring,
    "ModelicaStrings_compare": compare,
    "ModelicaStrings_skipWhiteSpace": skip_white_space,
    "ModelicaStrings_scanReal": scan_real,
    "ModelicaStrings_scanInteger": scan_integer,
    "ModelicaStrings_scanString": scan_string,
    "ModelicaStrings_scanIdentifier": scan_identifier,
}
