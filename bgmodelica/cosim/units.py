"""FMU instances as co-simulation units, run through fmpy's low-level API.

Every unit offers the master the same small interface: ``setup`` (instantiate, set
parameters and start values, initialize), ``set_inputs``, ``get_outputs``, ``get``,
``step(t, h, u0, slope)`` and ``terminate``; ``terminated`` tells when the FMU asked to end
the simulation (FMI 2.0 ``Discard`` with ``fmi2Terminated``, FMI 3.0 ``terminateSimulation``).

* :class:`CoSimUnit` calls the FMU's own ``doStep`` (FMI 2.0 ``FMU2Slave`` / FMI 3.0
  ``FMU3Slave``); inputs are held over the step (a ramp given by the master is replaced by its
  mean over the step, which has the same integral). An FMI 3.0 early return ends the step at
  the FMU's ``lastSuccessfulTime``.
* :class:`~.me_unit.ModelExchangeUnit` integrates a Model Exchange FMU itself, with state,
  time and step events.

Inputs, outputs and parameters of every FMI type go through the FMI call of their own type
(:mod:`.values`). The units capture the FMU's log messages; when an FMU call fails, the
:class:`~.errors.CosimStepError` carries the FMU's own error message.
"""

from __future__ import annotations

import collections
import ctypes
import itertools
import weakref
from collections.abc import Mapping
from typing import Any

import numpy as np

from .archive import _one_line
from .errors import CosimStepError, SetupError
from .fmu import _EXTRACTED, FmuInfo
from .values import PortAccess, get_text, set_by_name, to_fmi

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
        self._in = PortAccess(info.fmi_version, [info.variables[n] for n in input_names])
        self._out = PortAccess(info.fmi_version, [info.variables[n] for n in output_names])
        self._u_vr = (ctypes.c_uint32 * len(input_names))(
            *[info.variables[n].vr for n in input_names])
        self._y_vr = (ctypes.c_uint32 * len(output_names))(
            *[info.variables[n].vr for n in output_names])
        self._y_buf = np.zeros(len(output_names))
        self._u_buf = np.zeros(len(input_names))
        self._y_ptr = self._y_buf.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
        self._u_ptr = self._u_buf.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
        self._raw: dict[str, Any] = {}        # the FMU's C functions (hot path, no wrapper)
        self._readers: dict[tuple[str, ...], PortAccess] = {}
        self.time = 0.0
        # (status, category, message) logged by the FMU; the last errors go into exceptions
        self.messages: collections.deque[tuple[int, str, str]] = collections.deque(maxlen=50)
        self._callbacks: Any = None
        self._n_logged = 0
        self.terminated = False     # the FMU asked to end the simulation
        self.stop_reason = ""

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

    def _set_inputs(self, values: np.ndarray) -> None:
        if self._in.all_real:
            self._set(self._u_vr, values)
        else:
            self._in.set(self.fmu, np.asarray(values, dtype=float))

    def set_inputs(self, values: np.ndarray) -> None:
        """Set all inputs (in ``input_names`` order), each with its own FMI type."""
        raw = self._raw.get("set")
        if raw is not None:                   # scalar reals: one C call, no wrapper
            n = len(self._u_buf)
            self._u_buf[:] = values
            status = raw(self.fmu.component, self._u_vr, n, self._u_ptr) if \
                self.info.fmi_version == 2 else raw(self.fmu.component, self._u_vr, n,
                                                    self._u_ptr, n)
            if status <= 1:
                return
        self._call(self._set_inputs, values)

    def _get_outputs(self) -> np.ndarray:
        if self._out.all_real:
            return self._get(self._y_vr, self._y_buf)
        return self._out.get(self.fmu, self._y_buf)

    def get_outputs(self) -> np.ndarray:
        """All outputs (in ``output_names`` order) as float64, a fresh array."""
        raw = self._raw.get("get")
        if raw is not None:
            n = len(self._y_buf)
            status = raw(self.fmu.component, self._y_vr, n, self._y_ptr) if \
                self.info.fmi_version == 2 else raw(self.fmu.component, self._y_vr, n,
                                                    self._y_ptr, n)
            if status <= 1:
                return self._y_buf.copy()
        return self._call(self._get_outputs).copy()

    def _bind_raw(self) -> None:
        """Keep the FMU's own C functions for the per-step calls on scalar reals."""
        functions = getattr(self.fmu, "_functions", {})
        if self.info.fmi_version == 2:
            names = {"set": "fmi2SetReal", "get": "fmi2GetReal", "step": "fmi2DoStep"}
        else:
            names = {"set": "fmi3SetFloat64", "get": "fmi3GetFloat64", "step": "fmi3DoStep"}
            # fmi3DoStep's results: eventHandlingNeeded, terminateSimulation, earlyReturn,
            # lastSuccessfulTime
            self._step3_out = (ctypes.c_bool(), ctypes.c_bool(), ctypes.c_bool(),
                               ctypes.c_double())
            self._step3_refs = tuple(ctypes.pointer(v) for v in self._step3_out)
        self._raw = {k: functions[v] for k, v in names.items() if v in functions}
        if not (self._in.all_real and len(self._u_buf)):
            self._raw.pop("set", None)
        if not (self._out.all_real and len(self._y_buf)):
            self._raw.pop("get", None)

    def get(self, names: list[str]) -> np.ndarray:
        """Values of any numeric or Boolean variables by name (locals, states, parameters,
        array elements ``x[2]``...) as float64."""
        key = tuple(names)
        reader = self._readers.get(key)
        if reader is None:
            variables = [self.info.variable(n, self.name) for n in names]
            try:
                reader = PortAccess(self.info.fmi_version, variables)
            except ValueError as err:
                raise SetupError(f"element {self.name!r}: {err}") from None
            self._readers[key] = reader
        return self._call(reader.get, self.fmu, np.zeros(len(names)))

    def get_text(self, names: list[str]) -> list[Any]:
        """Values of String (``str``) and Binary (``bytes``) variables by name."""
        variables = [self.info.variable(n, self.name) for n in names]
        return self._call(get_text, self.fmu, self.info.fmi_version, variables)

    def set_text(self, values: Mapping[str, Any]) -> None:
        """Set String/Binary inputs during the run (a Model Exchange unit at an event)."""
        self.set_values(values)

    def set_values(self, values: Mapping[str, Any]) -> None:
        """Set variables of any type by name (parameters, start values, tunable parameters;
        String and Binary ones included)."""
        if not values:
            return
        variables = [self.info.variable(n, self.name) for n in values]
        converted = []
        for v, x in zip(variables, values.values(), strict=True):
            try:
                converted.append(to_fmi(v.fmi_type or v.type, x,
                                        f"element {self.name!r}: {v.name}"))
            except (TypeError, ValueError) as err:
                raise SetupError(str(err)) from None
        self._call(set_by_name, self.fmu, self.info.fmi_version, variables, converted)

    set_real = set_values

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
            self._bind_raw()
        else:
            ref = weakref.ref(self)

            def log3(env: Any, status: int, category: Any, message: Any) -> None:
                unit = ref()
                if unit is not None:
                    unit._log(status, category, message)

            self._callbacks = log3                # fmpy keeps it as fmu.logMessage too
            self._call(self.fmu.instantiate, logMessage=log3)
            self._bind_raw()

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
        their mean over the step (``u0 + slope h / 2``). An FMI 3.0 early return resumes from
        the FMU's ``lastSuccessfulTime``; a terminate request ends the unit's run there."""
        u = u0 if slope is None else u0 + 0.5 * h * slope
        self.set_inputs(u)
        self.time = t
        if self.info.fmi_version == 2:
            self._step2(t, h)
        else:
            self._step3(t, h)

    def _step3(self, t: float, h: float) -> None:
        """``fmi3DoStep`` from ``t`` (``self.time``) to ``t + h``, resuming after early
        returns; a terminate request ends the unit's run (``terminated``)."""
        t_end = t + h
        raw = self._raw.get("step")
        for _ in range(100000):
            if raw is not None:                      # the C function, no wrapper
                status = raw(self.fmu.component, self.time, t_end - self.time, True,
                             *self._step3_refs)
                if status > 1:                       # Discard, Error, Fatal
                    from fmpy.fmi1 import FMICallException

                    self._call(self._raise, FMICallException(function="fmi3DoStep",
                                                             status=status))
                term, early, last = (v.value for v in self._step3_out[1:])
            else:
                _event, term, early, last = self._call(self.fmu.doStep, self.time,
                                                       t_end - self.time)
            if term:
                self.time = float(last) if early else t_end
                self.terminated = True
                self.stop_reason = "the FMU asked to terminate the simulation (doStep)"
                return
            if not early or not float(last) < t_end:
                self.time = t_end
                return
            self.time = max(float(last), self.time)
        raise CosimStepError(f"element {self.name!r}: more than 100000 early returns in the "
                             f"step at t={t:g}", self.name, self.time)

    def _step2(self, t: float, h: float) -> None:
        from fmpy.fmi1 import FMICallException

        raw = self._raw.get("step")
        if raw is not None:                          # the C function, no wrapper
            status = raw(self.fmu.component, t, h, 1)
            if status <= 1:                          # fmi2OK, fmi2Warning
                self.time = t + h
                return
            self.step_failed(FMICallException(function="fmi2DoStep", status=status), t)
            return
        try:
            self.fmu.doStep(t, h)
            self.time = t + h
        except FMICallException as exc:
            self.step_failed(exc, t)

    def step_failed(self, err: Any, t: float) -> None:
        """After ``fmi2DoStep`` from ``t`` returned ``err.status`` > Warning: a Discard with
        ``fmi2Terminated`` ends this unit's run (``terminated``), anything else raises
        :class:`~.errors.CosimStepError` with the FMU's messages."""
        if err.status == 2 and self._fmi2_terminated():          # fmi2Discard
            self.terminated = True
            self.stop_reason = "the FMU asked to terminate the simulation (doStep " \
                               "returned Discard, fmi2Terminated)"
            try:
                self.time = float(self.fmu.getRealStatus(2))      # fmi2LastSuccessfulTime
            except Exception:  # noqa: BLE001 - optional status
                self.time = t
            return
        self._call(self._raise, err)

    @staticmethod
    def _raise(err: Exception) -> None:
        raise err

    def _fmi2_terminated(self) -> bool:
        try:
            return bool(self.fmu.getBooleanStatus(3))               # fmi2Terminated
        except Exception:  # noqa: BLE001 - the status is optional
            return False


def make_unit(name: str, info: FmuInfo, interface: str, input_names: list[str],
              output_names: list[str], *, rtol: float = 1e-8, atol: float = 1e-10,
              euler_step: float | None = None) -> _Unit:
    """A :class:`CoSimUnit` (``interface="cs"``) or :class:`ModelExchangeUnit` (``"me"``;
    ``euler_step``: forward Euler at that step instead of Radau)."""
    if interface == "cs":
        return CoSimUnit(name, info, input_names, output_names)
    if interface == "me":
        from .me_unit import ModelExchangeUnit

        return ModelExchangeUnit(name, info, input_names, output_names, rtol=rtol, atol=atol,
                                 euler_step=euler_step)
    raise SetupError(f"element {name!r}: interface must be 'cs' or 'me', not {interface!r}")
