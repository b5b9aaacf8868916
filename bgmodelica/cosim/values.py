"""Typed reading and writing of FMU variables.

The master keeps every numeric signal as a float64 (Integer, Boolean and enumeration values
are exact in a double up to 2**53), but each variable reaches the FMU through the FMI call of
its own type: ``fmi2SetInteger``, ``fmi3SetFloat32``, ``fmi3SetUInt16``, ... FMI 3.0 array
variables appear to the master as their elements ``x[1]``, ``x[2]``... (row-major, 1-based,
``A[i,j]`` for matrices); an array is always read and written whole, the elements the master
does not set keep their last written (or start) value.

String and Binary variables are not numeric signals: they are read with :func:`get_text`
and written by name with :func:`set_by_name` (parameters, start values, and the values the
master passes along String/Binary connections, see :mod:`.text`). The master holds a String
as ``str`` and a Binary as ``bytes``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from .fmu import FmuVariable

#: FMI 3.0 types handled by the fmpy getters/setters of the same name
FMI3_NUMERIC = ("Float32", "Float64", "Int8", "UInt8", "Int16", "UInt16", "Int32", "UInt32",
                "Int64", "UInt64", "Boolean")
#: the FMI 2.0 types
FMI2_TYPES = ("Real", "Integer", "Boolean", "String")


def call_type(fmi_version: int, fmi_type: str) -> str:
    """The suffix of the fmpy get/set method for a variable of ``fmi_type``."""
    if fmi_type == "Enumeration":
        return "Integer" if fmi_version == 2 else "Int64"
    return fmi_type


def _integer_range(fmi_type: str) -> tuple[int, int] | None:
    if fmi_type.startswith("UInt"):
        return 0, 2 ** int(fmi_type[4:]) - 1
    if fmi_type.startswith("Int") and fmi_type[3:].isdigit():
        bits = int(fmi_type[3:])
        return -(2 ** (bits - 1)), 2 ** (bits - 1) - 1
    if fmi_type in ("Integer", "Enumeration"):
        return -(2 ** 31), 2 ** 31 - 1 if fmi_type == "Integer" else 2 ** 63 - 1
    return None


def to_fmi(fmi_type: str, value: Any, what: str) -> Any:
    """``value`` converted for an FMU variable of ``fmi_type`` (``what`` names it in errors)."""
    if fmi_type in ("String",):
        return str(value)
    if fmi_type == "Binary":
        if isinstance(value, str):
            return bytes.fromhex(value)
        return bytes(value)
    if fmi_type == "Boolean":
        if isinstance(value, str):
            low = value.strip().lower()
            if low in ("true", "1"):
                return True
            if low in ("false", "0"):
                return False
            raise ValueError(f"{what}: {value!r} is not a Boolean (true/false/1/0)")
        return bool(float(value) != 0.0)
    if fmi_type in ("Real", "Float64", "Float32"):
        return float(value)
    x = float(value)
    if not float(x).is_integer():
        raise ValueError(f"{what}: {value!r} is not an integer (an {fmi_type} variable)")
    bounds = _integer_range(fmi_type)
    if bounds is not None and not bounds[0] <= x <= bounds[1]:
        raise ValueError(f"{what}: {value!r} is outside the {fmi_type} range "
                         f"[{bounds[0]}, {bounds[1]}]")
    return int(value) if isinstance(value, (int, np.integer)) else int(x)


class PortAccess:
    """Typed get/set of a fixed list of (element) variables of one FMU instance, in the
    order given, as float64 arrays."""

    def __init__(self, fmi_version: int, variables: Sequence[FmuVariable]) -> None:
        self.fmi_version = fmi_version
        self.variables = list(variables)
        self.size = len(self.variables)
        self.fmu: Any = None
        # groups: method suffix -> (value references, positions in the whole-array buffer,
        # element count, positions of our variables in that buffer)
        groups: dict[str, dict[str, Any]] = {}
        self._cache: dict[int, np.ndarray] = {}   # vr -> last written whole array
        for pos, v in enumerate(self.variables):
            kind = call_type(fmi_version, v.fmi_type)
            if kind in ("String", "Binary"):
                raise ValueError(f"variable {v.name!r} is a {v.fmi_type}: only numeric and "
                                 "Boolean variables can be signals")
            g = groups.setdefault(kind, {"vrs": [], "offset": {}, "n": 0, "take": [],
                                         "put": []})
            if v.vr not in g["offset"]:
                g["offset"][v.vr] = g["n"]
                g["vrs"].append(v.vr)
                g["n"] += v.array_size
                if v.array_size > 1:
                    self._cache[v.vr] = np.asarray(v.array_start, dtype=float).copy()
            g["take"].append(g["offset"][v.vr] + v.element)
            g["put"].append(pos)
        self._groups = [(kind, g["vrs"], g["n"], np.array(g["take"], dtype=int),
                         np.array(g["put"], dtype=int), kind == "Boolean")
                        for kind, g in groups.items()]
        self._fast = (all(v.array_size == 1 for v in self.variables)
                      and len(self._groups) == 1 and self._groups[0][0] in ("Real", "Float64")
                      and self._groups[0][2] == self.size
                      and np.array_equal(self._groups[0][3], np.arange(self.size)))

    @property
    def all_real(self) -> bool:
        """Whether every variable is a scalar Real/Float64 (the fast path applies)."""
        return self._fast

    def get(self, fmu: Any, out: np.ndarray) -> np.ndarray:
        """Read the variables into ``out`` (float64) and return it."""
        for kind, vrs, n, take, put, _ in self._groups:
            values = getattr(fmu, "get" + kind)(vrs, n) if self.fmi_version == 3 else \
                getattr(fmu, "get" + kind)(vrs)
            out[put] = np.asarray(values, dtype=float)[take]
        return out

    def set(self, fmu: Any, values: np.ndarray) -> None:
        """Write ``values`` (float64, in variable order) with each variable's own type."""
        for kind, vrs, n, take, put, is_bool in self._groups:
            if n == len(vrs):                       # scalars only
                chosen = values[put]
                whole = [bool(x) for x in chosen] if is_bool else (
                    chosen.tolist() if kind in ("Real", "Float64", "Float32")
                    else [int(round(x)) for x in chosen])
            else:
                flat = []
                for vr in vrs:
                    flat.append(self._cache.get(vr, np.zeros(1)))
                buf = np.concatenate(flat)
                buf[take] = values[put]
                start = 0
                for vr in vrs:
                    if vr in self._cache:
                        k = len(self._cache[vr])
                        self._cache[vr] = buf[start:start + k].copy()
                        start += k
                    else:
                        start += 1
                whole = [bool(x) for x in buf] if is_bool else (
                    buf.tolist() if kind in ("Real", "Float64", "Float32")
                    else [int(round(x)) for x in buf])
            getattr(fmu, "set" + kind)(vrs, whole)


def set_by_name(fmu: Any, fmi_version: int, variables: Sequence[FmuVariable],
                values: Sequence[Any]) -> None:
    """Set variables of any type (String and Binary included) to the given values (already
    converted with :func:`to_fmi`); array elements are merged into their whole arrays."""
    by_kind: dict[str, dict[int, Any]] = {}
    arrays: dict[int, list[Any]] = {}
    for v, x in zip(variables, values, strict=True):
        kind = call_type(fmi_version, v.fmi_type)
        if v.array_size > 1:
            arr = arrays.setdefault(v.vr, list(v.array_start))
            arr[v.element] = x
            by_kind.setdefault(kind, {})[v.vr] = arr
        else:
            by_kind.setdefault(kind, {})[v.vr] = x
    for kind, entries in by_kind.items():
        vrs = list(entries)
        flat: list[Any] = []
        for vr in vrs:
            x = entries[vr]
            flat.extend(x if isinstance(x, list) else [x])
        if kind == "Boolean":
            flat = [bool(x) for x in flat]
        elif kind not in ("Real", "Float64", "Float32", "String", "Binary"):
            flat = [int(x) for x in flat]
        getattr(fmu, "set" + kind)(vrs, flat)


def get_text(fmu: Any, fmi_version: int, variables: Sequence[FmuVariable]) -> list[Any]:
    """The values of String (as ``str``) and Binary (as ``bytes``) variables, array elements
    included (their whole arrays are read)."""
    out: list[Any] = [None] * len(variables)
    for kind in ("String", "Binary"):
        chosen = [(k, v) for k, v in enumerate(variables) if v.type == kind]
        if not chosen:
            continue
        vrs: list[int] = []
        offset: dict[int, int] = {}
        n = 0
        for _, v in chosen:
            if v.vr not in offset:
                offset[v.vr] = n
                vrs.append(v.vr)
                n += v.array_size
        values = getattr(fmu, "get" + kind)(vrs, n) if fmi_version == 3 else \
            getattr(fmu, "get" + kind)(vrs)
        for k, v in chosen:
            x = values[offset[v.vr] + v.element]
            if kind == "String":
                x = x.decode("utf-8", "replace") if isinstance(x, bytes) else str(x or "")
            else:
                x = bytes(x or b"")
            out[k] = x
    return out
