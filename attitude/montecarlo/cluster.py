"""Where a Monte Carlo job runs: a ``distributed.Client`` to a local cluster or to a
scheduler, its workers checked (the same versions) and its cost per task measured.

Ctrl-C stops the job: the local cluster is closed (its worker processes ignore the
terminal's SIGINT, which the client handles).
"""

from __future__ import annotations

import contextlib
import os
import signal
import tempfile
import threading
import time
from collections.abc import Iterator
from typing import Any

import numpy as np

from attitude.base.errors import InputError
from attitude.base.version import __version__
from attitude.outputs.folder import held_signals

__all__ = ["check_where", "check_workers", "connect", "task_overhead_s"]

_CONNECT_TIMEOUT_S = 10

_OVERHEAD_PROBES = 40


def _noop(index: int) -> int:
    return index


def _worker_versions() -> tuple[str, str, str]:
    """(attitude, numpy, scipy) on a worker; importing the sample's modules warms it up."""
    import scipy

    import attitude.pointing.search  # noqa: F401 (loaded here, not in the first task)

    return __version__, np.__version__, scipy.__version__


@contextlib.contextmanager
def _workers_ignore_interrupts() -> Iterator[None]:
    """SIGINT ignored while worker processes start: they inherit it (an ignored signal
    stays ignored across exec), so the terminal's Ctrl-C, sent to every process of the
    foreground group, reaches only the client, which closes the cluster.  A Ctrl-C in
    this window (the cluster's start, about two seconds) is lost."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _ignore_interrupts_plugin():
    """A worker plugin that ignores SIGINT in worker processes the nanny restarts."""
    from distributed.diagnostics.plugin import WorkerPlugin

    class IgnoreInterrupts(WorkerPlugin):
        name = "attitude-ignore-sigint"

        def setup(self, worker) -> None:
            if threading.current_thread() is threading.main_thread():
                signal.signal(signal.SIGINT, signal.SIG_IGN)

    return IgnoreInterrupts()


def check_where(scheduler: str | None, workers: int | None) -> int:
    """The local cluster's worker count (0 with a scheduler), after checking the options;
    a malformed address is refused before a Client exists (a half-made one hangs at exit)."""
    if scheduler is not None:
        if workers is not None:
            raise InputError("--workers: sets the size of the local cluster; not with --scheduler")
        from distributed.comm.addressing import get_address_host_port

        try:
            get_address_host_port(scheduler)
        except (ValueError, TypeError) as exc:
            raise InputError(f"--scheduler {scheduler!r}: not a scheduler address: {exc}") from None
        return 0
    count = workers if workers is not None else len(os.sched_getaffinity(0))
    if not 1 <= count <= 4 * (os.cpu_count() or 1):
        raise InputError(f"--workers: expected 1 to {4 * (os.cpu_count() or 1)}, got {count}")
    return count


@contextlib.contextmanager
def connect(scheduler: str | None = None, workers: int | None = None) -> Iterator[Any]:
    """A ``distributed.Client``: to the scheduler at ``scheduler``, or to a local cluster
    of ``workers`` processes (default: every core), one thread each, on 127.0.0.1,
    closed on exit (with its processes and ports) whatever ends the block."""
    import logging

    from distributed import Client, LocalCluster

    count = check_where(scheduler, workers)
    if scheduler is not None:
        try:
            client = Client(scheduler, timeout=_CONNECT_TIMEOUT_S, set_as_default=False)
        except (OSError, TimeoutError, ValueError, TypeError) as exc:
            text = " ".join(str(exc).split())
            raise InputError(f"--scheduler {scheduler}: cannot connect: {text}") from None
        try:
            yield client
        finally:
            with held_signals():
                client.close()
        return
    with tempfile.TemporaryDirectory(prefix="attitude-dask-") as scratch:
        with _workers_ignore_interrupts():
            cluster = LocalCluster(
                n_workers=count,
                threads_per_worker=1,
                processes=True,
                host="127.0.0.1",
                dashboard_address=":0",  # no fixed port (8787 may be taken)
                silence_logs=logging.CRITICAL,
                local_directory=scratch,  # workers' spill files: removed with it
            )
        try:
            client = Client(cluster, set_as_default=False)
            try:
                client.register_plugin(_ignore_interrupts_plugin())
                yield client
            finally:
                with held_signals():
                    client.close()
        finally:
            with held_signals():
                cluster.close()


def task_overhead_s(client) -> float:
    """The scheduler's cost per task, from no-op tasks on warm workers."""
    start = time.perf_counter()
    client.gather(client.map(_noop, range(_OVERHEAD_PROBES), pure=False))
    return (time.perf_counter() - start) / _OVERHEAD_PROBES


def check_workers(client) -> int:
    """The workers' thread count, after checking that they run this very code."""
    here = _worker_versions()
    try:
        versions = client.run(_worker_versions)
    except Exception as exc:  # a worker without attitude, say
        text = " ".join(f"{type(exc).__name__}: {exc}".split())
        raise InputError(f"--scheduler: the workers cannot run attitude ({text})") from None
    if not versions:
        raise InputError("--scheduler: the cluster has no workers")
    for address, theirs in versions.items():
        if tuple(theirs) != here:
            raise InputError(
                f"--scheduler: worker {address} runs attitude {theirs[0]} with numpy "
                f"{theirs[1]} and scipy {theirs[2]}; this is attitude {here[0]} with numpy "
                f"{here[1]} and scipy {here[2]}: install the same versions on every worker"
            )
    return sum(w["nthreads"] for w in client.scheduler_info()["workers"].values())
