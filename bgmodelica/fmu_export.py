"""``bgmodelica.export_fmu``: a model (component, compiled model or MODEL reference) to an
``.fmu`` in one call, as ``bgmodelica export`` does it."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from .errors import OptionError

_TYPES = {"me": "me", "cs": "cs", "both": "both", "me+cs": "both"}


def export_fmu(model: Any, folder: str | Path = ".", fmi_version: str | int = "2.0",
               fmi_type: str = "ME", *, stop_time: float | None = None,
               step_size: float | None = None, tolerance: float | None = None,
               static_states: bool = False,
               units: str = "error") -> Path:
    """Export ``model`` as ``<folder>/<model name>.fmu`` and return its path.

    model: a :class:`~bgmodelica.Component`, a :class:`~bgmodelica.CompiledModel` or a MODEL
    reference as on the command line (``"library.examples:RC"``, ``"file.py:Name"``,
    ``"file.mo:Package.Model"``). fmi_version: ``"2.0"`` or ``"3.0"`` (2 and 3 too). fmi_type:
    ``"ME"`` (Model Exchange), ``"CS"`` (Co-Simulation with the embedded BDF solver) or ``"both"``.
    stop_time [s], step_size [s] (optional) and tolerance: the default experiment written into
    ``modelDescription.xml`` (and the CS solver's tolerance); left None, the model's experiment
    annotation gives them (else 1 s and 1e-6). static_states: export a model whose
    state choice could change during a simulation anyway (see
    :func:`bgmodelica.fmi.from_model.fmu_spec`). units: the unit check when ``model`` is compiled
    here. The folder is made if missing.
    """
    version = _version(fmi_version)
    kind = _TYPES.get(str(fmi_type).strip().lower())
    if kind is None:
        raise OptionError(f"fmi_type={fmi_type!r}: expected 'ME', 'CS' or 'both'")
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise OptionError(f"folder {folder}: is a file; FMUs are written into a directory")
    from .compiler import CompiledModel, compile
    from .fmi.from_model import export_model

    compiled = model if isinstance(model, CompiledModel) else compile(model, units=units)
    return export_model(compiled, folder, fmi_version=version, fmu_type=kind,
                        stop_time=stop_time, step_size=step_size, tolerance=tolerance,
                        static_states=static_states)


def _version(value: str | int) -> int:
    text = str(value).strip()
    for major in (2, 3):
        if text in (str(major), f"{major}.0"):
            return major
    raise OptionError(f"fmi_version={value!r}: expected '2.0' or '3.0'")
