"""Fixtures of the study tests: compiled models, and a real Dask cluster made of separate
processes (``dask scheduler`` + two ``dask worker``) on a free local port."""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

import bgmodelica as bg
from bgmodelica.loader import load_model

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def rc():
    return bg.compile(load_model("library.examples.circuits:RC"))


@pytest.fixture(scope="session")
def dcmotor():
    return bg.compile(load_model("library.examples.motors:DCMotor"))


@pytest.fixture(scope="session")
def robot():
    return bg.compile(load_model("library.robots:RobotPID"))


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _dask_command() -> list[str]:
    exe = Path(sys.executable).parent / "dask"
    if exe.exists():
        return [str(exe)]
    found = shutil.which("dask")
    if found:
        return [found]
    return [sys.executable, "-m", "dask"]


def _port_open(port: int) -> bool:
    with contextlib.suppress(OSError), socket.create_connection(("127.0.0.1", port), 0.5):
        return True
    return False


@pytest.fixture(scope="module")
def dask_cluster(tmp_path_factory):
    """``tcp://127.0.0.1:PORT`` of a scheduler with two single-threaded worker processes,
    all started as separate ``dask`` commands and stopped (then killed) at the end."""
    pytest.importorskip("distributed")
    logs = tmp_path_factory.mktemp("dask")
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])]))
    dask = _dask_command()
    procs: list[subprocess.Popen] = []
    files = []

    def start(args: list[str], name: str) -> None:
        fh = open(logs / f"{name}.log", "w")  # noqa: SIM115 -- closed in the finalizer
        files.append(fh)
        procs.append(subprocess.Popen([*dask, *args], cwd=ROOT, env=env, stdout=fh,
                                      stderr=subprocess.STDOUT, start_new_session=True))

    try:
        start(["scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
              "scheduler")
        deadline = time.monotonic() + 60
        while not _port_open(port):
            if procs[0].poll() is not None or time.monotonic() > deadline:
                raise RuntimeError("dask scheduler did not start:\n"
                                   + (logs / "scheduler.log").read_text()[-2000:])
            time.sleep(0.1)
        for k in range(2):
            start(["worker", address, "--nthreads", "1", "--no-nanny", "--no-dashboard",
                   "--host", "127.0.0.1", "--name", f"w{k}", "--death-timeout", "60",
                   "--local-directory", str(logs / f"w{k}")], f"worker{k}")
        yield address
    finally:
        for p in reversed(procs):           # workers first, then the scheduler
            if p.poll() is None:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(p.pid, signal.SIGTERM)      # its own session: only it
        for p in reversed(procs):
            try:
                p.wait(timeout=15)
            except subprocess.TimeoutExpired:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(p.pid, signal.SIGKILL)
                p.wait(timeout=5)
        for fh in files:
            fh.close()
