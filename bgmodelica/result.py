"""Simulation results: time vector, every variable by dotted name, CSV and plots."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, MutableMapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np


class Deferred(MutableMapping):
    """A dict made when first used: ``make()`` gives it (a large model's units or aliases
    then cost nothing until asked for). Reads and writes go to that dict; it pickles and
    copies as a plain dict."""

    __slots__ = ("_make", "_data")

    def __init__(self, make: Callable[[], dict]) -> None:
        self._make: Callable[[], dict] | None = make
        self._data: dict | None = None

    @property
    def data(self) -> dict:
        if self._data is None:
            self._data = self._make()     # type: ignore[misc]
            self._make = None
        return self._data

    def __getitem__(self, key: Any) -> Any:
        return self.data[key]

    def __setitem__(self, key: Any, value: Any) -> None:
        self.data[key] = value

    def __delitem__(self, key: Any) -> None:
        del self.data[key]

    def __iter__(self) -> Iterator:
        return iter(self.data)

    def __len__(self) -> int:
        return len(self.data)

    def __contains__(self, key: object) -> bool:
        return key in self.data

    def get(self, key: Any, default: Any = None) -> Any:
        return self.data.get(key, default)

    def __eq__(self, other: object) -> bool:
        return self.data == (other.data if isinstance(other, Deferred) else other)

    __hash__ = None     # type: ignore[assignment]

    def __repr__(self) -> str:
        return repr(self.data)

    def copy(self) -> dict:
        return dict(self.data)

    def __reduce__(self) -> tuple:
        return (dict, (self.data,))


@dataclass
class Result:
    """Trajectories of a simulation.

    time: [s], shape (N,). ``result["motor.R.i"]`` gives a variable (aliases and parameters
    included). ``meta`` holds solver statistics and compile/run times [s]. The variables
    other than the states are computed from the trajectory when first asked for.
    ``text``: String (``str``) and Binary (``bytes``) variables of a co-simulation, name ->
    one value per time point; ``result[name]`` gives them as an object array.
    """

    time: np.ndarray
    data: np.ndarray | Callable[[], np.ndarray]   # (N, len(names)), or computes it on demand
    names: list[str]
    aliases: MutableMapping[str, tuple[str, float]] = field(default_factory=dict)
    parameters: dict[str, float] = field(default_factory=dict)
    units: MutableMapping[str, str] = field(default_factory=dict)
    meta: dict[str, Any] = field(default_factory=dict)
    text: dict[str, list[Any]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self._by_name: dict[str, int] | None = None

    @property
    def _index(self) -> dict[str, int]:
        """Name -> column of :attr:`values` (made when first used)."""
        if self._by_name is None:
            self._by_name = {n: k for k, n in enumerate(self.names)}
        return self._by_name

    def __repr__(self) -> str:
        """One line: ``Result(RobotPID: 162 variables, 501 points, t = 0..10 s)``."""
        model = self.meta.get("model") or self.meta.get("name")
        n = len(self.time)
        span = f", t = {float(self.time[0]):g}..{float(self.time[-1]):g} s" if n else ""
        return (f"Result({f'{model}: ' if model else ''}{len(self.names) + len(self.aliases)} "
                f"variables, {n} points{span})")

    @property
    def values(self) -> np.ndarray:
        """All recorded variables, shape (N, len(names)); evaluated on first use."""
        if callable(self.data):
            self.data = self.data()
        return self.data

    def __contains__(self, name: str) -> bool:
        return (name in self._index or name in self.aliases or name in self.parameters
                or name in self.text)

    def __getitem__(self, name: str) -> np.ndarray:
        if name in ("time", "t"):
            return self.time
        if name in self._index:
            return self.values[:, self._index[name]]
        if name in self.aliases:
            rep, sign = self.aliases[name]
            return sign * self[rep]
        if name in self.parameters:
            return np.full_like(self.time, self.parameters[name])
        if name in self.text:
            out = np.empty(len(self.text[name]), dtype=object)
            out[:] = self.text[name]
            return out
        close = [n for n in self.all_names() if n.endswith(name.split(".")[-1])][:6]
        raise KeyError(f"no variable {name!r} in the result"
                       + (f"; similar: {', '.join(close)}" if close else ""))

    def all_names(self) -> list[str]:
        """Every name the result answers to, computed variables first, then aliases."""
        return list(self.names) + sorted(self.aliases)

    def sensitivity(self, name: str, param: str) -> np.ndarray:
        """d(name)/d(param) along ``time`` of a run made with ``simulate(...,
        sensitivities=[param, ...])`` (see :mod:`bgmodelica.studies.sensitivity`)."""
        from .studies.sensitivity import sensitivity_of

        return sensitivity_of(self, name, param)

    def final(self, name: str) -> float:
        return float(self[name][-1])

    def unit(self, name: str) -> str:
        """The unit of ``name`` ("" if dimensionless or not declared; aliases resolved)."""
        from .dataio import unit_of

        return unit_of(self, name)

    def to_csv(self, path: str | Path, names: Sequence[str] | None = None, *,
               units: bool = False) -> Path:
        """Write ``time,<names>`` (default: every variable incl. aliases, then the ``text``
        ones: a String as text, a Binary in hex) to a CSV file; ``units=True`` adds a second
        header row with the units (``s,V,A,...``). At an event instant there are two rows
        with the same time (left and right limit).
        :meth:`read_csv` reads it back."""
        from .dataio import write_csv

        return write_csv(self, path, names, units=units)

    def save(self, path: str | Path, names: Sequence[str] | None = None, *,
             units: bool = False, progress: Callable[[float], None] | None = None) -> Path:
        """Write by extension: ``.parquet`` (pyarrow), ``.nc`` (netCDF), else CSV (``units``:
        the units row); ``progress`` is called with the fraction written. :meth:`read` reads
        any of them back (see :mod:`bgmodelica.result_files`)."""
        from .result_files import save

        return save(self, path, names, units=units, progress=progress)

    @classmethod
    def read(cls, path: str | Path) -> Result:
        """A result from a ``.csv``, ``.parquet`` or ``.nc`` file written by :meth:`save`."""
        from .result_files import read

        return read(path)

    def to_parquet(self, path: str | Path, names: Sequence[str] | None = None) -> Path:
        """Write ``time`` and the variables (default: every one, aliases included) as an
        Apache Parquet file, units in the field metadata, parameters in the schema metadata;
        :meth:`read_parquet` reads it back."""
        from .result_files import write_parquet

        return write_parquet(self, path, names)

    @classmethod
    def read_parquet(cls, path: str | Path) -> Result:
        """A result from a Parquet file written by :meth:`to_parquet`."""
        from .result_files import read_parquet

        return read_parquet(path)

    def to_netcdf(self, path: str | Path, names: Sequence[str] | None = None) -> Path:
        """Write the Dataset of :meth:`to_xarray` as netCDF (4 with h5netcdf, else 3);
        :meth:`read_netcdf` reads it back."""
        from .result_files import write_netcdf

        return write_netcdf(self, path, names)

    @classmethod
    def read_netcdf(cls, path: str | Path) -> Result:
        """A result from a netCDF file written by :meth:`to_netcdf`."""
        from .result_files import read_netcdf

        return read_netcdf(path)

    @classmethod
    def read_csv(cls, path: str | Path) -> Result:
        """A result from a CSV file written by :meth:`to_csv` (units row optional)."""
        from .dataio import read_csv

        return read_csv(path)

    def to_pandas(self, names: Sequence[str] | None = None) -> Any:
        """A :class:`pandas.DataFrame` indexed by ``time`` (not unique at events: two rows,
        left and right limit), columns by dotted name, units in ``df.attrs["units"]``,
        parameters in ``df.attrs["parameters"]`` (see :mod:`bgmodelica.dataio`)."""
        from .dataio import to_pandas

        return to_pandas(self, names)

    def to_xarray(self, names: Sequence[str] | None = None, parameters: bool = True) -> Any:
        """An :class:`xarray.Dataset` along ``time`` with ``attrs["units"]`` on every
        variable; parameters as 0-d variables (see :mod:`bgmodelica.dataio`)."""
        from .dataio import to_xarray

        return to_xarray(self, names, parameters)

    @classmethod
    def from_pandas(cls, df: Any) -> Result:
        """The inverse of :meth:`to_pandas`."""
        from .dataio import from_pandas

        return from_pandas(df)

    @classmethod
    def from_xarray(cls, ds: Any) -> Result:
        """The inverse of :meth:`to_xarray`."""
        from .dataio import from_xarray

        return from_xarray(ds)

    def plot(self, names: Iterable[str] | None = None, path: str | Path | None = None,
             title: str | None = None, ax: Any = None, **options: Any) -> Any:
        """Plot variables against time, one stacked subplot per unit, events marked;
        ``names`` default to the states. Saves to ``path`` if given. Returns the figure.
        ``options``: ``style`` ("paper" or None), ``events``, ``figsize``
        (see :func:`bgmodelica.plotting.plot_result`)."""
        from .plotting import plot_result

        return plot_result(self, names, path, title, ax, **options)

    def _repr_html_(self) -> str:
        from .notebook import result_html

        return result_html(self)
