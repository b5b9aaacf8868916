"""Reading MSL table matrices from files: text (``#1`` format), MATLAB MAT and CSV.

Text files start with ``#1``, then declare each matrix as ``double name(rows,cols)`` (or
``float``) followed by its ``rows*cols`` numbers row by row (separators: blanks, tabs, commas,
semicolons; ``#`` starts a comment anywhere). MAT files (v4 to v7) are read with scipy.
CSV files hold one matrix (named ``Values`` by the MSL blocks) after ``n_header`` lines.
``modelica://`` and ``file://`` URIs are not resolved here: pass a plain path.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from .errors import TableError

_DECL = re.compile(r"^\s*(double|float)\s+([^\s(),]+)\s*\(\s*(\d+)\s*,\s*(\d+)\s*\)")
_SEP = re.compile(r"[\s,;]+")


def read_table(file_name: str, table_name: str, delimiter: str = ",",
               n_header: int = 0) -> np.ndarray:
    """Matrix ``table_name`` of the file ``file_name`` (text, ``.mat`` or ``.csv``)."""
    path = Path(file_name.strip())
    if not path.is_file():
        raise TableError(f"table {table_name!r}: the file {str(path)!r} does not exist")
    suffix = path.suffix.lower()
    if suffix == ".csv":
        return _read_csv(path, delimiter, n_header)
    if suffix == ".mat":
        return _read_mat(path, table_name)
    return _read_text(path, table_name)


def _read_text(path: Path, name: str) -> np.ndarray:
    text = path.read_text(encoding="utf-8-sig", errors="replace")
    if not text.startswith("#1"):
        raise TableError(f"table {name!r}: {path} is not a table text file (it must start "
                         "with '#1')")
    lines = [ln.split("#", 1)[0] for ln in text.splitlines()[1:]]
    for i, line in enumerate(lines):
        m = _DECL.match(line)
        if m is None or m.group(2) != name:
            continue
        rows, cols = int(m.group(3)), int(m.group(4))
        numbers: list[float] = []
        rest = [line[m.end():], *lines[i + 1:]]
        for chunk in rest:
            if len(numbers) >= rows * cols:
                break
            if _DECL.match(chunk):
                break
            for tok in _SEP.split(chunk.strip()):
                if tok:
                    try:
                        numbers.append(float(tok))
                    except ValueError:
                        raise TableError(f"table {name!r} in {path}: {tok!r} is not a "
                                         "number") from None
        if len(numbers) < rows * cols:
            raise TableError(f"table {name!r} in {path}: declared ({rows},{cols}) but only "
                             f"{len(numbers)} numbers follow")
        return np.array(numbers[:rows * cols], dtype=float).reshape(rows, cols)
    raise TableError(f"table {name!r} is not declared in {path}")


def _read_mat(path: Path, name: str) -> np.ndarray:
    from scipy.io import loadmat

    try:
        data = loadmat(str(path))
    except Exception as exc:          # noqa: BLE001 -- scipy raises several kinds
        raise TableError(f"table {name!r}: cannot read the MAT file {path}: {exc}") from None
    if name not in data:
        raise TableError(f"table {name!r} is not in the MAT file {path}")
    return np.atleast_2d(np.asarray(data[name], dtype=float))


def _read_csv(path: Path, delimiter: str, n_header: int) -> np.ndarray:
    rows = []
    lines = path.read_text(encoding="utf-8-sig").splitlines()[n_header:]
    for n, line in enumerate(lines, start=n_header + 1):
        if not line.strip():
            continue
        parts = line.split(delimiter) if delimiter.strip() else line.split()
        try:
            rows.append([float(p) for p in parts if p.strip()])
        except ValueError:
            raise TableError(f"CSV table {path} line {n}: non-numeric entry") from None
    if not rows or len({len(r) for r in rows}) != 1:
        raise TableError(f"CSV table {path}: rows are empty or of different lengths")
    return np.array(rows, dtype=float)
