"""What an FMU's ``modelDescription.xml`` says, as the master needs it (:class:`FmuInfo`,
:class:`FmuVariable`), and the FMU archives unpacked once per process.

Variables of every FMI type are listed with their exact type; FMI 3.0 array variables are
listed as their elements ``x[1]``, ``x[2]``... (row-major, 1-based, ``A[1,2]`` for matrices),
so connections, parameters and results name single elements. How the units run FMUs is in
:mod:`.units` and :mod:`.me_unit`.

FMU archives are checked and unpacked by :mod:`.archive` (never ``extractall``): an unsafe,
truncated or non-FMU zip raises :class:`~.errors.UnsafeArchiveError` /
:class:`~.errors.FmuFormatError` naming the file.
"""

from __future__ import annotations

import atexit
import math
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .archive import SafeZip, _one_line
from .errors import FmuFormatError, UnknownConnectorError

MODEL_DESCRIPTION = "modelDescription.xml"

REAL_TYPES = {"Real", "Float64", "Float32"}


def _kind_of_type(type_name: str) -> str:
    if type_name in REAL_TYPES:
        return "Real"
    if type_name.startswith(("Int", "UInt")) or type_name == "Integer":
        return "Integer"
    return type_name  # Boolean, String, Binary, Clock, Enumeration


@dataclass
class FmuVariable:
    """One scalar variable of an FMU."""

    name: str
    vr: int
    causality: str
    variability: str
    type: str                 # "Real", "Integer", "Boolean", "String", ...
    unit: str = ""
    start: float | None = None
    description: str = ""
    min: float | None = None
    max: float | None = None
    fmi_type: str = ""        # the exact FMI type: "Float32", "UInt16", "Enumeration"...
    element: int = 0          # FMI 3.0 arrays: the element's row-major offset in its array
    array_size: int = 1       # ... and the array's number of elements (1: a scalar)
    array_start: tuple = ()   # ... and the start values of the whole array
    start_text: Any = None    # the start value as declared (String, Binary: the only one)
    base: str = ""            # the array's name ("" for scalars)

    @property
    def settable(self) -> bool:
        """Whether an importer may set it before initialization (a parameter that is not a
        constant or calculated, or an input's start value)."""
        if self.causality == "input":
            return True
        return self.causality == "parameter" and self.variability in ("fixed", "tunable")

    @property
    def set_by_name(self) -> bool:
        """Set at start-up by name rather than as a signal: a parameter, or the start value of
        a String or Binary input."""
        return self.causality == "parameter" or (self.causality == "input"
                                                 and self.type in ("String", "Binary"))

    def range_text(self) -> str:
        lo = "-inf" if self.min is None else f"{self.min:g}"
        hi = "inf" if self.max is None else f"{self.max:g}"
        return f"[{lo}, {hi}]"

    def out_of_range(self, value: float) -> bool:
        return ((self.min is not None and value < self.min)
                or (self.max is not None and value > self.max))


def _bound(*candidates: Any) -> float | None:
    """The first of ``candidates`` (strings from the model description) that is a number;
    infinite bounds are the same as none."""
    for c in candidates:
        if c is None or c == "":
            continue
        try:
            value = float(c)
        except (TypeError, ValueError):
            continue
        return value if math.isfinite(value) else None
    return None


@dataclass
class FmuInfo:
    """The parts of an FMU's model description the master needs."""

    path: Path
    model_name: str
    fmi_version: int
    guid: str
    variables: dict[str, FmuVariable]
    feedthrough: dict[str, list[str]]        # output -> inputs it depends on directly
    cs_identifier: str | None = None
    me_identifier: str | None = None
    n_states: int = 0
    n_event_indicators: int = 0
    scheduled_execution: bool = False       # FMI 3.0 Scheduled Execution offered
    description: Any = field(default=None, repr=False)   # the fmpy ModelDescription

    @property
    def inputs(self) -> list[FmuVariable]:
        return [v for v in self.variables.values() if v.causality == "input"]

    @property
    def outputs(self) -> list[FmuVariable]:
        return [v for v in self.variables.values() if v.causality == "output"]

    @property
    def parameters(self) -> list[FmuVariable]:
        return [v for v in self.variables.values() if v.causality == "parameter"]

    def variable(self, name: str, element: str = "") -> FmuVariable:
        try:
            return self.variables[name]
        except KeyError:
            where = f"element {element!r} ({self.path.name})" if element else self.path.name
            raise UnknownConnectorError(f"{where} has no variable {name!r}") from None


def read_fmu_info(path: str | Path) -> FmuInfo:
    """Read ``modelDescription.xml`` of the FMU at ``path`` (the archive is checked and
    unpacked safely first, see :mod:`.archive`; errors: :class:`~.errors.FmuFormatError`,
    :class:`~.errors.UnsafeArchiveError`)."""
    from fmpy import read_model_description

    path = Path(path)
    unzipped = _EXTRACTED.get(path)
    try:
        md = read_model_description(str(unzipped))
    except Exception as err:  # fmpy raises various errors for broken descriptions
        raise FmuFormatError(f"{path}: {MODEL_DESCRIPTION} is not a valid FMI model "
                             f"description: {_one_line(err)}") from None
    try:
        version = int(str(md.fmiVersion).split(".")[0])
    except ValueError:
        version = 0
    if version not in (2, 3):
        raise FmuFormatError(f"{path}: FMI version {md.fmiVersion!r} is not supported "
                             "(FMI 2.0 and 3.0 are)")
    variables: dict[str, FmuVariable] = {}
    for v in md.modelVariables:
        if v.type == "Clock":
            continue                  # clocks belong to Scheduled Execution
        kind = _kind_of_type(v.type)
        fmi_type = "Enumeration" if kind == "Enumeration" else v.type
        dt = v.declaredType
        unit = v.unit or (dt.unit if dt is not None and getattr(dt, "unit", None) else "") or ""
        lo = hi = None
        if kind in ("Real", "Integer"):
            lo = _bound(getattr(v, "min", None), getattr(dt, "min", None))
            hi = _bound(getattr(v, "max", None), getattr(dt, "max", None))
        shape = tuple(int(s) for s in (getattr(v, "shape", None) or ()))
        starts = _start_values(v.start, kind, max(1, int(np.prod(shape))) if shape else 1)
        base = dict(causality=str(v.causality), variability=str(v.variability), type=kind,
                    unit=unit, description=v.description or "", min=lo, max=hi,
                    fmi_type=fmi_type)
        if not shape:
            entries = [(v.name, 0, starts[0] if starts else None)]
            size, array_start, base_name = 1, (), ""
        else:
            size = int(np.prod(shape))
            idx = np.array(np.unravel_index(np.arange(size), shape)).T + 1
            entries = [(f"{v.name}[{','.join(str(int(i)) for i in row)}]", k,
                        starts[k] if k < len(starts) else None) for k, row in enumerate(idx)]
            fill = 0.0 if kind not in ("String", "Binary") else ""
            array_start = tuple(s if s is not None else fill for s in
                                (starts + [None] * size)[:size])
            base_name = v.name
        for name, k, start in entries:
            if name in variables:
                raise FmuFormatError(f"{path}: {MODEL_DESCRIPTION} declares the variable "
                                     f"{name!r} twice")
            numeric = start if kind not in ("String", "Binary") else None
            variables[name] = FmuVariable(name, int(v.valueReference), start=numeric,
                                          element=k, array_size=size,
                                          array_start=array_start, start_text=start,
                                          base=base_name, **base)
    inputs = [v.name for v in variables.values() if v.causality == "input"]
    feedthrough = {v.name: list(inputs) for v in variables.values() if v.causality == "output"}
    for unknown in md.outputs:
        if unknown.dependencies is None:        # no attribute: depends on everything
            continue
        feedthrough[unknown.variable.name] = [d.name for d in unknown.dependencies
                                              if d.causality == "input"]
    return FmuInfo(path=path, model_name=md.modelName, fmi_version=version,
                   guid=md.guid if version < 3 else md.instantiationToken,
                   variables=variables, feedthrough=feedthrough,
                   cs_identifier=md.coSimulation.modelIdentifier if md.coSimulation else None,
                   me_identifier=md.modelExchange.modelIdentifier if md.modelExchange else None,
                   n_states=int(md.numberOfContinuousStates or 0),
                   n_event_indicators=int(md.numberOfEventIndicators or 0),
                   scheduled_execution=getattr(md, "scheduledExecution", None) is not None,
                   description=md)


def _start_values(start: Any, kind: str, size: int) -> list[Any]:
    """The declared start value(s) of a variable, as floats for numeric kinds (Boolean:
    1.0/0.0), as text for String and as bytes for Binary; [] when there is none."""
    if start is None:
        return []
    if kind == "String":
        return [str(start)]
    parts = start if isinstance(start, (list, tuple)) else str(start).split() if size > 1 \
        else [start]
    out: list[Any] = []
    for p in parts:
        if kind == "Binary":
            try:
                out.append(bytes.fromhex(str(p)))
            except ValueError:
                out.append(None)
            continue
        text = str(p).strip().lower()
        if kind == "Boolean" or text in ("true", "false"):
            out.append(1.0 if text in ("true", "1") else 0.0)
            continue
        try:
            x = float(p)
        except (TypeError, ValueError):
            out.append(None)
            continue
        out.append(x if math.isfinite(x) else None)
    return out


class _Extracted:
    """Unzip each FMU once per process (shared by the instances of one FMU), safely
    (:class:`~.archive.SafeZip`: checked members, all-or-nothing extraction)."""

    def __init__(self) -> None:
        self.dirs: dict[tuple[Path, int, int], Path] = {}
        self.root: Path | None = None

    def get(self, path: Path) -> Path:
        path = Path(path)
        if not path.is_file():
            raise FmuFormatError(f"FMU {path} does not exist"
                                 + ("" if not path.exists() else " (not a file)"))
        path = path.resolve()
        st = path.stat()
        key = (path, st.st_mtime_ns, st.st_size)     # a rebuilt FMU is unzipped again
        if key not in self.dirs:
            with SafeZip(path, "FMU", MODEL_DESCRIPTION, error=FmuFormatError) as zf:
                if self.root is None:
                    self.root = Path(tempfile.mkdtemp(prefix="bgm_cosim_"))
                target = self.root / f"{len(self.dirs):02d}_{path.stem}"
                zf.extract_all(target)
            self.dirs[key] = target
        return self.dirs[key]

    def cleanup(self) -> None:
        if self.root is not None:
            shutil.rmtree(self.root, ignore_errors=True)
        self.dirs.clear()
        self.root = None


_EXTRACTED = _Extracted()
atexit.register(_EXTRACTED.cleanup)

