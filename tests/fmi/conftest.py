"""Fixtures for the FMU exporter tests: every FMU is built once per session, on demand."""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import pytest

_ROOT = str(Path(__file__).resolve().parents[2])
_HERE = str(Path(__file__).resolve().parent)
for _p in (_ROOT, _HERE):
    if _p not in sys.path:
        sys.path.insert(0, _p)

from fmi_models import SPECS  # noqa: E402

from bgmodelica.fmi import export_fmu  # noqa: E402


def pytest_collection_modifyitems(config, items):
    if shutil.which("cc") is None and shutil.which("gcc") is None:
        skip = pytest.mark.skip(reason="no C compiler")
        for item in items:
            if "fmi" in str(item.fspath) and "build_fmu" in getattr(item, "fixturenames", ()):
                item.add_marker(skip)


@pytest.fixture(scope="session")
def build_fmu(tmp_path_factory):
    """``build_fmu(model, version, fmu_type) -> Path``; cached for the whole session."""
    cache: dict[tuple[str, int, str], Path] = {}
    base = tmp_path_factory.mktemp("fmus")

    def build(model: str, version: int, fmu_type: str) -> Path:
        key = (model, version, fmu_type)
        if key not in cache:
            out = base / f"{model}_fmi{version}_{fmu_type}"
            cache[key] = export_fmu(SPECS[model](), out, version, fmu_type)
        return cache[key]

    return build
