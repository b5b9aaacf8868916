"""Cross-check of the master with an independent one: ``fmucontainer`` (FMU Manipulation
Toolbox) packs the same FMUs and connections into a *container FMU* whose C runtime steps the
embedded FMUs with a fixed step; fmpy runs that container.

The container's scheduling is the textbook one: *parallel* mode sets every input from the
outputs read after the previous step, steps all FMUs, reads all outputs (Jacobi); *sequential*
mode does set-inputs / step / read-outputs FMU by FMU in the declared order (Gauss-Seidel).
Inputs are held over the step and outputs are read right after ``doStep``; so our master
reproduces it with ``propagate=False`` and no extrapolation (:func:`cross_check`).

:func:`container_description` writes the system as an ``fmucontainer`` JSON description
(FMU instances, links, the unlinked outputs exposed as container outputs
``<element>.<output>`` -- linked ones are the container's locals of that name --, the SSP
parameter bindings as start values); the SSP file itself
can be given to ``fmucontainer`` too, but its SSP reader ignores parameter bindings.
"""

from __future__ import annotations

import contextlib
import ctypes
import json
import logging
import os
import shutil
import sys
import tempfile
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from ..result import Result
from .errors import CosimError, SetupError
from .fmu import read_fmu_info
from .master import Master, _norm_order
from .ssp import SystemStructure


@contextlib.contextmanager
def quiet_c_output() -> Iterator[None]:
    """Silence what native code prints on file descriptors 1 and 2 (the container runtime
    logs its mode and warnings with printf)."""
    try:
        libc = ctypes.CDLL(None)
    except OSError:          # no C runtime handle (unusual platform): do not redirect
        yield
        return
    sys.stdout.flush()
    sys.stderr.flush()
    libc.fflush(None)
    saved = [os.dup(1), os.dup(2)]
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        os.dup2(devnull, 2)
        yield
    finally:
        libc.fflush(None)
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in (*saved, devnull):
            os.close(fd)


def _instance(name: str) -> str:
    return f"{name}.fmu"


def container_description(system: SystemStructure, path: str | Path, *, step_size: float,
                          order: str = "jacobi",
                          parameters: Mapping[str, Mapping[str, float]] | None = None,
                          fmu_dir: str | Path | None = None) -> Path:
    """Write ``system`` as an ``fmucontainer`` JSON description at ``path``.

    FMU files are referenced relative to ``fmu_dir`` (default: the JSON's directory, which
    is the ``-fmu-directory`` to give ``fmucontainer``). ``order`` ``"gauss-seidel"`` sets
    the container's sequential mode (FMUs in the element order of the system).
    ``parameters`` adds start values on top of the SSP bindings.
    """
    path = Path(path)
    base = Path(fmu_dir) if fmu_dir is not None else path.parent
    base.mkdir(parents=True, exist_ok=True)
    seq = _norm_order(order) == "gauss-seidel"
    fmus, paths, starts, outputs = [], {}, [], []
    for comp in system.elements:
        if comp.fmu_path is None:
            raise SetupError(f"element {comp.name!r}: FMU file unknown")
        inst = _instance(comp.name)
        fmus.append(inst)
        paths[inst] = Path(os.path.relpath(Path(comp.fmu_path).resolve(),
                                           base.resolve())).as_posix()
        values = dict(comp.parameters)
        values.update((parameters or {}).get(comp.name, {}))
        starts += [[inst, k, repr(float(v))] for k, v in values.items()]
        info = read_fmu_info(comp.fmu_path)
        linked = {c.start_connector for c in system.connections
                  if c.start_element == comp.name}
        # linked outputs are visible as the container's locals "<element>.<output>" already
        outputs += [[inst, v.name, f"{comp.name}.{v.name}"] for v in info.outputs
                    if v.name not in linked]
    links = [[_instance(c.start_element), c.start_connector, _instance(c.end_element),
              c.end_connector] for c in system.connections]
    data: dict[str, Any] = {
        "name": f"{system.name}_container.fmu", "mt": False, "profiling": False,
        "sequential": seq, "auto_link": False, "auto_input": False, "auto_output": False,
        "auto_parameter": False, "auto_local": False, "step_size": float(step_size),
        "fmu": fmus, "path": paths, "link": links, "output": outputs, "start": starts,
    }
    path.write_text(json.dumps(data, indent=2) + "\n")
    return path


def build_container(system: SystemStructure, out_dir: str | Path, *, step_size: float,
                    order: str = "jacobi",
                    parameters: Mapping[str, Mapping[str, float]] | None = None) -> Path:
    """Build the container FMU of ``system`` with ``fmucontainer`` (Python API) in
    ``out_dir`` (the FMUs are copied there); returns its path."""
    try:
        from fmu_manipulation_toolbox.assembly import Assembly
    except ImportError as err:
        raise CosimError("the cross-check needs fmu-manipulation-toolbox "
                         "(pip install fmu-manipulation-toolbox)") from err
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    copies: dict[Path, Path] = {}
    local = SystemStructure(system.name, [], list(system.connections), system.start_time,
                            system.stop_time, system.description, dict(system.master))
    for comp in system.elements:
        src = Path(comp.fmu_path).resolve()
        if src not in copies:
            dst = out / src.name
            if dst.resolve() != src:
                shutil.copyfile(src, dst)
            copies[src] = dst
        local.elements.append(replace(comp, fmu_path=copies[src]))
    desc = container_description(local, out / f"{system.name}_container.json",
                                 step_size=step_size, order=order, parameters=parameters)
    logging.getLogger("fmu_manipulation_toolbox").setLevel(logging.ERROR)
    try:
        with quiet_c_output():
            assembly = Assembly(desc.name, fmu_directory=out, default_auto_input=False,
                                default_auto_output=False, default_auto_link=False)
            assembly.make_fmu(fmi_version=2)
    except Exception as err:
        raise CosimError(f"fmucontainer could not build the container: {err}") from err
    fmu = out / f"{system.name}_container.fmu"
    if not fmu.is_file():
        raise CosimError(f"fmucontainer did not produce {fmu}")
    return fmu


def run_container(fmu: str | Path, stop_time: float, step_size: float,
                  start_time: float = 0.0) -> Result:
    """Simulate a (container) Co-Simulation FMU with fmpy, one ``doStep`` per ``step_size``;
    all outputs, as a :class:`~bgmodelica.Result`."""
    from fmpy import simulate_fmu

    info = read_fmu_info(fmu)
    wanted = [v.name for v in info.variables.values()
              if v.causality in ("output", "local") and v.type == "Real" and "." in v.name]
    with quiet_c_output():
        res = simulate_fmu(str(fmu), start_time=start_time, stop_time=stop_time,
                           output_interval=step_size, fmi_type="CoSimulation", output=wanted)
    names = [n for n in res.dtype.names if n != "time"]
    data = np.column_stack([res[n] for n in names]) if names else np.zeros((len(res), 0))
    return Result(np.asarray(res["time"], dtype=float), data.astype(float), names,
                  meta={"master": "fmucontainer"})


@dataclass
class CrossCheck:
    """Our master against ``fmucontainer`` on the same FMUs, step and order."""

    order: str
    step: float
    stop_time: float
    max_abs_diff: dict[str, float] = field(default_factory=dict)
    points: int = 0
    container_fmu: str = ""

    @property
    def worst(self) -> tuple[str, float]:
        if not self.max_abs_diff:
            return ("", 0.0)
        name = max(self.max_abs_diff, key=self.max_abs_diff.get)
        return name, self.max_abs_diff[name]

    def to_dict(self) -> dict[str, Any]:
        name, diff = self.worst
        return {"order": self.order, "step": self.step, "stop_time": self.stop_time,
                "points": self.points, "worst": name, "worst_abs_diff": diff,
                "max_abs_diff": dict(self.max_abs_diff)}


def cross_check(system: SystemStructure, *, stop_time: float, step: float,
                order: str = "jacobi",
                parameters: Mapping[str, Mapping[str, float]] | None = None,
                work_dir: str | Path | None = None) -> CrossCheck:
    """Run ``system`` with our master (``propagate=False``, no extrapolation, Co-Simulation
    FMUs) and in an ``fmucontainer`` container with the same step and order; return the
    largest absolute difference per output (``<element>.<output>``)."""
    order = _norm_order(order)
    tmp = None
    if work_dir is None:
        tmp = tempfile.mkdtemp(prefix="bgm_xcheck_")
        work_dir = tmp
    try:
        fmu = build_container(system, Path(work_dir) / order, step_size=step, order=order,
                              parameters=parameters)
        theirs = run_container(fmu, stop_time, step, system.start_time)
        ours = Master(system, interface="cs").simulate(
            stop_time, step, order=order, extrapolation=False, propagate=False,
            parameters=parameters)
        n = min(len(ours.time), len(theirs.time))
        if n < 2 or np.max(np.abs(ours.time[:n] - theirs.time[:n])) > 1e-9 * max(1, stop_time):
            raise CosimError("the two masters did not produce the same communication points")
        diffs = {}
        for name in theirs.names:
            if name in ours.names:
                diffs[name] = float(np.max(np.abs(ours[name][:n] - theirs[name][:n])))
        return CrossCheck(order, step, stop_time, diffs, n, str(fmu))
    finally:
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)
