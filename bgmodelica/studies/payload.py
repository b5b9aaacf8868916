"""What a Dask worker receives to run a model many times: a :class:`ModelPayload`.

The compiled model travels once per worker, never once per run, and is never recompiled:

* a :class:`~bgmodelica.compiler.CompiledModel` is pickled as it is, CasADi SX graphs
  included (under ``casadi.global_pickle_context()``, which keeps the symbols shared between
  the DAE's expressions), without the component tree it came from and without the CasADi
  functions cached by earlier runs. A worker unpickles it once (a few ms for the robot: the
  pickle is about 400 kB) and keeps it in :data:`_CACHE`, keyed by the payload's token, so
  its integrators are built once and reused by every later run of the same settings;
* when the compiled model cannot be pickled (a CasADi build without serialization), a
  payload made with a model reference (``"library.robots:RobotPID"``) and its constructor
  arguments compiles the model once per worker instead and caches it the same way;
* an FMU (exported or foreign) travels as the bytes of its archive, unpacked once per worker.

Runs on one worker are serialized by a lock per model: the CasADi functions of a compiled
model are not safe to call from two threads at once (start ``dask worker --nthreads 1`` and
more processes rather than more threads).
"""

from __future__ import annotations

import hashlib
import pickle
import threading
import time
from collections import OrderedDict
from dataclasses import replace
from pathlib import Path
from typing import Any

#: token -> (kind, object, lock): models unpacked in this process (a worker's, or ours)
_CACHE: OrderedDict[str, tuple[str, Any, threading.Lock]] = OrderedDict()
_CACHE_LOCK = threading.Lock()
_CACHE_SIZE = 4
#: how each model of :data:`_CACHE` was obtained and at what cost [s] (for benchmarks)
STATS: dict[str, dict[str, Any]] = {}


def pickle_compiled(compiled: Any) -> bytes:
    """The bytes of ``compiled`` without its source component and cached CasADi functions."""
    import casadi as ca

    lean = replace(compiled, source=None, dae=replace(compiled.dae, cache={}))
    with ca.global_pickle_context():
        return pickle.dumps(lean, protocol=pickle.HIGHEST_PROTOCOL)


def unpickle_compiled(blob: bytes) -> Any:
    import casadi as ca

    with ca.global_unpickle_context():
        return pickle.loads(blob)


class ModelPayload:
    """A model as shipped to workers: ``kind`` is ``"compiled"`` (pickled CompiledModel),
    ``"reference"`` (``ref`` + ``kwargs``, compiled once per worker) or ``"fmu"`` (archive
    bytes). :meth:`get` returns the ready model (a CompiledModel or an :class:`FmuModel`)
    and the lock to hold while running it."""

    def __init__(self, kind: str, token: str, name: str, blob: bytes | None = None,
                 ref: str | None = None, kwargs: dict[str, Any] | None = None,
                 units: str = "error") -> None:
        self.kind, self.token, self.name = kind, token, name
        self.blob, self.ref, self.kwargs, self.units = blob, ref, dict(kwargs or {}), units
        self._local: Any = None          # the live model in the process that made it

    def __reduce__(self):
        return (_rebuild, (self.kind, self.token, self.name, self.blob, self.ref,
                           self.kwargs, self.units))

    @property
    def size(self) -> int:
        """Bytes shipped to each worker."""
        return len(self.blob) if self.blob is not None else len(repr((self.ref, self.kwargs)))

    def get(self) -> tuple[Any, threading.Lock]:
        with _CACHE_LOCK:
            hit = _CACHE.get(self.token)
            if hit is not None:
                _CACHE.move_to_end(self.token)
                return hit[1], hit[2]
        t0 = time.perf_counter()
        if self._local is not None:
            model, how = self._local, "in process"
        elif self.kind == "compiled":
            model, how = unpickle_compiled(self.blob), "unpickled"
        elif self.kind == "reference":
            from ..compiler import compile as compile_model
            from ..loader import load_model

            model = compile_model(load_model(self.ref, **self.kwargs), units=self.units)
            how = "compiled on the worker"
        elif self.kind == "fmu":
            model, how = FmuModel.from_bytes(self.blob, self.name, self.token), "unpacked"
        else:  # pragma: no cover - constructed only here
            raise ValueError(f"unknown payload kind {self.kind!r}")
        with _CACHE_LOCK:
            if self.token not in _CACHE:
                _CACHE[self.token] = (self.kind, model, threading.Lock())
                STATS[self.token] = {"how": how, "seconds": time.perf_counter() - t0}
                while len(_CACHE) > _CACHE_SIZE:
                    _CACHE.popitem(last=False)
            return _CACHE[self.token][1], _CACHE[self.token][2]


def _rebuild(kind, token, name, blob, ref, kwargs, units) -> ModelPayload:
    return ModelPayload(kind, token, name, blob, ref, kwargs, units)


def payload_for(model: Any, *, ref: str | None = None, kwargs: dict[str, Any] | None = None,
                units: str = "error", mode: str = "auto") -> ModelPayload:
    """The payload of ``model``: a CompiledModel, a Component (compiled here, once), a MODEL
    reference (``"package.module:Name"``, loaded with ``kwargs``) or the path of an ``.fmu``.
    ``ref``/``kwargs``: the model reference it was loaded from, used when ``mode="reference"`` or
    when pickling fails (``mode="auto"``); ``mode="pickle"``
    insists on pickling."""
    from ..compiler import CompiledModel
    from ..compiler import compile as compile_model
    from ..core.component import Component

    if isinstance(model, (str, Path)) and str(model).lower().endswith(".fmu"):
        data = Path(model).read_bytes()
        token = "fmu-" + hashlib.sha1(data).hexdigest()
        payload = ModelPayload("fmu", token, Path(model).stem, blob=data)
        return payload
    if isinstance(model, str):                  # a MODEL reference: workers can load it too
        from ..loader import load_model

        ref, kwargs = model, dict(kwargs or {})
        model = load_model(ref, **kwargs)
    if isinstance(model, Component):
        model = compile_model(model, units=units)
    if not isinstance(model, CompiledModel):
        raise TypeError(f"expected a CompiledModel, a Component or an .fmu path, got "
                        f"{type(model).__name__}")
    blob = None
    if mode in ("auto", "pickle"):
        try:
            blob = pickle_compiled(model)
        except Exception as err:  # noqa: BLE001 -- fall back to the reference when we can
            if mode == "pickle" or ref is None:
                from ..errors import ModelError

                raise ModelError(f"the compiled model {model.name} cannot be pickled for the "
                                 f"workers ({type(err).__name__}: {err}); pass the model "
                                 "reference (ref='package.module:Name') so that each worker "
                                 "compiles it once") from None
    if blob is not None:
        token = "cm-" + hashlib.sha1(blob).hexdigest()
        payload = ModelPayload("compiled", token, model.name, blob=blob)
    else:
        if ref is None:
            raise ValueError("mode='reference' needs ref='package.module:Name'")
        key = repr((ref, sorted((kwargs or {}).items()), units)).encode()
        token = "ref-" + hashlib.sha1(key).hexdigest()
        payload = ModelPayload("reference", token, model.name, ref=ref, kwargs=kwargs,
                               units=units)
    payload._local = model           # this process runs the model it already has
    return payload


class FmuModel:
    """An FMU unpacked once in this process, run with fmpy (Co-Simulation if the FMU offers
    it, else Model Exchange with fmpy's CVode)."""

    def __init__(self, path: Path, unzipdir: str, name: str) -> None:
        from fmpy import read_model_description

        self.path, self.unzipdir, self.name = path, unzipdir, name
        self.description = read_model_description(str(path))
        md = self.description
        self.kind = "CoSimulation" if md.coSimulation is not None else "ModelExchange"
        self.variables = {v.name: v for v in md.modelVariables}
        units = {}
        for v in md.modelVariables:
            unit = getattr(v, "unit", None) or getattr(getattr(v, "declaredType", None),
                                                       "unit", None)
            units[v.name] = unit or ""
        self.units = units

    @classmethod
    def from_bytes(cls, data: bytes, name: str, token: str) -> FmuModel:
        import atexit
        import shutil
        import tempfile

        from fmpy import extract

        folder = Path(tempfile.mkdtemp(prefix="bgmodelica-fmu-"))
        atexit.register(shutil.rmtree, folder, True)
        path = folder / f"{name}.fmu"
        path.write_bytes(data)
        return cls(path, extract(str(path), unzipdir=str(folder / "x")), name)

    def default(self, name: str) -> float:
        v = self.variables.get(name)
        if v is None:
            from ..errors import ParameterError

            raise ParameterError(f"{name!r} is not a variable of the FMU {self.name}")
        if v.start is None:
            from ..errors import ParameterError

            raise ParameterError(f"{name!r} of the FMU {self.name} has no start value")
        return float(v.start)

    def names(self) -> list[str]:
        return list(self.variables)

    def default_outputs(self) -> list[str]:
        outs = [v.name for v in self.description.modelVariables if v.causality == "output"]
        if outs:
            return outs
        return [v.name for v in self.description.modelVariables
                if v.causality == "local" and v.variability == "continuous"][:20]

    def simulate(self, grid, params: dict[str, float], outputs: list[str], rtol: float):
        """Values of ``outputs`` on ``grid`` (interpolated linearly where the FMU's output
        points differ from it), shape (len(grid), len(outputs))."""
        import numpy as np
        from fmpy import simulate_fmu

        missing = [n for n in list(outputs) + list(params) if n not in self.variables]
        if missing:
            from ..errors import ParameterError

            raise ParameterError(f"{missing[0]!r} is not a variable of the FMU {self.name}")
        interval = float(grid[1] - grid[0]) if len(grid) > 1 else None
        res = simulate_fmu(self.unzipdir, validate=False, fmi_type=self.kind,
                           start_time=float(grid[0]), stop_time=float(grid[-1]),
                           output_interval=interval, relative_tolerance=rtol,
                           start_values=dict(params), output=list(outputs),
                           model_description=self.description)
        t = np.asarray(res["time"], dtype=float)
        cols = []
        for name in outputs:
            y = np.asarray(res[name], dtype=float)
            same = len(t) == len(grid) and np.allclose(t, grid, rtol=0, atol=1e-12)
            cols.append(y if same else np.interp(grid, t, y))
        return np.column_stack(cols) if cols else np.zeros((len(grid), 0))
