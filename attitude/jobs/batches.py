"""A job's batches: how many items a task takes (from the measured costs), the batches'
ranges, and the tasks sent to the cluster and gathered as they finish.

A job (a Monte Carlo job's samples, an envelope's failures) is ``count`` items, each
computed from the job alone, so that its table is the same whatever the batch size
and the workers.  :func:`gather` is the loop both jobs run: one task
``evaluate(job, first, stop)`` per batch, each result handed to the job as it comes
in, the progress told after each.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from typing import Any

from attitude.base.errors import InputError
from attitude.jobs.cluster import Workers
from attitude.jobs.failures import task_failure

__all__ = [
    "batch_ranges",
    "batches_as_they_finish",
    "check_batch_size",
    "choose_batch_size",
    "gather",
    "split_ranges",
]

# A task should last this many times the scheduler's cost per task (so that the
# overhead is at most 1 %), and every worker should get at least this many tasks
# (balance at the end of the job, and a progress bar that moves).
_OVERHEAD_FACTOR = 100

_TASKS_PER_WORKER = 4

# A task lasts at most about this (s of a worker's CPU): a job's checkpoint takes a
# batch as it finishes, so an interruption loses at most this much of each worker's
# work (a 10 000-sample job on two workers would otherwise run as eight tasks).
_TASK_AT_MOST_S = 30.0


def choose_batch_size(count: int, workers: int, item_s: float, task_overhead_s: float) -> int:
    """Items per task: enough that a task lasts _OVERHEAD_FACTOR times the scheduler's
    cost per task, few enough that every worker gets _TASKS_PER_WORKER tasks and that
    a task lasts at most _TASK_AT_MOST_S."""
    item_s = max(item_s, 1e-9)
    long_enough = math.ceil(_OVERHEAD_FACTOR * task_overhead_s / item_s)
    balanced = math.ceil(count / (_TASKS_PER_WORKER * max(workers, 1)))
    short_enough = math.floor(_TASK_AT_MOST_S / item_s)
    return max(1, min(long_enough, balanced, short_enough))


def check_batch_size(batch_size: int | None, count: int) -> None:
    """A ``--batch-size`` given for a job of ``count`` items: 1 to ``count``."""
    if batch_size is not None and not 1 <= batch_size <= count:
        raise InputError(
            f"expected 1 to {count}, got {batch_size}", key="--batch-size", value=batch_size
        )


def batch_ranges(count: int, size: int) -> list[tuple[int, int]]:
    """[first, stop) of each task's items, ``size`` at a time over ``count``."""
    return split_ranges([(0, count)], size)


def split_ranges(ranges: list[tuple[int, int]], size: int) -> list[tuple[int, int]]:
    """[first, stop) of each task's items, ``size`` at a time over each of ``ranges``
    (the items a checkpoint does not hold)."""
    return [(a, min(a + size, stop)) for start, stop in ranges for a in range(start, stop, size)]


def batches_as_they_finish(
    client, evaluate: Callable[..., Any], job: Any, batches: list[tuple[int, int]]
) -> Iterator[tuple[int, int, Any]]:
    """Send ``job`` once, one task ``evaluate(job, first, stop)`` per batch, and yield
    ``(first, stop, result)`` as the tasks finish, each released once read;
    ``result`` is the task's value, or the exception it ended with (raised by the
    task, or the cluster's: a task cancelled when the scheduler was lost, a task
    whose workers kept dying).  A task whose worker dies is run again on another by
    the scheduler itself, up to ``distributed.scheduler.allowed-failures`` times.

    The job is a task's result (:func:`_the_job`), not scattered data: a worker that
    fetched it keeps it for its other tasks, and if the workers holding it die the
    scheduler computes it again.  Scattered, it died with them, and every task left
    was cancelled (a one-worker cluster whose worker was killed mid-job)."""
    from distributed import as_completed

    shared = client.submit(_the_job, job, pure=False)
    futures = client.map(
        evaluate,
        [shared] * len(batches),
        [a for a, _ in batches],
        [b for _, b in batches],
        pure=False,
    )
    span = {future.key: batch for future, batch in zip(futures, batches, strict=True)}
    for future, result in as_completed(futures, client.loop, with_results=True, raise_errors=False):
        first, stop = span[future.key]
        if future.status == "error":  # as_completed gives (type, exception, traceback)
            _, exc, tb = result
            result = exc.with_traceback(tb)
        yield first, stop, result
        future.release()


def _the_job(job: Any) -> Any:
    return job


def _in_this_process(
    evaluate: Callable[..., Any], job: Any, batches: list[tuple[int, int]]
) -> Iterator[tuple[int, int, Any]]:
    """:func:`batches_as_they_finish` for a job without a cluster: each batch in turn."""
    for first, stop in batches:
        try:
            result = evaluate(job, first, stop)
        except Exception as exc:  # judged by the caller, as a remote task's
            result = exc
        yield first, stop, result


def gather(
    workers: Workers,
    evaluate: Callable[..., Any],
    job: Any,
    batches: list[tuple[int, int]],
    count: int,
    add: Callable[[int, int, Any], int],
    progress: Callable[[int, int, int], None] | None = None,
    noun: str = "items",
    done: int = 0,
    failed: int = 0,
) -> None:
    """Run ``evaluate(job, first, stop)`` for every batch on ``workers`` and hand each
    result to ``add(first, stop, result)`` as it comes in, which returns how many of
    the batch's ``noun`` failed; ``progress(done, count, failed)`` after each (from
    ``done`` and ``failed`` already, those of a checkpoint).  A task that ends with an
    exception ends the job (:func:`attitude.jobs.failures.task_failure`: the
    cluster's or the machine's failure, or a bug), whatever the other tasks."""
    if progress:
        progress(done, count, failed)
    if workers.client is None:
        results = _in_this_process(evaluate, job, batches)
    else:
        results = batches_as_they_finish(workers.client, evaluate, job, batches)
    for first, stop, result in results:
        if isinstance(result, BaseException):
            raise task_failure(result, first, stop, noun, workers.where)
        failed += add(first, stop, result)
        done += stop - first
        if progress:
            progress(done, count, failed)
