"""Adaptive co-simulation: two first-order lags in a feedback loop, each its own FMU, against
the matrix exponential of the coupled system."""

from __future__ import annotations

import functools
import zipfile
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import expm

from bgmodelica.cosim.adaptive import cosimulate_adaptive
from bgmodelica.cosim.errors import SetupError
from bgmodelica.cosim.ssp import system_from_fmus
from bgmodelica.fmi.from_model import export_model

# T_a ya' = k_a yb - ya, T_b yb' = k_b ya - yb; ya(0) = 1, yb(0) = 0
TA, KA, TB, KB = 0.5, -2.0, 0.2, 1.5
M = np.array([[-1 / TA, KA / TA], [KB / TB, -1 / TB]])


def _exact(t: np.ndarray) -> np.ndarray:
    return np.array([expm(M * s) @ [1.0, 0.0] for s in t])


@functools.cache
def _fmus(base: str, version: int) -> dict[str, Path]:
    from library.blocks import FirstOrder

    out = {}
    for name, (y0, k, T) in {"a": (1.0, KA, TA), "b": (0.0, KB, TB)}.items():
        out[name] = export_model(FirstOrder(y_start=y0, k=k, T=T),
                                 Path(base) / f"{name}{version}", fmi_version=version,
                                 fmu_type="cs", tolerance=1e-10)
    return out


@pytest.fixture(scope="module")
def loop(tmp_path_factory):
    base = str(tmp_path_factory.mktemp("adaptive"))

    def make(version: int = 2, fmus: dict | None = None):
        fmus = fmus or _fmus(base, version)
        return system_from_fmus("loop", fmus, [("a", "y", "b", "u"), ("b", "y", "a", "u")])
    return make


def _error(res) -> float:
    exact = _exact(res.time)
    return float(max(np.max(np.abs(res["a.y"] - exact[:, 0])),
                     np.max(np.abs(res["b.y"] - exact[:, 1]))))


@pytest.mark.parametrize("version", [2, 3])
def test_meets_its_tolerance_and_adapts(loop, version):
    loose = cosimulate_adaptive(loop(version), 3.0, 1e-3)
    tight = cosimulate_adaptive(loop(version), 3.0, 1e-6)
    # a local (per step) tolerance: the global error stays within a few tens of it
    assert _error(tight) < 1e-4 < 1e-3 < _error(loose) < 3e-2
    assert tight.meta["steps_accepted"] > 4 * loose.meta["steps_accepted"]
    assert tight.meta["error_estimate_max"] <= 1e-6
    assert tight.time[-1] == pytest.approx(3.0)
    steps = np.diff(tight.time)
    assert steps.max() > 5 * steps.min()               # the step follows the dynamics


def test_rejected_steps_are_rolled_back(loop):
    """A far too large first step is rejected (the FMUs go back to t = 0 through their
    saved states); the result is as accurate as a run that starts small."""
    big = cosimulate_adaptive(loop(), 2.0, 1e-6, initial_step=0.5)
    small = cosimulate_adaptive(loop(), 2.0, 1e-6, initial_step=1e-4)
    assert big.meta["steps_rejected"] >= 2
    assert big.time[1] < 0.05
    assert _error(big) < 1e-4 and _error(small) < 1e-4
    assert np.interp(1.0, big.time, big["a.y"]) == pytest.approx(
        np.interp(1.0, small.time, small["a.y"]), abs=1e-4)


def test_fmu_without_state_rollback_is_refused(loop, tmp_path):
    fmus = _fmus(str(tmp_path), 2)
    crippled = tmp_path / "a_nostate.fmu"
    with zipfile.ZipFile(fmus["a"]) as src, zipfile.ZipFile(crippled, "w") as dst:
        for item in src.infolist():
            data = src.read(item)
            if item.filename == "modelDescription.xml":
                data = data.replace(b'canGetAndSetFMUstate="true"',
                                    b'canGetAndSetFMUstate="false"')
            dst.writestr(item, data)
    system = loop(fmus={"a": crippled, "b": fmus["b"]})
    with pytest.raises(SetupError, match=r"save and restore their state .*not: a "
                                         r"\(a_nostate\.fmu\)"):
        cosimulate_adaptive(system, 1.0, 1e-4)
