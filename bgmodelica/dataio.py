"""Results in the Python data ecosystem: pandas, xarray and CSV, with units, both ways.

Used through :class:`~bgmodelica.result.Result`: ``result.to_pandas()``,
``result.to_xarray()``, ``result.to_csv(path, units=True)`` and
``Result.from_pandas(df)``, ``Result.from_xarray(ds)``, ``Result.read_csv(path)``.

**Events.** A run with events holds two rows at each event instant, the left limit then the
right limit, with the *same* time. Both rows are kept: the time index of the DataFrame (and
the ``time`` coordinate of the Dataset) is then *not unique* -- select by position
(``df.iloc``) or with a boolean mask (``df[df.index >= 1.0]``); ``df.loc[t]`` returns both
rows at an event instant. ``attrs["event_times"]`` lists the instants.

**Units** of every column are in ``df.attrs["units"]`` (name -> unit string, ``"time"`` ->
``"s"``) and in each data variable's ``attrs["units"]`` of the Dataset (the CF convention);
parameters go to ``df.attrs["parameters"]`` and to 0-d data variables of the Dataset
(``attrs["kind"] = "parameter"``).
"""

from __future__ import annotations

import csv
import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from .result import Result

#: first cell of the optional units row of a CSV file
UNITS_ROW = "s"


def unit_of(result: Result, name: str) -> str:
    """The unit of ``name`` in ``result`` ("" if unknown): declared, through an alias, or
    ``s`` for time."""
    if name in ("time", "t"):
        return "s"
    if name in result.units:
        return result.units[name] or ""
    if name in result.aliases:
        return unit_of(result, result.aliases[name][0])
    return ""


def _names(result: Result, names: Sequence[str] | None) -> list[str]:
    return list(names) if names is not None else result.all_names()


def text_cell(value: Any) -> str:
    """A String value as it is, a Binary one (bytes) in hex, as CSV files hold them."""
    if isinstance(value, (bytes, bytearray)):
        return bytes(value).hex()
    return "" if value is None else str(value)


def _meta_attrs(result: Result) -> dict[str, Any]:
    attrs: dict[str, Any] = {}
    events = result.meta.get("event_times")
    if events is not None:
        attrs["event_times"] = [float(t) for t in events]
    if "model" in result.meta:
        attrs["model"] = str(result.meta["model"])
    return attrs


def to_pandas(result: Result, names: Sequence[str] | None = None) -> Any:
    """A :class:`pandas.DataFrame`: index ``time`` [s] (not unique at events), one column
    per dotted name (default: every variable and alias), units in ``df.attrs["units"]``,
    parameters in ``df.attrs["parameters"]``, event instants in ``df.attrs["event_times"]``.
    """
    import pandas as pd

    cols = _names(result, names)
    data = {n: np.asarray(result[n], dtype=float) for n in cols}
    df = pd.DataFrame(data, index=pd.Index(np.asarray(result.time, dtype=float), name="time"),
                      columns=cols)
    df.attrs["units"] = {"time": "s", **{n: unit_of(result, n) for n in cols}}
    df.attrs["parameters"] = dict(result.parameters)
    df.attrs["parameter_units"] = {n: result.units.get(n, "") for n in result.parameters}
    df.attrs.update(_meta_attrs(result))
    return df


def to_xarray(result: Result, names: Sequence[str] | None = None,
              parameters: bool = True) -> Any:
    """An :class:`xarray.Dataset` with the coordinate ``time`` [s] (not unique at events),
    one data variable per dotted name with ``attrs["units"]``, and (``parameters``) every
    parameter as a 0-d data variable with ``attrs["kind"] = "parameter"``."""
    import xarray as xr

    cols = _names(result, names)
    table = _table(result, cols)        # one gather; xr.Variable costs less than DataArray
    time = xr.Variable("time", table[:, 0], {"units": "s", "long_name": "time"})
    data = {n: xr.Variable("time", table[:, k], {"units": unit_of(result, n), "long_name": n})
            for k, n in enumerate(cols, start=1)}
    if parameters:
        for n, v in result.parameters.items():
            if n not in data:
                data[n] = xr.Variable((), float(v), {"units": result.units.get(n, ""),
                                                     "long_name": n, "kind": "parameter"})
    attrs = _meta_attrs(result)
    return xr.Dataset(data, coords={"time": time}, attrs=attrs)


def _result(time: np.ndarray, columns: dict[str, np.ndarray], units: dict[str, str],
            parameters: dict[str, float], attrs: dict[str, Any]) -> Result:
    from .result import Result

    names = list(columns)
    values = (np.column_stack([columns[n] for n in names]) if names
              else np.zeros((len(time), 0)))
    meta: dict[str, Any] = {}
    if "event_times" in attrs:
        meta["event_times"] = [float(t) for t in np.atleast_1d(attrs["event_times"])]
        meta["n_events"] = len(meta["event_times"])
    if "model" in attrs:
        meta["model"] = attrs["model"]
    unit_map = {n: u for n, u in units.items() if n not in ("time", "t")}
    return Result(np.asarray(time, dtype=float), values, names, {}, dict(parameters),
                  unit_map, meta)


def from_pandas(df: Any) -> Result:
    """The inverse of :func:`to_pandas` (any DataFrame with a numeric time index or a
    ``time`` column works; units are read from ``df.attrs["units"]`` when present)."""
    if "time" in df.columns:
        df = df.set_index("time")
    units = dict(df.attrs.get("units", {}))
    units.update(df.attrs.get("parameter_units", {}))
    cols = {str(c): df[c].to_numpy(dtype=float) for c in df.columns}
    return _result(df.index.to_numpy(dtype=float), cols, units,
                   {k: float(v) for k, v in df.attrs.get("parameters", {}).items()},
                   df.attrs)


def from_xarray(ds: Any) -> Result:
    """The inverse of :func:`to_xarray`: 1-d variables along ``time`` are trajectories, 0-d
    variables parameters; units from each variable's ``attrs["units"]``."""
    cols: dict[str, np.ndarray] = {}
    params: dict[str, float] = {}
    units: dict[str, str] = {}
    for name in ds.data_vars:          # ds.variables: no DataArray made per variable
        var = ds.variables[name]
        units[str(name)] = str(var.attrs.get("units", ""))
        if var.ndim == 0:
            params[str(name)] = float(var.values)
        elif var.dims == ("time",):
            cols[str(name)] = np.asarray(var.values, dtype=float)
    return _result(np.asarray(ds["time"].values, dtype=float), cols, units, params,
                   dict(ds.attrs))


def write_csv(result: Result, path: str | Path, names: Sequence[str] | None = None,
              units: bool = False, fmt: str = "%.12g",
              progress: Callable[[float], None] | None = None) -> Path:
    """``time,<names>`` per row; with ``units`` a second header row holds the units
    (``s,V,A,...``; an empty cell for a dimensionless or undeclared one). ``progress`` is
    called with the fraction written after each block of rows. String columns (of
    ``result.text``; by default after the others) are written as text, Binary ones in hex."""
    cols = _names(result, names)
    if names is None:
        cols += list(result.text)
    texts = [n for n in cols if n in result.text]
    numeric = [n for n in cols if n not in result.text]
    table = _table(result, numeric)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    row = ",".join([fmt] * table.shape[1])
    with path.open("w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(["time", *cols])
        if units:
            writer.writerow([UNITS_ROW, *[unit_of(result, n) for n in cols]])
        if texts:                                   # row by row, columns in the given order
            where = {n: k + 1 for k, n in enumerate(numeric)}
            for i, r in enumerate(table.tolist()):
                writer.writerow([fmt % r[0], *[fmt % r[where[n]] if n in where
                                               else text_cell(result.text[n][i])
                                               for n in cols]])
            return path
        for start in range(0, len(table), 256):          # in bulk: one format per row
            fh.write("\r\n".join(row % tuple(r) for r in table[start:start + 256].tolist()))
            fh.write("\r\n")
            if progress is not None:
                progress(min(1.0, (start + 256) / len(table)))
    return path


def _table(result: Result, cols: list[str]) -> np.ndarray:
    """``time`` then the columns ``cols`` (aliases and parameters resolved), one array."""
    index, values = result._index, result.values
    direct = [index.get(n) for n in cols]
    if all(k is not None for k in direct):                   # no alias: one gather
        return np.column_stack([np.asarray(result.time, dtype=float),
                                np.asarray(values, dtype=float)[:, direct]])
    return np.column_stack([np.asarray(result.time, dtype=float)]
                           + [np.asarray(result[n], dtype=float) for n in cols])


def column_major(result: Result, cols: list[str]) -> np.ndarray:
    """``time`` then the columns ``cols``, one row of the array per column (what columnar
    writers take): variables and aliases gathered at once, parameters filled in."""
    values = np.asarray(result.values, dtype=float)
    out = np.empty((len(cols) + 1, len(result.time)))
    out[0] = result.time
    rows, where, signs = [], [], []
    for k, name in enumerate(cols, start=1):
        j, sign = result._index.get(name), 1.0
        if j is None and name in result.aliases:
            rep, sign = result.aliases[name]
            j = result._index.get(rep)
        if j is None:
            out[k] = result[name]
        else:
            rows.append(k)
            where.append(j)
            signs.append(sign)
    if rows:
        out[rows] = values[:, where].T * np.asarray(signs)[:, None]
    return out


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def read_csv(path: str | Path) -> Result:
    """Read a CSV written by :func:`write_csv` (or any CSV whose first column is the time):
    the optional units row is recognised by its non-numeric cells."""
    with Path(path).open(newline="") as fh:
        rows = list(csv.reader(fh))
    if not rows:
        raise ValueError(f"{path}: empty CSV file")
    header = [h.strip() for h in rows[0]]
    body = rows[1:]
    units: dict[str, str] = {}
    if body and body[0] and not _is_number(body[0][0]):   # the units row: "s", ...
        units = {n: u.strip() for n, u in zip(header, body[0], strict=False)}
        body = body[1:]
    body = [r for r in body if r]
    texts = {k for k in range(1, len(header))
             if any(r[k].strip() and not _is_number(r[k]) for r in body if k < len(r))}
    table = np.array([[float(c) if c.strip() else math.nan
                       for k, c in enumerate(r) if k not in texts] for r in body],
                     dtype=float).reshape(-1, len(header) - len(texts))
    numeric = [n for k, n in enumerate(header) if k not in texts]
    cols = {n: table[:, k] for k, n in enumerate(numeric[1:], start=1)}
    result = _result(table[:, 0], cols, units, {}, {})
    result.text = {header[k]: [r[k] for r in body] for k in sorted(texts)}
    return result
