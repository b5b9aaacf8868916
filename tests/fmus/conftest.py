"""The C test FMUs (``build.py``), built once per test session."""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import pytest

_HERE = str(Path(__file__).resolve().parent)
if _HERE not in sys.path:
    sys.path.insert(0, _HERE)

from build import MODELS, MODELS2, build_fmu  # noqa: E402


@pytest.fixture(scope="session")
def c_fmus(tmp_path_factory) -> dict[str, Path]:
    """name -> path of every C test FMU (ME + CS)."""
    if not any(shutil.which(cc) for cc in ("cc", "gcc", "clang")):
        pytest.skip("no C compiler to build the test FMUs")
    out = tmp_path_factory.mktemp("c_fmus")
    return {name: build_fmu(name, out) for name in [*MODELS, *MODELS2]}
