"""FMUs as co-simulation units: what the ``modelDescription.xml`` says (:class:`FmuInfo`) and
how to run them through fmpy's low-level API (:class:`CoSimUnit`, :class:`ModelExchangeUnit`).

Both unit kinds offer the same small interface to the master: ``setup`` (instantiate, set
parameters, initialize), ``set_inputs``, ``get``, ``step(t, h, ramp)`` and ``terminate``.

* :class:`CoSimUnit` calls the FMU's own ``doStep`` (FMI 2.0 ``FMU2Slave`` or FMI 3.0
  ``FMU3Slave``); inputs are held over the step (the exported FMUs declare
  ``canInterpolateInputs="false"``), so a ramp given by the master is replaced by its mean
  over the step, which has the same integral.
* :class:`ModelExchangeUnit` integrates a Model Exchange FMU itself (``FMU2Model`` /
  ``FMU3Model``) over each macro step with SciPy's Radau IIA (order 5, L-stable, error
  controlled with ``rtol``/``atol``), the inputs following the ramp ``u0 + slope (t - t0)``.
  The last internal step size is carried over to the next macro step.

Only real-valued (Real / Float64) inputs and outputs are supported as connectors.

FMU archives are checked and unpacked by :mod:`.archive` (never ``extractall``): an unsafe,
truncated or non-FMU zip raises :class:`~.errors.UnsafeArchiveError` /
:class:`~.errors.FmuFormatError` naming the file. The units capture the FMU's log messages;
when an FMU call fails, the :class:`~.errors.CosimStepError` carries the FMU's own error
message (e.g. which parameter is out of range).
"""

from __future__ import annotations

import atexit
import collections
import ctypes
import itertools
import math
import shutil
import tempfile
import weakref
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .archive import SafeZip, _one_line
from .errors import CosimStepError, FmuFormatError, SetupError, UnknownConnectorError

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

    @property
    def settable(self) -> bool:
        """Whether an importer may set it before initialization (a parameter that is not a
        constant or calculated, or an input's start value)."""
        if self.causality == "input":
            return True
        return self.causality == "parameter" and self.variability in ("fixed", "tunable")

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
        start = None
        kind = _kind_of_type(v.type)
        if v.start is not None and kind == "Real":
            try:
                start = float(v.start)
            except (TypeError, ValueError):
                start = None
        dt = v.declaredType
        unit = v.unit or (dt.unit if dt is not None and getattr(dt, "unit", None) else "") or ""
        lo = hi = None
        if kind in ("Real", "Integer"):
            lo = _bound(getattr(v, "min", None), getattr(dt, "min", None))
            hi = _bound(getattr(v, "max", None), getattr(dt, "max", None))
        if v.name in variables:
            raise FmuFormatError(f"{path}: {MODEL_DESCRIPTION} declares the variable "
                                 f"{v.name!r} twice")
        variables[v.name] = FmuVariable(v.name, int(v.valueReference), str(v.causality),
                                        str(v.variability), kind, unit, start,
                                        v.description or "", lo, hi)
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
                   n_states=len(md.derivatives), description=md)


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


# FMI 2.0 log messages are variadic; fmpy formats them with a native proxy that forwards to
# ONE process-wide Python logger (a C global set by ``addLoggerProxy``). That logger must
# therefore live forever: this module's dispatcher, which hands each message to the unit
# whose componentEnvironment it carries, and prints the others as fmpy would.
_FMI2_UNITS: dict[int, weakref.ref] = {}
_FMI2_IDS = itertools.count(1)
_FMI2_CALLBACKS: Any = None


def _fmi2_dispatch(env: Any, name: Any, status: int, category: Any, message: Any) -> None:
    ref = _FMI2_UNITS.get(int(env or 0))
    unit = ref() if ref is not None else None
    if unit is None:
        from fmpy.fmi1 import printLogMessage

        printLogMessage(env, name, status, category, message)
        return
    unit._log(status, category, message)


def _fmi2_callbacks(unit_id: int) -> Any:
    """A callback structure whose logger reaches :func:`_fmi2_dispatch` with ``unit_id``."""
    global _FMI2_CALLBACKS
    from fmpy import calloc, free
    from fmpy.fmi2 import (
        fmi2CallbackAllocateMemoryTYPE,
        fmi2CallbackFreeMemoryTYPE,
        fmi2CallbackFunctions,
        fmi2CallbackLoggerTYPE,
    )
    from fmpy.logging import addLoggerProxy

    if _FMI2_CALLBACKS is None:      # created once, never freed
        _FMI2_CALLBACKS = (fmi2CallbackLoggerTYPE(_fmi2_dispatch),
                           fmi2CallbackAllocateMemoryTYPE(calloc),
                           fmi2CallbackFreeMemoryTYPE(free))
    cb = fmi2CallbackFunctions()
    cb.logger, cb.allocateMemory, cb.freeMemory = _FMI2_CALLBACKS
    cb.componentEnvironment = unit_id
    addLoggerProxy(ctypes.byref(cb))   # cb.logger := proxy; the proxy's target := dispatcher
    return cb


class _Unit:
    """Common part of the co-simulation units (one FMU instance)."""

    interface = ""

    def __init__(self, name: str, info: FmuInfo, input_names: list[str],
                 output_names: list[str]) -> None:
        self.name = name
        self.info = info
        self.input_names = list(input_names)
        self.output_names = list(output_names)
        self.fmu: Any = None
        self._vr_u = [info.variables[n].vr for n in input_names]
        self._vr_y = [info.variables[n].vr for n in output_names]
        self._u_vr = (ctypes.c_uint32 * len(self._vr_u))(*self._vr_u)
        self._y_vr = (ctypes.c_uint32 * len(self._vr_y))(*self._vr_y)
        self._u_buf = np.zeros(len(self._vr_u))
        self._y_buf = np.zeros(len(self._vr_y))
        self.time = 0.0
        # (status, category, message) logged by the FMU; the last errors go into exceptions
        self.messages: collections.deque[tuple[int, str, str]] = collections.deque(maxlen=50)
        self._callbacks: Any = None
        self._n_logged = 0

    # fast real access with preallocated buffers ---------------------------------------------
    def _set(self, vr_arr: Any, values: np.ndarray) -> None:
        if len(values) == 0:
            return
        buf = np.ascontiguousarray(values, dtype=float)
        ptr = buf.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
        if self.info.fmi_version == 2:
            self.fmu.fmi2SetReal(self.fmu.component, vr_arr, len(buf), ptr)
        else:
            self.fmu.fmi3SetFloat64(self.fmu.component, vr_arr, len(buf), ptr, len(buf))

    def _get(self, vr_arr: Any, out: np.ndarray) -> np.ndarray:
        if len(out) == 0:
            return out
        ptr = out.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
        if self.info.fmi_version == 2:
            self.fmu.fmi2GetReal(self.fmu.component, vr_arr, len(out), ptr)
        else:
            self.fmu.fmi3GetFloat64(self.fmu.component, vr_arr, len(out), ptr, len(out))
        return out

    def set_inputs(self, values: np.ndarray) -> None:
        """Set all inputs (in ``input_names`` order)."""
        self._call(self._set, self._u_vr, values)

    def get_outputs(self) -> np.ndarray:
        """All outputs (in ``output_names`` order), a fresh array."""
        return self._call(self._get, self._y_vr, self._y_buf).copy()

    def get(self, names: list[str]) -> np.ndarray:
        """Values of any real variables by name (locals, states, parameters...)."""
        vrs = [self.info.variable(n, self.name).vr for n in names]
        arr = (ctypes.c_uint32 * len(vrs))(*vrs)
        return self._call(self._get, arr, np.zeros(len(vrs)))

    def set_real(self, values: dict[str, float]) -> None:
        if not values:
            return
        vrs = [self.info.variable(n, self.name).vr for n in values]
        arr = (ctypes.c_uint32 * len(vrs))(*vrs)
        self._call(self._set, arr, np.array([float(v) for v in values.values()]))

    def _log(self, status: int, category: Any, message: Any) -> None:
        def text(b: Any) -> str:
            return b.decode("utf-8", "replace") if isinstance(b, bytes) else str(b or "")
        self.messages.append((int(status), text(category), text(message)))
        self._n_logged += 1

    def fmu_errors(self) -> list[str]:
        """The messages the FMU logged with status Discard, Error or Fatal."""
        return [m for status, _, m in self.messages if status >= 2]

    def _call(self, fn: Any, *args: Any, **kw: Any) -> Any:
        n_before = self._n_logged
        try:
            return fn(*args, **kw)
        except CosimStepError:
            raise
        except Exception as err:
            new = min(self._n_logged - n_before, len(self.messages))
            said = [m for status, _, m in list(self.messages)[len(self.messages) - new:]
                    if status >= 2]
            detail = f"{err}" + (f" -- the FMU says: {' | '.join(said[-2:])}" if said else "")
            raise CosimStepError(f"element {self.name!r} ({self.info.path.name}): FMU call "
                                 f"failed at t={self.time:g}: {_one_line(detail, 600)}",
                                 self.name, self.time) from err

    def _instantiate(self, slave: bool) -> None:
        from fmpy import fmi2, fmi3

        unzip = str(_EXTRACTED.get(self.info.path))
        ident = self.info.cs_identifier if slave else self.info.me_identifier
        if ident is None:
            raise SetupError(f"element {self.name!r}: {self.info.path.name} has no "
                             f"{'Co-Simulation' if slave else 'Model Exchange'} interface")
        kw = dict(unzipDirectory=unzip, modelIdentifier=ident, instanceName=self.name)
        if self.info.fmi_version == 2:
            cls = fmi2.FMU2Slave if slave else fmi2.FMU2Model
        elif self.info.fmi_version == 3:
            cls = fmi3.FMU3Slave if slave else fmi3.FMU3Model
        else:
            raise SetupError(f"element {self.name!r}: FMI {self.info.fmi_version} is not "
                             "supported (FMI 2.0 and 3.0 are)")
        try:
            self.fmu = cls(guid=self.info.guid, **kw)  # fmpy: the FMI 3 token goes as guid
        except Exception as err:  # no binary for this platform, unloadable library...
            raise SetupError(f"element {self.name!r}: cannot load the binary of "
                             f"{self.info.path.name}: {_one_line(err)}") from None
        if self.info.fmi_version == 2:
            unit_id = next(_FMI2_IDS)
            _FMI2_UNITS[unit_id] = weakref.ref(self)
            self._fmi2_id = unit_id
            self._callbacks = _fmi2_callbacks(unit_id)   # the FMU keeps a pointer to it
            self._call(self.fmu.instantiate, callbacks=self._callbacks)
        else:
            ref = weakref.ref(self)

            def log3(env: Any, status: int, category: Any, message: Any) -> None:
                unit = ref()
                if unit is not None:
                    unit._log(status, category, message)

            self._callbacks = log3                # fmpy keeps it as fmu.logMessage too
            self._call(self.fmu.instantiate, logMessage=log3)

    def terminate(self) -> None:
        if self.fmu is None:
            return
        try:
            self.fmu.terminate()
        except Exception:  # noqa: BLE001 - best effort on shutdown
            pass
        try:
            self.fmu.freeInstance()
        except Exception:  # noqa: BLE001
            pass
        self.fmu = None
        _FMI2_UNITS.pop(getattr(self, "_fmi2_id", -1), None)


class CoSimUnit(_Unit):
    """A Co-Simulation FMU instance stepped by its own solver."""

    interface = "cs"

    def setup(self, start: float, stop: float, parameters: dict[str, float],
              inputs: np.ndarray, tolerance: float | None = None) -> None:
        self._instantiate(slave=True)
        fmu = self.fmu
        self.time = start
        if self.info.fmi_version == 2:
            self._call(fmu.setupExperiment, tolerance, start, stop)
            self.set_real(parameters)
            self.set_inputs(inputs)
            self._call(fmu.enterInitializationMode)
        else:
            self.set_real(parameters)
            self.set_inputs(inputs)
            self._call(fmu.enterInitializationMode, tolerance, start, stop)
        self._call(fmu.exitInitializationMode)

    def step(self, t: float, h: float, u0: np.ndarray, slope: np.ndarray | None = None) -> None:
        """Advance from ``t`` to ``t + h`` with the inputs ``u0 + slope (s - t)``, held at
        their mean over the step (``u0 + slope h / 2``)."""
        u = u0 if slope is None else u0 + 0.5 * h * slope
        self.set_inputs(u)
        self.time = t
        self._call(self.fmu.doStep, t, h)
        self.time = t + h


class ModelExchangeUnit(_Unit):
    """A Model Exchange FMU instance integrated by the master (SciPy Radau)."""

    interface = "me"

    def __init__(self, *args: Any, rtol: float = 1e-8, atol: float = 1e-10, **kw: Any) -> None:
        super().__init__(*args, **kw)
        self.rtol = rtol
        self.atol = atol
        self.nx = self.info.n_states
        self.x = np.zeros(self.nx)
        self.dx = np.zeros(self.nx)
        self._h_last: float | None = None
        self.n_rhs = 0

    def setup(self, start: float, stop: float, parameters: dict[str, float],
              inputs: np.ndarray, tolerance: float | None = None) -> None:
        self._instantiate(slave=False)
        fmu = self.fmu
        self.time = start
        if self.info.fmi_version == 2:
            self._call(fmu.setupExperiment, tolerance, start, stop)
            self.set_real(parameters)
            self.set_inputs(inputs)
            self._call(fmu.enterInitializationMode)
            self._call(fmu.exitInitializationMode)
            while True:   # event iteration at the initial time
                if not self._call(fmu.newDiscreteStates)[0]:
                    break
            self._call(fmu.enterContinuousTimeMode)
        else:
            self.set_real(parameters)
            self.set_inputs(inputs)
            self._call(fmu.enterInitializationMode, tolerance, start, stop)
            self._call(fmu.exitInitializationMode)
            while True:
                res = self._call(fmu.updateDiscreteStates)
                if not res[0]:
                    break
            self._call(fmu.enterContinuousTimeMode)
        self._get_states()

    def _ptr(self, arr: np.ndarray) -> Any:
        return arr.ctypes.data_as(ctypes.POINTER(ctypes.c_double))

    def _get_states(self) -> None:
        if self.nx == 0:
            return
        self._call(self.fmu.getContinuousStates, self._ptr(self.x), self.nx)

    def _set_state(self, t: float, x: np.ndarray) -> None:
        self.fmu.setTime(t)
        if self.nx:
            xs = np.ascontiguousarray(x, dtype=float)
            self.fmu.setContinuousStates(self._ptr(xs), self.nx)

    def _rhs(self, t: float, x: np.ndarray, u0: np.ndarray, slope: np.ndarray | None,
             t0: float) -> np.ndarray:
        self._set_state(t, x)
        self._set(self._u_vr, u0 if slope is None else u0 + slope * (t - t0))
        out = np.empty(self.nx)
        if self.info.fmi_version == 2:
            self.fmu.getDerivatives(self._ptr(out), self.nx)
        else:
            self.fmu.getContinuousStateDerivatives(self._ptr(out), self.nx)
        self.n_rhs += 1
        return out

    def step(self, t: float, h: float, u0: np.ndarray, slope: np.ndarray | None = None) -> None:
        """Integrate from ``t`` to ``t + h`` with the inputs ``u0 + slope (s - t)``."""
        from scipy.integrate import solve_ivp

        self.time = t
        if self.nx and h > 0:
            first = None if self._h_last is None else min(self._h_last, h)
            try:
                sol = solve_ivp(self._rhs, (t, t + h), self.x, method="Radau",
                                rtol=self.rtol, atol=self.atol, args=(u0, slope, t),
                                first_step=first)
            except CosimStepError:
                raise
            except Exception as err:
                said = self.fmu_errors()[-1:]
                detail = f"{err}" + (f" -- the FMU says: {said[0]}" if said else "")
                raise CosimStepError(f"element {self.name!r}: integration failed at t={t:g}: "
                                     f"{_one_line(detail, 600)}", self.name, t) from err
            if not sol.success:
                raise CosimStepError(f"element {self.name!r}: integration failed at t={t:g}: "
                                     f"{sol.message}", self.name, t)
            self.x = np.array(sol.y[:, -1])
            steps = np.diff(sol.t)
            if len(steps):
                self._h_last = float(steps[-1]) if len(steps) == 1 else float(
                    max(steps[-1], steps[-2]))
        self._call(self._set_state, t + h, self.x)
        end_inputs = u0 if slope is None else u0 + slope * h
        self.set_inputs(end_inputs)
        self.time = t + h
        if not all(math.isfinite(v) for v in self.x):
            raise CosimStepError(f"element {self.name!r}: states not finite at t={t + h:g}",
                                 self.name, t + h)


def make_unit(name: str, info: FmuInfo, interface: str, input_names: list[str],
              output_names: list[str], *, rtol: float = 1e-8, atol: float = 1e-10) -> _Unit:
    """A :class:`CoSimUnit` (``interface="cs"``) or :class:`ModelExchangeUnit` (``"me"``)."""
    if interface == "cs":
        return CoSimUnit(name, info, input_names, output_names)
    if interface == "me":
        return ModelExchangeUnit(name, info, input_names, output_names, rtol=rtol, atol=atol)
    raise SetupError(f"element {name!r}: interface must be 'cs' or 'me', not {interface!r}")
