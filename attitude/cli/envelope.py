"""``attitude envelope``: the command (its options are parsed in ``attitude.cli.main``)."""

from __future__ import annotations

import sys
from pathlib import Path

from attitude.base.errors import InputError
from attitude.base.progress import Progress
from attitude.cli.montecarlo import ProgressBar, note
from attitude.envelope.job import envelope_job
from attitude.envelope.plan import plan_envelope
from attitude.envelope.report import OUTPUT_NAMES
from attitude.files.scenario_reader import ScenarioFile
from attitude.jobs.cluster import check_where
from attitude.outputs.folder import claim
from attitude.outputs.lock import refuse_if_held

__all__ = ["command"]


def command(args, loaded: ScenarioFile, stage: Progress | None = None) -> int:
    """``attitude envelope`` (the command line's options in ``args``): the envelope of
    ``loaded``'s ``[envelope]`` into ``--out``."""
    stage = stage or Progress()
    if args.out is None:
        raise InputError("the output folder is required", key="--out")
    claim(args.out, OUTPUT_NAMES, dry_run=True)  # the folder first: ours, writable, free
    refuse_if_held(args.out)
    if args.scheduler is not None:
        stage(f"trying the Dask scheduler at {args.scheduler}")
    check_where(args.scheduler, args.workers)
    stage("checking the scenario and the [envelope] table")
    plan = plan_envelope(loaded)
    bar = None if args.quiet else ProgressBar(sys.stderr, noun="failures")
    result = envelope_job(
        plan,
        args.out,
        loaded,
        workers=args.workers,
        scheduler=args.scheduler,
        batch_size=args.batch_size,
        progress=bar,
        stage=stage,
        note=lambda text: note(f"{loaded.path.name}: {text}"),
        resume=args.resume,
        probed=True,
        refuse_all_failed=True,
    )
    failed = result.table[result.table["status"] != "ok"]
    if len(failed):
        note(
            f"{loaded.path.name}: {len(failed)} of {plan.count} failures could not be "
            f"computed (the first: {failed.iloc[0]['error']})"
        )
    stage(f"done: {Path(args.out) / 'report.html'}")
    return 0
