"""The envelope's batch of failures (their pointing searches run as one set of arrays,
``attitude.pointing.search.pointing_analyses``, and their power searches together,
``attitude.envelope.failure._power_search``) against the same failures computed one at
a time (``failure_metrics``, and a batch of one) and in tasks of other sizes: the same
rows, bit for bit.

Each failure's points in the batched searches are those it has alone, every step is
element by element, and every decision (an extremum's best, a count of cells) is the
failure's own, so the rows must be identical, not merely within the search's
precision.  The failures span imaging, a slew, the
station pass and charging, in and out of the Earth's shadow, with the power threshold
reached at the loss, later in the window, and never; both wheel cases.
"""

import functools
import math

import numpy as np
import pytest

from attitude import EnvelopeSettings, InputError, Wheels, load_scenario
from attitude.envelope.failure import evaluate_batch, failure_metrics
from attitude.envelope.plan import make_job, plan_envelope
from attitude.jobs.failures import TaskError

SCENARIO = "scenarios/eo_envelope.toml"
CASES = {
    "locked, threshold 0.3": ("locked", 0.3, tuple(np.arange(0.0, 5400.0, 450.0))),
    "locked, threshold 0.05": ("locked", 0.05, (300.0, 2100.0, 3000.0, 3900.0)),
    "spinning": ("spinning", 0.3, (600.0, 3300.0)),
}


@functools.cache
def _rows(name: str):
    case, threshold, taus = CASES[name]
    settings = EnvelopeSettings(
        window=1200.0, times=taus, wheels=Wheels(case, [0.0, 2.0, 0.0]), power_threshold=threshold
    )
    job, _, _ = make_job(plan_envelope(load_scenario(SCENARIO), settings=settings))
    return job, evaluate_batch(job, 0, job.count).rows


def _same(a, b) -> bool:
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return type(a) is type(b) and a == b


@pytest.mark.parametrize("name", list(CASES))
def test_batch_rows_against_failures_one_at_a_time(name):
    job, batch = _rows(name)
    assert [row["status"] for row in batch] == ["ok"] * job.count
    for k, together in enumerate(batch):
        alone = evaluate_batch(job, k, k + 1).rows[0]
        assert list(together) == list(alone)
        differing = {
            c: (together[c], alone[c]) for c in together if not _same(together[c], alone[c])
        }
        assert not differing, (k, differing)
        metrics = failure_metrics(job, k)
        assert all(_same(together[c], metrics[c]) for c in metrics)


@pytest.mark.parametrize("size", [2, 3, 5])
def test_batch_rows_against_tasks_of_other_sizes(size):
    """The rows whatever the task they ran in: the failures cut into tasks of ``size``."""
    job, batch = _rows("locked, threshold 0.3")
    rows = [
        row
        for first in range(0, job.count, size)
        for row in evaluate_batch(job, first, min(first + size, job.count)).rows
    ]
    assert len(rows) == len(batch)
    for together, other in zip(batch, rows, strict=True):
        assert list(together) == list(other)
        differing = {
            c: (together[c], other[c]) for c in together if not _same(together[c], other[c])
        }
        assert not differing, (together["failure"], differing)


def test_the_batches_cover_every_outcome_of_the_power_search():
    """Power at or below the threshold at the loss, reaching it later, and never:
    else the comparison above would be idle."""
    lost = [row["power_lost_s"] for name in CASES for row in _rows(name)[1]]
    assert any(x == 0.0 for x in lost)
    assert any(0.0 < x < math.inf for x in lost)
    assert any(x == math.inf for x in lost)


def _planted(failure, bug: type[Exception]):
    """``motion_after`` with failure 2's motion refused, and failure 5's attitude
    raising ``bug`` within the task's searches together."""
    real = failure.motion_after

    def motion_after(job, k):
        if k == 2:
            raise InputError("no motion for failure 2")
        trajectory = real(job, k)
        if k == 5:
            solver = trajectory.segments[0].solver

            def refused(t, scalar_first=True):
                raise bug("the attitude of failure 5 overflows")

            solver.attitude_quaternion = refused
        return trajectory

    return motion_after


def test_a_refused_failure_in_a_task_is_its_own_row(monkeypatch):
    """A failure whose motion is refused, and one whose search is refused within the
    task's searches together (an InputError: their own input's refusal): each its own
    failed row, naming the error; the others the same rows as before, bit for bit (the
    task's searches run again one at a time)."""
    import attitude.envelope.failure as failure

    job, batch = _rows("locked, threshold 0.3")
    motion_after = _planted(failure, InputError)

    monkeypatch.setattr(failure, "motion_after", motion_after)
    rows = evaluate_batch(job, 0, job.count).rows
    for k, (row, before) in enumerate(zip(rows, batch, strict=True)):
        if k in (2, 5):
            assert row["status"] == "failed"
            assert ("failure 2" if k == 2 else "failure 5") in row["error"]
            assert all(math.isnan(row[c]) for c in job.columns)
        else:
            assert all(_same(row[c], before[c]) for c in before), k


def test_an_exception_no_input_explains_is_a_bug_naming_the_failure_not_a_row(monkeypatch):
    """An OverflowError in failure 5's search is not a refusal of its input: the task
    ends with a TaskError naming failure 5 (exit 3 on the command line), never a
    failed row (main at d285687 made it one)."""
    import attitude.envelope.failure as failure

    job, _ = _rows("locked, threshold 0.3")
    monkeypatch.setattr(failure, "motion_after", _planted(failure, OverflowError))
    with pytest.raises(TaskError) as caught:
        evaluate_batch(job, 0, job.count)
    assert str(caught.value).startswith("failure 5 (τ = 2250 s): OverflowError: the attitude")
    assert "Traceback" in caught.value.details
