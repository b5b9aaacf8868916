"""String and Binary variables in a co-simulation: recorded and passed along connections.

They are no numeric signals (no extrapolation, no ramps): at every communication point,
after the numeric outputs are settled, :meth:`TextChannel.exchange` reads the String/Binary
outputs, sets each connected input that changed (a Model Exchange unit takes it at an event)
and reads again the outputs of the units it set, until nothing changes; the units then step
with these values held. :meth:`TextChannel.record` keeps a row of every String/Binary input,
output and recorded variable: ``str`` for a String, ``bytes`` for a Binary (CSV files write
them as text and as hex, :mod:`bgmodelica.dataio`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from .checks import Plan
from .fmu import FmuInfo


class TextChannel:
    """The String/Binary connectors of the elements ``names`` and the extra recorded ones
    (``extra[el]``: variable names)."""

    def __init__(self, plan: Plan, infos: Mapping[str, FmuInfo], names: list[str],
                 extra: Mapping[str, list[str]]) -> None:
        self.names = list(names)
        self.inputs = {n: list(plan.text_inputs.get(n, [])) for n in names}
        self.outputs = {n: list(plan.text_outputs.get(n, [])) for n in names}
        self.extra = {n: [v for v in extra.get(n, []) if v not in self.inputs[n]
                          and v not in self.outputs[n]] for n in names}
        self.sources = dict(plan.text_sources)
        self.columns = [f"{n}.{v}" for n in names
                        for v in self.inputs[n] + self.outputs[n] + self.extra[n]]
        self.units_of = {f"{n}.{v}": infos[n].variables[v].unit for n in names
                         for v in self.inputs[n] + self.outputs[n] + self.extra[n]}
        self.rows: list[list[Any]] = []
        self.y: dict[str, dict[str, Any]] = {}
        self.u: dict[str, dict[str, Any]] = {}
        self.units: Mapping[str, Any] = {}

    def __bool__(self) -> bool:
        return bool(self.columns)

    def start(self, units: Mapping[str, Any]) -> None:
        """Read the initial values of the initialized ``units``, pass them along."""
        self.units = units
        for n in self.names:
            self.u[n] = dict(zip(self.inputs[n], units[n].get_text(self.inputs[n]),
                                 strict=True)) if self.inputs[n] else {}
        self.exchange()

    def _read(self, n: str) -> None:
        if self.outputs[n]:
            self.y[n] = dict(zip(self.outputs[n], self.units[n].get_text(self.outputs[n]),
                                 strict=True))
        else:
            self.y[n] = {}

    def exchange(self) -> None:
        """Read the outputs, set the connected inputs that changed, until none changes."""
        for n in self.names:
            self._read(n)
        for _ in range(len(self.names) + 1):
            changed: dict[str, dict[str, Any]] = {}
            for (el, u), (src, y) in self.sources.items():
                value = self.y[src][y]
                if self.u[el].get(u) != value:
                    changed.setdefault(el, {})[u] = value
            if not changed:
                return
            for el, values in changed.items():
                self.units[el].set_text(values)
                self.u[el].update(values)
                self._read(el)

    def record(self) -> None:
        """Keep the current values as one row (call with every recorded point)."""
        row: list[Any] = []
        for n in self.names:
            row += [self.u[n][v] for v in self.inputs[n]]
            row += [self.y[n][v] for v in self.outputs[n]]
            if self.extra[n]:
                row += self.units[n].get_text(self.extra[n])
        self.rows.append(row)

    def table(self) -> dict[str, list[Any]]:
        """Column name -> the recorded values."""
        return {c: [r[k] for r in self.rows] for k, c in enumerate(self.columns)}
