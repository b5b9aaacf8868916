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
"""

from __future__ import annotations

import atexit
import ctypes
import math
import shutil
import tempfile
import zipfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .errors import CosimStepError, SetupError

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
            raise SetupError(f"{where} has no variable {name!r}") from None


def read_fmu_info(path: str | Path) -> FmuInfo:
    """Read ``modelDescription.xml`` of the FMU at ``path``."""
    from fmpy import read_model_description

    path = Path(path)
    if not path.is_file():
        raise SetupError(f"FMU {path} does not exist")
    try:
        md = read_model_description(str(path))
    except Exception as err:  # fmpy raises various errors for broken archives
        raise SetupError(f"cannot read the model description of {path}: {err}") from err
    version = int(str(md.fmiVersion).split(".")[0])
    variables: dict[str, FmuVariable] = {}
    for v in md.modelVariables:
        start = None
        if v.start is not None and _kind_of_type(v.type) == "Real":
            try:
                start = float(v.start)
            except (TypeError, ValueError):
                start = None
        variables[v.name] = FmuVariable(v.name, int(v.valueReference), str(v.causality),
                                        str(v.variability), _kind_of_type(v.type),
                                        v.unit or (v.declaredType.unit if v.declaredType
                                                   is not None and getattr(
                                                       v.declaredType, "unit", None)
                                                   else "") or "",
                                        start, v.description or "")
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
    """Unzip each FMU once per process (shared by the instances of one FMU)."""

    def __init__(self) -> None:
        self.dirs: dict[tuple[Path, int, int], Path] = {}
        self.root: Path | None = None

    def get(self, path: Path) -> Path:
        path = path.resolve()
        st = path.stat()
        key = (path, st.st_mtime_ns, st.st_size)     # a rebuilt FMU is unzipped again
        if key not in self.dirs:
            if self.root is None:
                self.root = Path(tempfile.mkdtemp(prefix="bgm_cosim_"))
            target = self.root / f"{len(self.dirs):02d}_{path.stem}"
            with zipfile.ZipFile(path) as zf:
                zf.extractall(target)
            self.dirs[key] = target
        return self.dirs[key]

    def cleanup(self) -> None:
        if self.root is not None:
            shutil.rmtree(self.root, ignore_errors=True)
        self.dirs.clear()
        self.root = None


_EXTRACTED = _Extracted()
atexit.register(_EXTRACTED.cleanup)


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

    def _call(self, fn: Any, *args: Any) -> Any:
        try:
            return fn(*args)
        except CosimStepError:
            raise
        except Exception as err:
            raise CosimStepError(f"element {self.name!r} ({self.info.path.name}): FMU call "
                                 f"failed at t={self.time:g}: {err}", self.name,
                                 self.time) from err

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
            self.fmu = cls(guid=self.info.guid, **kw)
        elif self.info.fmi_version == 3:
            cls = fmi3.FMU3Slave if slave else fmi3.FMU3Model
            self.fmu = cls(guid=self.info.guid, **kw)   # fmpy: the token is passed as guid
        else:
            raise SetupError(f"element {self.name!r}: FMI {self.info.fmi_version} is not "
                             "supported (FMI 2.0 and 3.0 are)")
        self._call(self.fmu.instantiate)

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
                raise CosimStepError(f"element {self.name!r}: integration failed at t={t:g}: "
                                     f"{err}", self.name, t) from err
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
