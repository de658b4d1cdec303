"""Where independent jobs (a scene's layers) run: here, in local worker processes, or on a Dask cluster.

``local`` with one job runs them one after the other in this process. With ``jobs`` N > 1
they run in N spawned processes, each with ``cpu_count // N`` numba threads so the
machine is not oversubscribed, and with this process's log level and progress format.
``dask://HOST:PORT`` submits them to an existing Dask distributed scheduler (extra
``fluidymation[distributed]``); its workers must see the same files (the output folder
on a shared path); a job running on a Dask worker submits its own jobs (a layer's frames)
through that worker's client. Results come back in the order of the jobs.
"""

from __future__ import annotations

import logging
import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor
from typing import Callable

from fluidymation.errors import InputError, StageError
from fluidymation.pipeline import progress

LOCAL = "local"
_DASK = "dask://"

log = logging.getLogger(__name__)


def dask_address(executor: str) -> str | None:
    """The scheduler address (``tcp://HOST:PORT``) of ``dask://HOST:PORT``; None for ``local``."""
    if executor == LOCAL:
        return None
    host, _, port = executor.removeprefix(_DASK).rpartition(":")
    if not executor.startswith(_DASK) or not host or not port.isdigit():
        raise InputError(f"--executor {executor!r}: use 'local' or 'dask://HOST:PORT' (a Dask scheduler)")
    return f"tcp://{host}:{port}"


def run_jobs(function: Callable, arguments: list[tuple], *, executor: str = LOCAL, jobs: int = 1) -> list:
    """``[function(*args) for args in arguments]``, run by ``executor`` with up to ``jobs`` local processes.

    ``function`` must be importable by name (a module-level function) unless everything runs here.
    """
    address = dask_address(executor)
    if address is not None:
        return _from_dask_worker(function, arguments) if _inside_dask_worker() else _on_dask(function, arguments, address)
    if jobs <= 1 or len(arguments) <= 1:
        return [function(*args) for args in arguments]
    workers = min(jobs, len(arguments))
    settings = (max(1, (os.cpu_count() or 1) // workers), logging.getLogger().getEffectiveLevel(),
                progress.json_lines())
    log.debug("running %d jobs in %d processes with %d numba threads each", len(arguments), workers, settings[0])
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"),
                               initializer=_start_worker, initargs=settings)
    try:
        futures = [pool.submit(function, *args) for args in arguments]
        return [future.result() for future in futures]
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _start_worker(numba_threads: int, log_level: int, json_lines: bool) -> None:
    """Set up a local worker process like its parent, with its share of the numba threads."""
    import numba

    numba.set_num_threads(min(numba_threads, numba.config.NUMBA_NUM_THREADS))
    logging.basicConfig(level=log_level, format="%(name)s: %(message)s")
    progress.use_json_lines(json_lines)


def _on_dask(function: Callable, arguments: list[tuple], address: str) -> list:
    """Run the jobs on the Dask scheduler at ``address`` and gather their results."""
    try:
        from distributed import Client
    except ImportError:
        raise InputError("--executor dask://...: the Dask distributed package is not installed; install "
                         "fluidymation with the distributed extra: pip install 'fluidymation[distributed]'") from None
    try:
        client = Client(address, timeout=10, set_as_default=False)
    except OSError as exc:
        raise StageError(f"--executor: cannot reach a Dask scheduler at {address} ({exc})") from None
    with client:
        log.debug("running %d jobs on the Dask cluster at %s", len(arguments), address)
        futures = [client.submit(function, *args, pure=False) for args in arguments]
        return client.gather(futures)


def _inside_dask_worker() -> bool:
    try:
        from distributed import get_worker
        get_worker()
    except (ImportError, ValueError):
        return False
    return True


def _from_dask_worker(function: Callable, arguments: list[tuple]) -> list:
    """Jobs submitted by a job that runs on a Dask worker (a layer's frames): through the worker's client,
    the worker giving up its thread while it waits so the cluster cannot deadlock."""
    from distributed import worker_client

    with worker_client() as client:
        log.debug("running %d jobs from a Dask worker", len(arguments))
        return client.gather([client.submit(function, *args, pure=False) for args in arguments])
