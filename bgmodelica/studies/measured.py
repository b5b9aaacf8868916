"""Measured data for :func:`~.fitting.fit`: an :class:`Experiment` (one measured run and the
parameter values that differ in it) and :func:`load_table`, which reads its table (CSV file,
pandas DataFrame, mapping of columns, :class:`~bgmodelica.result.Result`) into a time column
and named data columns, refusing unusable data with :class:`FitError`."""

from __future__ import annotations

import csv
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ModelError


class FitError(ModelError):
    """The data or the fit set-up is unusable, or the model failed during the fit."""


@dataclass
class Experiment:
    """One measured run: ``data`` (CSV path, pandas DataFrame, mapping of columns with
    ``"time"``, or a :class:`~bgmodelica.result.Result` with ``columns``), the parameter
    values of this experiment (``params``), column weights (1/sigma) and a name."""

    data: Any
    params: dict[str, Any] = field(default_factory=dict)
    weights: dict[str, float] | None = None
    name: str = ""
    columns: Sequence[str] | None = None
    start_time: float | None = None       # default: fit(start_time=...)


def load_table(data: Any, columns: Sequence[str] | None = None,
               what: str = "data") -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """``(times, {column: values})`` from a CSV file (first column the time), a DataFrame,
    a mapping or a Result."""
    from ..result import Result

    if isinstance(data, (str, Path)):
        path = Path(data)
        if not path.is_file():
            raise FitError(f"{what}: no such file {path}")
        with path.open(newline="") as fh:
            rows = list(csv.reader(fh))
        rows = [r for r in rows if r and any(c.strip() for c in r)]
        if len(rows) < 2:
            raise FitError(f"{path}: needs a header row and at least one data row")
        header = [h.strip() for h in rows[0]]
        try:
            values = np.array([[float(c) if c.strip() else np.nan for c in r] + [np.nan] * (
                len(header) - len(r)) for r in rows[1:]], dtype=float)
        except ValueError as err:
            raise FitError(f"{path}: not a table of numbers ({err})") from None
        if values.shape[1] != len(header):
            raise FitError(f"{path}: rows longer than the header")
        table = {h: values[:, k] for k, h in enumerate(header)}
        tname = header[0]
        if tname.lower() not in ("time", "t", "time [s]"):
            raise FitError(f"{path}: the first column must be 'time', found {tname!r}")
        times = table.pop(tname)
        what = str(path)
    elif isinstance(data, Result):
        if not columns:
            raise FitError(f"{what}: a Result needs the columns to fit (columns=[...])")
        times = np.asarray(data.time, dtype=float)
        table = {c: np.asarray(data[c], dtype=float) for c in columns}
    elif hasattr(data, "columns") and hasattr(data, "to_numpy"):        # a DataFrame
        cols = {str(c): np.asarray(data[c].to_numpy(), dtype=float) for c in data.columns}
        tkey = next((k for k in cols if k.lower() in ("time", "t")), None)
        times = cols.pop(tkey) if tkey else np.asarray(data.index.to_numpy(), dtype=float)
        table = cols
    elif isinstance(data, Mapping):
        cols = {str(k): np.asarray(v, dtype=float).ravel() for k, v in data.items()}
        tkey = next((k for k in cols if k.lower() in ("time", "t")), None)
        if tkey is None:
            raise FitError(f"{what}: no 'time' column")
        times = cols.pop(tkey)
        table = cols
    else:
        raise FitError(f"{what}: expected a CSV path, a DataFrame, a mapping or a Result, got "
                       f"{type(data).__name__}")
    if columns is not None:
        missing = [c for c in columns if c not in table]
        if missing:
            raise FitError(f"{what}: no column {missing[0]!r}; columns: {', '.join(table)}")
        table = {c: table[c] for c in columns}
    if not table:
        raise FitError(f"{what}: no measured column besides the time")
    times = np.asarray(times, dtype=float)
    if times.ndim != 1 or not len(times) or not np.all(np.isfinite(times)):
        raise FitError(f"{what}: the time column must be finite numbers")
    if np.any(np.diff(times) <= 0):
        raise FitError(f"{what}: the times must be strictly increasing")
    for c, v in table.items():
        if len(v) != len(times):
            raise FitError(f"{what}: column {c!r} has {len(v)} values for {len(times)} times")
        if np.any(np.isinf(v)):
            raise FitError(f"{what}: column {c!r} has infinite values")
    return times, table


def as_experiments(data: Any) -> list[Experiment]:
    """The experiments of ``fit``'s ``data``: one, a list, or a table (one experiment)."""
    if isinstance(data, Experiment):
        return [data]
    if isinstance(data, (list, tuple)):
        if not data:
            raise FitError("fit: no data")
        return [d if isinstance(d, Experiment) else Experiment(d) for d in data]
    return [Experiment(data)]
