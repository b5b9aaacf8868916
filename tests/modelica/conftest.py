"""Put the project root on ``sys.path`` so ``library`` imports without installation; start
every test from an empty Modelica library path: a ``MODELICAPATH`` of the machine must not
change what ``Modelica.*`` means in tests written for the built-in fallback (tests that use a
library set it themselves)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

_ROOT = str(Path(__file__).resolve().parents[2])
if _ROOT not in sys.path:
    sys.path.insert(0, _ROOT)


@pytest.fixture(autouse=True)
def _empty_library_path(monkeypatch):
    from bgmodelica.modelica import library_path

    monkeypatch.setenv("MODELICAPATH", "")
    monkeypatch.setattr(library_path, "_extra", [])
    library_path.clear()
    yield
    library_path.clear()
