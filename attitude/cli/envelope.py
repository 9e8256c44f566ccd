"""``attitude envelope``: the command (its options are parsed in ``attitude.cli.main``)."""

from __future__ import annotations

import sys
from pathlib import Path

from attitude.base.errors import InputError
from attitude.base.progress import Progress
from attitude.cli.montecarlo import ProgressBar
from attitude.envelope.engine import simulate
from attitude.envelope.plan import plan_envelope
from attitude.envelope.report import check_folder, write_report
from attitude.files.scenario_reader import ScenarioFile
from attitude.jobs.cluster import check_where

__all__ = ["command"]


def command(args, loaded: ScenarioFile, stage: Progress | None = None) -> int:
    """``attitude envelope`` (the command line's options in ``args``): the envelope of
    ``loaded``'s ``[envelope]`` into ``--out``."""
    stage = stage or Progress()
    if args.out is None:
        raise InputError("the output folder is required", key="--out")
    if args.scheduler is not None:
        stage(f"trying the Dask scheduler at {args.scheduler}")
    check_where(args.scheduler, args.workers)
    stage("checking the scenario and the [envelope] table")
    plan = plan_envelope(loaded)
    check_folder(plan, args.out)
    bar = None if args.quiet else ProgressBar(sys.stderr, noun="failures")
    result = simulate(plan, args.scheduler, args.workers, args.batch_size, bar, stage, probed=True)
    failed = result.table[result.table["status"] != "ok"]
    if len(failed) == plan.count:
        raise InputError(f"every failure failed; the first: {failed.iloc[0]['error']}")
    write_report(result, args.out)
    if len(failed):
        print(
            f"attitude: note: {loaded.path.name}: {len(failed)} of {plan.count} failures "
            f"could not be computed (the first: {failed.iloc[0]['error']})",
            file=sys.stderr,
            flush=True,
        )
    stage(f"done: {Path(args.out) / 'report.html'}")
    return 0
