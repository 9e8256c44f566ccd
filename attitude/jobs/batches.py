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

__all__ = [
    "batch_ranges",
    "batches_as_they_finish",
    "check_batch_size",
    "choose_batch_size",
    "gather",
]

# A task should last this many times the scheduler's cost per task (so that the
# overhead is at most 1 %), and every worker should get at least this many tasks
# (balance at the end of the job, and a progress bar that moves).
_OVERHEAD_FACTOR = 100

_TASKS_PER_WORKER = 4


def choose_batch_size(count: int, workers: int, item_s: float, task_overhead_s: float) -> int:
    """Items per task: enough that a task lasts _OVERHEAD_FACTOR times the scheduler's
    cost per task, few enough that every worker gets _TASKS_PER_WORKER tasks."""
    long_enough = math.ceil(_OVERHEAD_FACTOR * task_overhead_s / max(item_s, 1e-9))
    balanced = math.ceil(count / (_TASKS_PER_WORKER * max(workers, 1)))
    return max(1, min(long_enough, balanced))


def check_batch_size(batch_size: int | None, count: int) -> None:
    """A ``--batch-size`` given for a job of ``count`` items: 1 to ``count``."""
    if batch_size is not None and not 1 <= batch_size <= count:
        raise InputError(
            f"expected 1 to {count}, got {batch_size}", key="--batch-size", value=batch_size
        )


def batch_ranges(count: int, size: int) -> list[tuple[int, int]]:
    """[first, stop) of each task's items, ``size`` at a time over ``count``."""
    return [(first, min(first + size, count)) for first in range(0, count, size)]


def batches_as_they_finish(
    client, evaluate: Callable[..., Any], job: Any, batches: list[tuple[int, int]]
) -> Iterator[tuple[int, int, Any]]:
    """Send ``job`` once to every worker, one task ``evaluate(job, first, stop)`` per
    batch, and yield ``(first, stop, result)`` as the tasks finish, each released once
    read; ``result`` is the task's value, or the exception of a task that died (a
    worker killed, say)."""
    from distributed import as_completed

    shared = client.scatter(job, broadcast=True, hash=False)
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
        yield first, stop, result
        future.release()


def gather(
    client,
    evaluate: Callable[..., Any],
    job: Any,
    batches: list[tuple[int, int]],
    count: int,
    add: Callable[[int, int, Any], int],
    progress: Callable[[int, int, int], None] | None = None,
) -> None:
    """Run ``evaluate(job, first, stop)`` for every batch on ``client``'s cluster and
    hand each result to ``add(first, stop, result)`` as it comes in (``result``: the
    task's value, or the exception of a task that died), which returns how many of the
    batch's items failed; ``progress(done, count, failed)`` after each."""
    done = failed = 0
    if progress:
        progress(0, count, 0)
    for first, stop, result in batches_as_they_finish(client, evaluate, job, batches):
        failed += add(first, stop, result)
        done += stop - first
        if progress:
            progress(done, count, failed)
