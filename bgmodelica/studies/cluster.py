"""Where the runs of a study go: a Dask cluster (``dask.distributed``) or this process.

``scheduler``:

* ``"local"`` (default): a :class:`distributed.LocalCluster` of ``workers`` processes (one
  thread each) started for the study and closed after it;
* ``"tcp://HOST:PORT"`` (or any address ``distributed.Client`` accepts): an existing scheduler,
  e.g. ``dask scheduler`` + ``dask worker`` on many machines, dask-jobqueue or a Kubernetes
  cluster; only the address changes. With ``workers=N`` the study waits until N workers are
  connected;
* ``"serial"``: no Dask at all, the runs one after another in this process (debugging, and
  the baseline of the benchmarks).

An existing ``distributed.Client`` may be passed as ``client`` instead (kept open).
"""

from __future__ import annotations

import contextlib
import logging
import os
from collections.abc import Iterator
from typing import Any

from ..errors import OptionError

#: seconds to wait for a remote scheduler and its workers
CONNECT_TIMEOUT = 60.0


def default_workers() -> int:
    return max(1, min(os.cpu_count() or 1, 8))


def check_scheduler(scheduler: Any, workers: Any) -> tuple[str, int | None]:
    """Validate ``scheduler`` / ``workers`` before anything starts."""
    if scheduler is None:
        scheduler = "local"
    if not isinstance(scheduler, str) or not scheduler.strip():
        raise OptionError(f"scheduler (--scheduler) must be 'local', 'serial' or an address "
                          f"like tcp://HOST:PORT, got {scheduler!r}")
    scheduler = scheduler.strip()
    if scheduler not in ("local", "serial") and "://" not in scheduler \
            and ":" not in scheduler:
        raise OptionError(f"scheduler (--scheduler) {scheduler!r} is neither 'local', 'serial' "
                          "nor an address like tcp://HOST:PORT")
    if workers is not None:
        if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
            raise OptionError(f"workers (--workers) must be a positive integer, got {workers!r}")
    return scheduler, workers


@contextlib.contextmanager
def dask_client(client: Any = None, scheduler: str = "local",
                workers: int | None = None) -> Iterator[Any]:
    """A connected ``distributed.Client`` for ``scheduler`` (closed at exit unless given)."""
    if client is not None:
        yield client
        return
    try:
        from distributed import Client, LocalCluster
    except ImportError as err:  # pragma: no cover - the 'studies' extra is missing
        raise OptionError("studies on Dask need the 'studies' extra: pip install "
                          "'bgmodelica[studies]' (dask[distributed], xarray)") from err
    if scheduler == "local":
        cluster = LocalCluster(n_workers=workers or default_workers(), threads_per_worker=1,
                               processes=True, dashboard_address=None,
                               silence_logs=logging.ERROR, worker_dashboard_address=None,
                               preload=["bgmodelica.studies.worker"])
        cl = Client(cluster)
        try:
            yield cl
        finally:
            with contextlib.suppress(Exception):
                cl.close()
            with contextlib.suppress(Exception):
                cluster.close()
        return
    try:
        cl = Client(scheduler, timeout=CONNECT_TIMEOUT)
    except OSError as err:
        raise OptionError(f"--scheduler {scheduler}: cannot connect to the Dask scheduler "
                          f"({err})") from None
    try:
        try:
            cl.wait_for_workers(workers or 1, timeout=CONNECT_TIMEOUT)
        except TimeoutError:
            raise OptionError(f"--scheduler {scheduler}: fewer than {workers or 1} worker(s) "
                              f"connected after {CONNECT_TIMEOUT:g} s") from None
        yield cl
    finally:
        with contextlib.suppress(Exception):
            cl.close()


def n_workers(client: Any) -> int:
    try:
        return len(client.scheduler_info(n_workers=-1)["workers"])
    except TypeError:
        return len(client.scheduler_info()["workers"])
