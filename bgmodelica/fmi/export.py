"""``export_fmu``: FmuSpec -> ``<model_name>.fmu`` (FMI 2.0 / 3.0, ME / CS / both)."""

from __future__ import annotations

import hashlib
import shutil
import tempfile
from pathlib import Path

from . import codegen
from .build import compile_shared_library, platform_dir, zip_fmu
from .csources import TEMPLATES, c_files, model_data_sources, write_runtime
from .model_description import (
    build_description_xml,
    instantiation_token,
    model_description_xml,
)
from .spec import FmuSpec, FmuSpecError
from .variables import build_table

FMU_TYPES = {"me": ("me",), "cs": ("cs",), "both": ("me", "cs")}


def _runtime_digest() -> str:
    h = hashlib.sha256()
    for p in sorted(TEMPLATES.iterdir()):
        if p.is_file():
            h.update(p.name.encode())
            h.update(p.read_bytes())
    return h.hexdigest()


def export_fmu(spec: FmuSpec, out_dir: str | Path, fmi_version: int = 2,
               fmu_type: str = "me", *, compiler: str | None = None) -> Path:
    """Export ``spec`` as an FMU and return the path of ``<out_dir>/<model_name>.fmu``.

    ``fmi_version`` is 2 or 3; ``fmu_type`` is ``"me"`` (Model Exchange), ``"cs"``
    (Co-Simulation with the embedded BDF solver) or ``"both"`` (one binary, both
    interfaces).  ``compiler`` overrides the C compiler (default: ``$CC``, ``cc``, ``gcc``,
    ``clang``).  Raises :class:`~bgmodelica.fmi.spec.FmuSpecError` for an inconsistent spec
    and :class:`~bgmodelica.fmi.build.FmuBuildError` when the binary cannot be built.
    """
    if fmi_version not in (2, 3):
        raise FmuSpecError(f"fmi_version must be 2 or 3, got {fmi_version!r}")
    if fmu_type not in FMU_TYPES:
        raise FmuSpecError(f"fmu_type must be one of {sorted(FMU_TYPES)}, got {fmu_type!r}")
    spec.validate()
    interfaces = FMU_TYPES[fmu_type]
    ident = spec.model_name
    prefix = codegen.symbol_prefix(ident)
    funcs = codegen.build_functions(spec, prefix)
    deps = codegen.dependencies(spec, funcs)
    table = build_table(spec, with_solver="cs" in interfaces,
                        with_indicators=fmi_version == 3 and "me" in interfaces)

    with tempfile.TemporaryDirectory(prefix="bgm_fmu_") as tmp:
        root = Path(tmp) / "fmu"
        src = root / "sources"
        src.mkdir(parents=True)
        model_base = f"{prefix}model"
        codegen.generate_c(funcs, src, model_base, prefix)
        write_runtime(fmi_version, src, hybrid=spec.hybrid is not None)
        token = instantiation_token(
            str(fmi_version), fmu_type, ident, repr(table.variables),
            (src / f"{model_base}.c").read_text(), _runtime_digest(),
            repr((spec.start_time, spec.stop_time, spec.step_size, spec.tolerance)))
        data = model_data_sources(spec, table, fmi_version, token, f"{model_base}.h", prefix,
                                  interfaces, codegen.jacobian_band(funcs.jacx))
        for name, text in data.items():
            (src / name).write_text(text)
        sources = c_files(src)
        (root / "modelDescription.xml").write_bytes(model_description_xml(
            spec, table, deps, fmi_version, ident, token, interfaces, sources))
        if fmi_version == 3:
            (src / "buildDescription.xml").write_bytes(build_description_xml(ident, sources))
        for tb in spec.hybrid.tables if spec.hybrid is not None else ():
            if tb.source:                  # tables read from files travel in the resources
                target = root / "resources" / tb.resource
                target.parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(tb.source[0], target)
        plat, ext = platform_dir(fmi_version)
        compile_shared_library(src, root / "binaries" / plat / f"{ident}{ext}", compiler)
        return zip_fmu(root, Path(out_dir) / f"{ident}.fmu")
