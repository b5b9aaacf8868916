"""Time-varying top-level inputs: ``simulate(..., inputs=...)`` and ``--input file.csv``.

Each input named in the data becomes a table of time (linear interpolation, a repeated time is
a jump, the last value held): the model's input symbol is replaced by ``c0 + c1*time`` with
coefficients that change at the breakpoints, which are time events.

Data: a CSV path whose first column is ``time`` and whose other columns are named after the
model's inputs, or a mapping ``{name: (times, values)}``.
"""

from __future__ import annotations

import csv
from dataclasses import replace
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np

from ..backends.casadi_dae import CasadiDAE
from ..core.flatmodel import FlatTable, FlatVariable, HybridPart
from ..core.variables import Discrete
from ..errors import ParameterError


def read_input_table(source: Any) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """``{name: (times, values)}`` from a CSV path or a mapping."""
    if isinstance(source, (str, Path)):
        path = Path(source)
        if not path.is_file():
            raise ParameterError(f"input file {path} does not exist")
        with path.open(newline="") as fh:
            rows = list(csv.reader(fh))
        if len(rows) < 2:
            raise ParameterError(f"input file {path}: needs a header row and data rows")
        head = [h.strip() for h in rows[0]]
        if head[0] != "time":
            raise ParameterError(f"input file {path}: the first column must be 'time', got "
                                 f"{head[0]!r}")
        try:
            data = np.array([[float(v) for v in r] for r in rows[1:] if r], dtype=float)
        except ValueError as err:
            raise ParameterError(f"input file {path}: {err}") from None
        if data.shape[1] != len(head):
            raise ParameterError(f"input file {path}: rows have {data.shape[1]} columns, the "
                                 f"header {len(head)}")
        return {h: (data[:, 0], data[:, k]) for k, h in enumerate(head) if k}
    if isinstance(source, dict):
        out = {}
        for name, val in source.items():
            try:
                times, values = val
            except (TypeError, ValueError):
                raise ParameterError(f"input {name!r}: expected (times, values)") from None
            out[name] = (np.asarray(times, dtype=float), np.asarray(values, dtype=float))
        return out
    raise ParameterError(f"inputs must be a CSV path or a mapping, got {type(source).__name__}")


def with_input_tables(dae: CasadiDAE, source: Any) -> CasadiDAE:
    """A copy of ``dae`` whose named inputs follow the tables of ``source``."""
    tables = read_input_table(source)
    names = [u.name for u in dae.inputs]
    unknown = [n for n in tables if n not in names]
    if unknown:
        raise ParameterError(f"input data names {', '.join(unknown)}, which are not inputs of "
                             f"the model (its inputs: {', '.join(names) or 'none'})")
    for name, (t, v) in tables.items():
        if t.size == 0 or not (np.all(np.isfinite(t)) and np.all(np.isfinite(v))):
            raise ParameterError(f"input {name!r}: times and values must be finite numbers")
        if np.any(np.diff(t) < 0):
            raise ParameterError(f"input {name!r}: times must not decrease")
    hybrid = dae.hybrid or HybridPart()
    discretes = list(dae.discretes)
    new_tables = list(hybrid.tables)
    old, new, extra_p = [], [], []
    for name, (t, v) in tables.items():
        u = dae.inputs[names.index(name)]
        c0 = FlatVariable(f"${name}.c0", ca.SX.sym(f"{name}.c0"), Discrete(), "")
        c1 = FlatVariable(f"${name}.c1", ca.SX.sym(f"{name}.c1"), Discrete(), "")
        new_tables.append(FlatTable(len(discretes), len(discretes) + 1, t, v, "linear", "hold",
                                    f"input {name}"))
        discretes += [c0, c1]
        extra_p += [c0.sx, c1.sx]
        old.append(u.sx)
        new.append(c0.sx + c1.sx * dae.t)
    old_v, new_v = ca.vertcat(*old), ca.vertcat(*new)
    exprs = [dae.ode, dae.alg, dae.observed] + hybrid.expressions()
    sub = ca.substitute(exprs, [old_v], [new_v])
    hybrid = replace(hybrid.with_expressions(sub[3:]), tables=new_tables)
    return replace(dae, ode=sub[0], alg=sub[1], observed=sub[2],
                   p=ca.vertcat(dae.p, *extra_p), discretes=discretes, hybrid=hybrid,
                   cache={})
