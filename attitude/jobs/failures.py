"""What a job's failures are: the item's own, the machine's, or ours.

A job's table holds one row per item (a Monte Carlo sample, an envelope's failure
time), and a row says ``failed`` only for a reason that belongs to the item's own
input: its drawn state refused, its motion over a budget, every refusal this package
raises on purpose (an :class:`~attitude.base.errors.InputError`).  The rest never
becomes a row, since a row is a science result that would differ from run to run:

- the machine or the cluster (:class:`JobFailed`, a
  :class:`~attitude.base.errors.MachineError`): a lost scheduler, workers killed
  again and again (Dask reschedules a task whose worker died, up to its
  ``distributed.scheduler.allowed-failures``), a worker out of memory, a connection
  that broke.  The job fails with one line, its finished batches kept for ``--resume``;
- anything else a task raised (:class:`TaskError`): a bug of ours, the command line's
  exit 3, with the item that raised it and the worker's traceback
  (``ATTITUDE_TRACEBACK=1`` prints it).
"""

from __future__ import annotations

import traceback
from concurrent.futures import CancelledError

from attitude.base.errors import AttitudeError, MachineError

__all__ = ["JobFailed", "TaskError", "cluster_failure", "task_failure"]


class JobFailed(MachineError):
    """The machine or the cluster failed the job (see the module notes)."""


class TaskError(AttitudeError):
    """An exception a task raised that no input explains: a bug.

    ``str(error)`` is one line (the item and the exception); ``details`` is the
    traceback where it was raised (on a worker: its own), for ``ATTITUDE_TRACEBACK``.
    Picklable (a worker raises it; Dask sends it to the client)."""

    def __init__(self, text: str, details: str = "") -> None:
        super().__init__(text, details)
        self.text = text
        self.details = details

    def __str__(self) -> str:
        return self.text

    @classmethod
    def of(cls, exc: BaseException, where: str) -> TaskError:
        """``exc`` (being handled) raised while computing ``where`` ("sample 7")."""
        text = " ".join(f"{where}: {type(exc).__name__}: {exc}".split())
        return cls(text, "".join(traceback.format_exception(exc)))


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split()) or type(exc).__name__


def _is_cluster(exc: BaseException) -> bool:
    """Whether ``exc``, met on the client, is the cluster's or the machine's doing."""
    kinds: tuple[type[BaseException], ...] = (CancelledError, OSError, TimeoutError, MemoryError)
    try:
        from distributed.scheduler import KilledWorker

        kinds += (KilledWorker,)
    except ImportError:  # no Dask: only this process's own failures
        pass
    return isinstance(exc, kinds)


def cluster_failure(exc: BaseException, where: str) -> JobFailed | None:
    """The :class:`JobFailed` that ``exc`` is (None if it is not the cluster's or the
    machine's), in one line; ``where``: the cluster as the user named it."""
    if not _is_cluster(exc):
        return None
    reason = getattr(exc, "reason", "")
    if isinstance(exc, CancelledError) and "scheduler" in str(reason):
        text = f"{where}: the connection to the Dask scheduler was lost"
    elif type(exc).__name__ == "KilledWorker":
        text = (
            f"{where}: the workers computing a task died one after another (killed, or out "
            f"of memory): {_one_line(exc)}"
        )
    elif isinstance(exc, MemoryError):
        text = f"{where}: a worker ran out of memory"
    elif isinstance(exc, CancelledError):
        text = f"{where}: a task was cancelled ({reason or 'no reason given'})"
    else:
        text = f"{where}: {type(exc).__name__}: {_one_line(exc)}"
    return JobFailed(text)


def task_failure(exc: BaseException, first: int, stop: int, noun: str, where: str) -> Exception:
    """What a task of items ``first`` to ``stop − 1`` (``noun``: "samples") that raised
    ``exc`` makes of the job: :class:`JobFailed` (the cluster's or the machine's),
    ``exc`` itself if it is a :class:`TaskError` already (the item named), or a
    :class:`TaskError`."""
    failed = cluster_failure(exc, where)
    if failed is not None:
        return failed
    if isinstance(exc, TaskError):
        return exc
    span = f"{noun} {first}-{stop - 1}" if stop - first > 1 else f"{noun[:-1]} {first}"
    return TaskError.of(exc, f"the task of {span}")
