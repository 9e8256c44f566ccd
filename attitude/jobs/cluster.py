"""Where a long job runs (a Monte Carlo job, an envelope): a ``distributed.Client`` to a
local cluster or to a scheduler, its workers checked (the same versions) and its cost
per task measured.

Ctrl-C stops the job: the local cluster is closed (its worker processes never see the
terminal's SIGINT, which the client handles), also when it comes while the cluster
starts (:func:`_start_deferring_stops`).  A scheduler's address is tried first
(:func:`probe_scheduler`), with a timeout: what answers there (nothing, a web server
such as the Dask dashboard, another protocol) is said in one line, before any
``distributed.Client`` exists (a half-made one hangs, or raises at exit).
"""

from __future__ import annotations

import contextlib
import os
import signal
import socket
import tempfile
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from attitude.base.errors import InputError, OptionError
from attitude.base.signals import STOPPING
from attitude.jobs.failures import cluster_failure
from attitude.jobs.fingerprint import differences, what_runs
from attitude.outputs.folder import held_signals

__all__ = [
    "WORKER_MODULES",
    "Workers",
    "check_where",
    "check_workers",
    "connect",
    "probe_scheduler",
    "task_overhead_s",
    "workers_for",
]

_CONNECT_TIMEOUT_S = 10
# A scheduler's address: the connection within this (s), and an answer within as much.
_PROBE_TIMEOUT_S = 5.0
# A Dask scheduler's handshake comes within milliseconds of the connection; after this
# (s) of silence the server is asked as a web server is.
_FIRST_WORDS_S = 2.0

_OVERHEAD_PROBES = 40

# The cost of a task in this process, without a cluster: its batch kept in the job's
# checkpoint (a Parquet file of a few tens of kB: 5 to 10 ms measured here), so that
# batches are not single items, each a file.
_IN_PROCESS_TASK_S = 0.01

# What a worker imports before its first task: with a fork server (below), once for
# every worker.  A job adds the modules of its own tasks (``connect(preload=...)``).
WORKER_MODULES = (
    "distributed",
    "numpy",
    "astropy.time",
    "astropy.utils.iers",
    "attitude.pointing.search",
)


def _noop(index: int) -> int:
    return index


def _what_worker_runs() -> dict[str, str]:
    """:func:`attitude.jobs.fingerprint.what_runs` on a worker; importing the tasks'
    modules warms it up."""
    import attitude.pointing.search  # noqa: F401 (loaded here, not in the first task)

    return what_runs()


@contextlib.contextmanager
def _start_deferring_stops(received: list[int]) -> Iterator[None]:
    """The local cluster's start, with the stopping signals deferred to its end.

    SIGINT is blocked in this thread meanwhile, so that the threads the start creates
    (Dask's event loop, the threads that spawn the workers) and the worker processes
    they start inherit it blocked (a signal mask survives fork and exec): the
    terminal's Ctrl-C, sent to every process of the foreground group, never reaches a
    worker (no traceback of theirs), and the client, which handles it, closes the
    cluster.  SIGINT, SIGTERM and SIGHUP received during the start are recorded in
    ``received`` (a handler that raised here would leave a half-started cluster
    behind) for the caller to deliver once the cluster exists and can be closed: a
    Ctrl-C stops the job as the start ends, about two seconds.  A signal the caller
    ignores stays ignored (attitude.base.signals).
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    # multiprocessing's resource tracker, started by the first worker's spawn, unblocks
    # SIGINT in the thread that starts it (its own guard, CPython bpo-33613): started
    # here first, it leaves Dask's threads as they are made.
    from multiprocessing import resource_tracker

    resource_tracker.ensure_running()
    previous = {}
    for number in STOPPING:
        handler = signal.getsignal(number)
        if handler is not None and handler is not signal.SIG_IGN:
            previous[number] = signal.signal(number, lambda n, frame: received.append(n))
    blocked = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, blocked)  # a pending one is recorded now
        for number, handler in previous.items():
            signal.signal(number, handler)


def _deliver(received: list[int]) -> None:
    """Deliver the signals deferred during the start, to the handlers now in place."""
    for number in dict.fromkeys(received):
        signal.raise_signal(number)


def _ignore_interrupts_plugin():
    """A worker plugin that ignores SIGINT in worker processes the nanny restarts."""
    from distributed.diagnostics.plugin import WorkerPlugin

    class IgnoreInterrupts(WorkerPlugin):
        name = "attitude-ignore-sigint"

        def setup(self, worker) -> None:
            if threading.current_thread() is threading.main_thread():
                signal.signal(signal.SIGINT, signal.SIG_IGN)

    return IgnoreInterrupts()


def check_where(scheduler: str | None, workers: int | None, probe: bool = True) -> int:
    """The local cluster's worker count (0 with a scheduler), after checking the options;
    a malformed address, or one where no Dask scheduler answers (``probe``:
    :func:`probe_scheduler`), is refused before a Client exists (a half-made one hangs
    at exit)."""
    if scheduler is not None:
        if workers is not None:
            raise InputError(
                "sets the size of the local cluster; not with --scheduler", key="--workers"
            )
        from distributed.comm.addressing import get_address_host_port

        try:
            get_address_host_port(scheduler)
        except (ValueError, TypeError) as exc:
            hint = (
                " (http:// is the dashboard's web page; the scheduler's address is "
                "tcp://HOST:PORT, 8786 by default)"
                if scheduler.lower().startswith(("http://", "https://"))
                else ""
            )
            raise InputError(
                f"--scheduler {scheduler!r}: not a scheduler address: {exc}{hint}"
            ) from None
        if probe:
            probe_scheduler(scheduler)
        return 0
    count = workers if workers is not None else len(os.sched_getaffinity(0))
    if not 1 <= count <= 4 * (os.cpu_count() or 1):
        raise InputError(
            f"expected 1 to {4 * (os.cpu_count() or 1)}, got {count}", key="--workers", value=count
        )
    return count


def probe_scheduler(address: str, timeout_s: float = _PROBE_TIMEOUT_S) -> None:
    """Refuse (:class:`OptionError`, one line naming the address and what answered) an
    address where no Dask scheduler listens, within ``timeout_s`` for the connection
    and as much for its first words.

    A Dask scheduler speaks first: on a TCP connection it sends its handshake (msgpack:
    ``compression``, ``python``, ``pickle-protocol``) before it reads anything.  A web
    server (the Dask dashboard, the address users see in their browser) waits for a
    request: it is asked ``HEAD /`` and named by its status line.  Anything else is
    another protocol.  TLS and the other transports are only checked for a connection.
    """
    from distributed.comm.addressing import get_address_host_port, parse_address

    scheme, _ = parse_address(address)
    if scheme not in ("tcp", "tls"):
        return
    host, port = get_address_host_port(address)

    def refused(reason: str) -> OptionError:
        return OptionError(reason, key="--scheduler", value=address)

    try:
        connection = socket.create_connection((host, port), timeout=timeout_s)
    except TimeoutError:
        raise refused(
            f"nothing answered within {timeout_s:g} s (no route to the host, or a firewall "
            "drops the connection)"
        ) from None
    except ConnectionRefusedError:
        raise refused(
            "connection refused: nothing listens on that port (`dask scheduler` prints its "
            "address as 'Scheduler at: tcp://HOST:PORT')"
        ) from None
    except OSError as exc:
        raise refused(f"cannot connect: {exc.strerror or exc}") from None
    with connection:
        if scheme == "tls":
            return
        # A scheduler handshakes at once; a busy one that is late is recognized after
        # the request below all the same (its handshake comes first).
        first = _read_some(connection, _FIRST_WORDS_S)
        if not first:  # silent: a server that waits for a request, perhaps a web server
            with contextlib.suppress(OSError):
                connection.sendall(f"HEAD / HTTP/1.0\r\nHost: {host}\r\n\r\n".encode())
            first = _read_some(connection, timeout_s)
            if not first:
                raise refused(
                    "something listens there but said nothing a Dask scheduler says within "
                    f"{_FIRST_WORDS_S + timeout_s:g} s"
                )
        if b"compression" in first and b"pickle-protocol" in first:
            return  # a Dask handshake
        status = first.split(b"\r\n", 1)[0].split(b"\n", 1)[0][:80]
        if status.startswith(b"HTTP/"):
            raise refused(
                f"a web server answered ({status.decode('ascii', 'replace')}), not a Dask "
                "scheduler: is it the dashboard's port?  The scheduler's address is "
                "tcp://HOST:PORT (8786 by default), as `dask scheduler` prints it after "
                "'Scheduler at:'"
            )
        shown = status.decode("ascii", "replace") if status.isascii() and status.strip() else ""
        raise refused(
            "another protocol answered, not a Dask scheduler"
            + (f": {shown.strip()!r}" if shown.isprintable() and shown.strip() else "")
        )


def _read_some(connection: socket.socket, timeout_s: float, enough: int = 256) -> bytes:
    """What the peer sends within ``timeout_s`` (up to ``enough`` bytes; b"" if nothing)."""
    connection.settimeout(timeout_s)
    data = b""
    deadline = time.monotonic() + timeout_s
    while len(data) < enough:
        left = deadline - time.monotonic()
        if left <= 0.0:
            break
        connection.settimeout(left)
        try:
            chunk = connection.recv(enough - len(data))
        except (TimeoutError, OSError):
            break
        if not chunk:
            break
        data += chunk
        if b"pickle-protocol" in data or b"\r\n" in data:
            break
    return data


@dataclass(frozen=True)
class Workers:
    """Where a job's tasks run: the cluster of a Dask ``client``, or this very process
    (``client`` None: one worker, no cluster); its thread count, Dask's cost per task,
    how the job's record describes it, and how its failures name it."""

    client: Any | None
    threads: int
    overhead_s: float
    described: str
    where: str


@contextlib.contextmanager
def workers_for(
    scheduler: str | None,
    workers: int | None,
    preload: tuple[str, ...] = WORKER_MODULES,
    probed: bool = False,
) -> Iterator[Workers]:
    """The workers of a job (:class:`Workers`), checked (:func:`check_workers`) and
    timed (:func:`task_overhead_s`): one worker without a scheduler is this process
    (no cluster to start, nothing to pickle, and a script without an ``if __name__ ==
    "__main__":`` guard works: a local cluster's new processes import the script
    again); otherwise :func:`connect`.  On a cluster, Dask's own log lines are held
    back (a lost scheduler is the job's one line, not two tracebacks) and a failure of
    the cluster or the machine met by the client is a
    :class:`~attitude.jobs.failures.JobFailed` naming it."""
    count = check_where(scheduler, workers, probe=not probed)
    if scheduler is None and count == 1:
        described = "this process (one worker, no cluster)"
        yield Workers(None, 1, _IN_PROCESS_TASK_S, described, "this process")
        return
    where = f"--scheduler {scheduler}" if scheduler is not None else "the local Dask cluster"
    with (
        _quiet_dask_logs(),
        _failures_named(where),
        connect(scheduler, workers, probed=True, preload=preload) as client,
    ):
        threads = check_workers(client)
        overhead = task_overhead_s(client)
        described = scheduler or f"local cluster ({threads} processes, one thread each)"
        yield Workers(client, threads, overhead, described, where)


@contextlib.contextmanager
def _quiet_dask_logs() -> Iterator[None]:
    """Dask's loggers in this process silent for the block (restored after): each
    one, since Dask's configuration gives some their own level ("Couldn't gather 1
    keys, rescheduling" is ``distributed.client``'s warning)."""
    import logging

    names = ("distributed", "tornado", "asyncio")
    loggers = [logging.getLogger(name) for name in names] + [
        logger
        for name, logger in list(logging.root.manager.loggerDict.items())
        if name.startswith(tuple(f"{n}." for n in names)) and isinstance(logger, logging.Logger)
    ]
    levels = [logger.level for logger in loggers]
    for logger in loggers:
        logger.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        for logger, level in zip(loggers, levels, strict=True):
            logger.setLevel(level)


@contextlib.contextmanager
def _failures_named(where: str) -> Iterator[None]:
    """A failure of the cluster or the machine in the block (the client's calls: a
    connection lost, a timeout) raised as :class:`JobFailed` naming ``where``."""
    try:
        yield
    except Exception as exc:
        failed = cluster_failure(exc, where)
        if failed is None:
            raise
        raise failed from None


@contextlib.contextmanager
def connect(
    scheduler: str | None = None,
    workers: int | None = None,
    probed: bool = False,
    preload: tuple[str, ...] = WORKER_MODULES,
) -> Iterator[Any]:
    """A ``distributed.Client``: to the scheduler at ``scheduler``, or to a local cluster
    of ``workers`` processes (default: every core), one thread each, on 127.0.0.1,
    closed on exit (with its processes and ports) whatever ends the block.
    ``probed``: the caller has already checked the options and the scheduler's address
    (:func:`check_where`); ``preload``: the modules a local worker imports before its
    first task (:func:`_forked_workers`)."""
    import logging

    from distributed import Client, LocalCluster

    count = check_where(scheduler, workers, probe=not probed)
    if scheduler is not None:
        try:
            client = Client(scheduler, timeout=_CONNECT_TIMEOUT_S, set_as_default=False)
        except (OSError, TimeoutError, ValueError, TypeError) as exc:
            text = " ".join(str(exc).split())
            raise OptionError(
                f"cannot connect: {text}", key="--scheduler", value=scheduler
            ) from None
        try:
            yield client
        finally:
            with held_signals():
                client.close()
        return
    with (
        tempfile.TemporaryDirectory(prefix="attitude-dask-") as scratch,
        _forked_workers(preload),
    ):
        received: list[int] = []
        with _start_deferring_stops(received):
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
            _deliver(received)  # a Ctrl-C during the start: the cluster is closed below
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


@contextlib.contextmanager
def _forked_workers(modules: tuple[str, ...]) -> Iterator[None]:
    """Local worker processes forked from one fork server that has imported ``modules``
    (multiprocessing's "forkserver" start method, Dask's
    ``distributed.worker.multiprocessing-method``), instead of each started afresh
    (Dask's default, "spawn"), which imports Dask and the package again in every
    worker: about 1 s of CPU a worker.  The server is started with the cluster (inside
    :func:`_start_deferring_stops`: it holds SIGINT blocked, as the workers do) and
    stopped with it.  Where there is no fork server (Windows), workers are spawned."""
    import multiprocessing

    if "forkserver" not in multiprocessing.get_all_start_methods():
        yield
        return
    import dask
    from distributed.utils import get_mp_context

    with dask.config.set({"distributed.worker.multiprocessing-method": "forkserver"}):
        get_mp_context().set_forkserver_preload(list(modules))
        try:
            yield
        finally:
            _stop_fork_server()


def _stop_fork_server() -> None:
    """End multiprocessing's fork server (it would otherwise live as long as this
    process: the cluster leaves no process behind); the next use starts another."""
    from multiprocessing import forkserver

    with contextlib.suppress(Exception):  # a private method: absent, the server stays
        forkserver._forkserver._stop()  # type: ignore[attr-defined]


def task_overhead_s(client) -> float:
    """The scheduler's cost per task, from no-op tasks on warm workers."""
    start = time.perf_counter()
    client.gather(client.map(_noop, range(_OVERHEAD_PROBES), pure=False))
    return (time.perf_counter() - start) / _OVERHEAD_PROBES


def check_workers(client) -> int:
    """The workers' thread count, after checking that they run this very code: the
    same digest of the package's files and the same numpy, scipy and numba
    (:mod:`attitude.jobs.fingerprint`), else one line naming what differs."""
    here = what_runs()
    try:
        answers = client.run(_what_worker_runs)
    except Exception as exc:  # a worker without attitude, say
        text = " ".join(f"{type(exc).__name__}: {exc}".split())
        raise InputError(f"the workers cannot run attitude ({text})", key="--scheduler") from None
    if not answers:
        raise InputError("the cluster has no workers", key="--scheduler")
    for address, theirs in sorted(answers.items()):
        differ = differences(theirs if isinstance(theirs, dict) else {}, here)
        if differ:
            raise InputError(
                f"worker {address} runs {'; '.join(differ)}: install this very code and "
                "these versions on every worker",
                key="--scheduler",
            )
    return sum(w["nthreads"] for w in client.scheduler_info()["workers"].values())
