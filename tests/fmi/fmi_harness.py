"""Low-level access to exported FMUs through fmpy's FMU2/FMU3 classes, capturing log messages."""

from __future__ import annotations

import atexit
import shutil
import tempfile
from ctypes import byref
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fmpy import calloc, extract, free, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (
    FMU2Model,
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)
from fmpy.fmi3 import FMU3Model, FMU3Slave
from fmpy.logging import addLoggerProxy

__all__ = ["FMICallException", "Opened", "open_fmu"]

_UNZIPPED: dict[str, str] = {}


@dataclass
class Opened:
    fmu: Any
    md: Any
    version: int
    kind: str
    messages: list[tuple[int, str, str]] = field(default_factory=list)
    _keep: Any = None

    def vr(self, name: str) -> int:
        return next(v.valueReference for v in self.md.modelVariables if v.name == name)

    def errors(self) -> list[str]:
        return [m for status, _, m in self.messages if status >= 3]

    # version-independent helpers
    def get(self, names: list[str]) -> list[float]:
        vrs = [self.vr(n) for n in names]
        return self.fmu.getReal(vrs) if self.version == 2 else self.fmu.getFloat64(vrs)

    def set(self, values: dict[str, float]) -> None:
        vrs = [self.vr(n) for n in values]
        if self.version == 2:
            self.fmu.setReal(vrs, list(values.values()))
        else:
            self.fmu.setFloat64(vrs, list(values.values()))

    def initialize(self, start_time: float = 0.0, values: dict[str, float] | None = None,
                   exit_init: bool = True) -> None:
        if self.version == 2:
            self.fmu.setupExperiment(startTime=start_time)
            if values:
                self.set(values)
            self.fmu.enterInitializationMode()
        else:
            if values:
                self.set(values)
            self.fmu.enterInitializationMode(startTime=start_time)
        if exit_init:
            self.fmu.exitInitializationMode()

    def dir_der(self, unknowns: list[str], knowns: list[str], seed: list[float]) -> list[float]:
        u = [self.vr(n) for n in unknowns]
        k = [self.vr(n) for n in knowns]
        return list(self.fmu.getDirectionalDerivative(u, k, seed))

    def instantiate(self, logging_on: bool = False) -> None:
        if self.version == 2:
            def logger(env, name, status, category, message):
                self.messages.append((status, category.decode(), message.decode()))
            cb = fmi2CallbackFunctions()
            cb.logger = fmi2CallbackLoggerTYPE(logger)
            cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
            cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
            addLoggerProxy(byref(cb))
            self._keep = (cb, logger)
            self.fmu.instantiate(callbacks=cb, loggingOn=logging_on)
        else:
            def log3(env, status, category, message):
                self.messages.append((status, category.decode(), message.decode()))
            self._keep = log3
            self.fmu.instantiate(logMessage=log3, loggingOn=logging_on)

    def close(self) -> None:
        try:
            self.fmu.freeInstance()
        finally:
            self.fmu.freeLibrary()


def open_fmu(path: Path, kind: str, token: str | None = None, instantiate: bool = True,
             logging_on: bool = False) -> Opened:
    """Load an FMU with fmpy's low-level classes; ``kind`` is "me" or "cs"."""
    key = str(path)
    if key not in _UNZIPPED:
        target = tempfile.mkdtemp(prefix="bgm_fmu_test_")
        atexit.register(shutil.rmtree, target, True)
        _UNZIPPED[key] = extract(key, unzipdir=target)
    unzip = _UNZIPPED[key]
    md = read_model_description(unzip)
    version = 2 if md.fmiVersion == "2.0" else 3
    iface = md.modelExchange if kind == "me" else md.coSimulation
    ident = (iface or md.modelExchange or md.coSimulation).modelIdentifier
    cls = {(2, "me"): FMU2Model, (2, "cs"): FMU2Slave, (3, "me"): FMU3Model,
           (3, "cs"): FMU3Slave}[(version, kind)]
    fmu = cls(guid=token if token is not None else md.guid, unzipDirectory=unzip,
              modelIdentifier=ident, instanceName="test")
    opened = Opened(fmu, md, version, kind)

    if instantiate:
        opened.instantiate(logging_on)
    return opened
