"""Fixtures of the co-simulation tests: the robot set-up (FMUs + SSP files) is built once per
test session by :func:`library.robots.subsystems.export_robot_setup`, and the monolithic
reference is simulated once."""

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

from cosim_helpers import GRID, HORIZON  # noqa: E402


def pytest_collection_modifyitems(config, items):
    if shutil.which("cc") is None and shutil.which("gcc") is None:
        skip = pytest.mark.skip(reason="no C compiler to build the FMUs")
        for item in items:
            if "cosim" in str(item.fspath):
                item.add_marker(skip)


@pytest.fixture(scope="session")
def robot_setup(tmp_path_factory):
    """``export_robot_setup`` output: keys ssp, ssp_plain, container_json, Arm, Motor,
    Controller, ControllerAngleD (paths)."""
    from library.robots.subsystems import export_robot_setup

    return export_robot_setup(tmp_path_factory.mktemp("robot_setup"))


@pytest.fixture(scope="session")
def robot_fmus(robot_setup):
    return {k: v for k, v in robot_setup.items() if k[0].isupper()}


@pytest.fixture(scope="session")
def robot_ssp(robot_setup):
    from bgmodelica.cosim.ssp_read import read_ssp

    return read_ssp(robot_setup["ssp"])


@pytest.fixture(scope="session")
def reference():
    """The monolithic RobotPID over HORIZON on the GRID, tight tolerances."""
    from bgmodelica import compile, simulate
    from library.robots.robot import RobotPID

    return simulate(compile(RobotPID()), stop_time=HORIZON, interval=GRID, rtol=1e-10,
                    atol=1e-12, dynamic=False)

