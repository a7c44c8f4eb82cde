"""Connecting to Dask: a LocalCluster on this machine by default, or an existing scheduler.

* ``scheduler=None``: ``LocalCluster(n_workers=workers or os.cpu_count(), threads_per_worker=1,
  processes=True)``, closed at the end. One single-threaded worker process per core: runs are
  CPU-bound Python/numba code, so processes, not threads, give the speed-up.
* ``scheduler="tcp://host:8786"``: a running Dask scheduler (e.g. one started by dask-jobqueue on
  SLURM, or ``dask scheduler`` + ``dask worker``). Its workers must see the campaign folder at the same
  path (a shared filesystem) and have slamtrials installed.
* ``scheduler="path/to/scheduler.json"``: the same, found through the file that ``dask scheduler
  --scheduler-file`` writes (the workers take ``--scheduler-file`` too): no address to pass around, and
  the scheduler may listen on any free port (``--port 0``). The file is waited for, as ``dask worker``
  waits for it, up to the connection timeout.
* ``scheduler=<distributed.Client>``: used as it is, and left open.
"""

from __future__ import annotations

import logging
import os
import signal
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from slamtrials.errors import ConfigError

__all__ = ["dask_client", "check_workers", "is_scheduler_file", "CONNECT_TIMEOUT"]

log = logging.getLogger(__name__)

#: Seconds to wait for an existing scheduler to answer.
CONNECT_TIMEOUT = 30.0


def check_workers(workers: int | None) -> int:
    """The number of local workers: ``workers`` or the CPU count; raise ConfigError below 1."""
    if workers is None:
        return max(os.cpu_count() or 1, 1)
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ConfigError(f"workers must be a positive integer, got {workers!r}")
    return workers


def is_scheduler_file(scheduler: Any) -> bool:
    """Whether ``scheduler`` names a scheduler file (a path ending in ``.json``) rather than an address."""
    if isinstance(scheduler, os.PathLike):
        return True
    return isinstance(scheduler, str) and "://" not in scheduler and scheduler.lower().endswith(".json")


def _connect(scheduler: Any, timeout: float) -> Any:
    """A ``distributed.Client`` of a running scheduler, by address or by scheduler file."""
    from distributed import Client

    if not is_scheduler_file(scheduler):
        return Client(str(scheduler), timeout=timeout)
    path = os.fspath(scheduler)
    deadline = time.monotonic() + timeout
    while not os.path.isfile(path):  # the scheduler may be starting: wait for its file, as dask worker does
        if time.monotonic() > deadline:
            raise OSError(
                f"no scheduler file {path} after {timeout:g} s (start dask scheduler --scheduler-file {path})"
            )
        time.sleep(0.1)
    return Client(scheduler_file=path, timeout=timeout)


@contextmanager
def _workers_ignore_ctrl_c() -> Iterator[None]:
    """Ignore SIGINT while the local workers start, so that they inherit the ignoring: Ctrl-C in a terminal
    reaches every process of the group, and the workers would each print a traceback; this process
    handles it and shuts them down."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


@contextmanager
def dask_client(
    scheduler: Any = None,
    workers: int | None = None,
    *,
    allowed_failures: int | None = None,
    timeout: float | None = None,
) -> Iterator[Any]:
    """Yield a ``distributed.Client`` (see the module docstring); close what this function opened.

    ``allowed_failures`` sets how many worker deaths a task may cause before the local cluster's
    scheduler gives up on it (``distributed.scheduler.allowed-failures``, default 3); an existing
    scheduler keeps its own setting.

    Raises
    ------
    ConfigError
        Bad ``workers``, or a scheduler address that cannot be reached within ``timeout`` seconds
        (default :data:`CONNECT_TIMEOUT`).
    """
    from distributed import Client, LocalCluster

    if isinstance(scheduler, Client):
        yield scheduler
        return
    if scheduler is not None:
        try:
            client = _connect(scheduler, timeout or CONNECT_TIMEOUT)
        except (OSError, TimeoutError, ValueError, KeyError) as exc:
            raise ConfigError(f"cannot connect to the Dask scheduler {str(scheduler)!r}: {exc}") from None
        log.info("connected to Dask scheduler %s", scheduler)
        try:
            yield client
        finally:
            client.close()
        return
    import dask

    n = check_workers(workers)
    settings = {} if allowed_failures is None else {"distributed.scheduler.allowed-failures": int(allowed_failures)}
    # the workers' own warnings (a task cancelled at shutdown, ...) only with -v: a run's failure is ours to tell
    worker_logs = logging.WARNING if logging.getLogger().getEffectiveLevel() <= logging.INFO else logging.ERROR
    with dask.config.set(settings), _workers_ignore_ctrl_c():
        cluster = LocalCluster(
            n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0", silence_logs=worker_logs
        )
    try:
        client = Client(cluster)
    except BaseException:
        cluster.close()
        raise
    log.info("started a local Dask cluster with %d worker processes (dashboard %s)", n, cluster.dashboard_link)
    try:
        yield client
    except KeyboardInterrupt:
        # Ctrl-C reached the workers too: their shutdown is expected, so the nanny's "still alive,
        # killing" warnings are not shown; the caller prints one line
        logging.getLogger("distributed").setLevel(logging.CRITICAL)
        raise
    finally:
        client.close()
        cluster.close()
