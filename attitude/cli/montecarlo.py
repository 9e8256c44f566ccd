"""``attitude montecarlo``: the command (its options are parsed in ``attitude.cli.main``)."""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

from attitude.base.errors import InputError
from attitude.base.progress import Progress
from attitude.files.scenario_reader import ScenarioFile
from attitude.jobs.cluster import check_where
from attitude.montecarlo.job import montecarlo_job
from attitude.montecarlo.plan import emit_samples, plan_montecarlo
from attitude.montecarlo.report import OUTPUT_NAMES
from attitude.outputs.folder import claim
from attitude.outputs.lock import refuse_if_held

__all__ = ["ProgressBar", "command", "note"]


def note(text: str) -> None:
    """One ``attitude: note:`` line on stderr (shown whatever ``--quiet`` says)."""
    print(f"attitude: note: {text}", file=sys.stderr, flush=True)


def command(args, loaded: ScenarioFile, stage: Progress | None = None) -> int:
    """``attitude montecarlo`` (the command line's options in ``args``): run the job into
    ``--out``, or write samples ``--sample`` into ``--emit-scenario``; ``stage``: the
    command's progress messages (none when None)."""
    emit = args.emit_scenario is not None or args.sample is not None
    stage = stage or Progress()
    if not emit:  # where the job runs, checked first: an address tried takes seconds
        if args.out is not None:  # and the folder (ours, writable, free) before planning
            claim(args.out, OUTPUT_NAMES, dry_run=True)
            refuse_if_held(args.out)
        if args.scheduler is not None:
            stage(f"trying the Dask scheduler at {args.scheduler}")
        check_where(args.scheduler, args.workers)
    stage("checking the nominal scenario and the [dispersions] table")
    mc = plan_montecarlo(loaded, None, args.samples, args.seed)
    if emit:
        if args.emit_scenario is None or args.sample is None:
            raise InputError(
                "K goes with --emit-scenario DIR: give both or neither", key="--sample"
            )
        if args.out is not None:
            raise InputError("runs the job; --emit-scenario writes samples instead", key="--out")
        if args.resume:
            raise InputError(
                "continues a job; --emit-scenario writes samples instead", key="--resume"
            )
        for path in emit_samples(mc, args.sample, args.emit_scenario):
            print(path, flush=True)
        return 0
    if args.out is None:
        raise InputError("the output folder is required (or --emit-scenario)", key="--out")
    bar = None if args.quiet else ProgressBar(sys.stderr)
    result = montecarlo_job(
        mc,
        args.out,
        scheduler=args.scheduler,
        workers=args.workers,
        batch_size=args.batch_size,
        progress=bar,
        stage=stage,
        note=lambda text: note(f"{loaded.path.name}: {text}"),
        resume=args.resume,
        probed=True,
        refuse_all_failed=True,
    )
    failed = result.failed
    if len(failed):
        note(
            f"{loaded.path.name}: {len(failed)} of {mc.samples} samples "
            f"failed (the first: sample {failed.iloc[0]['sample']}: {failed.iloc[0]['error']}); "
            "statistics.json lists them with their parameters"
        )
    stage(f"done: {Path(args.out) / 'report.html'}")
    return 0


class ProgressBar:
    """A one-line progress bar on a text stream (redrawn in place on a terminal, a line
    every 10 % otherwise)."""

    def __init__(self, stream=None, width: int = 30, noun: str = "samples") -> None:
        self.stream = stream or sys.stderr
        self.noun = noun
        self.width = width
        self.start: float | None = None  # the first call: the samples start
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.shown = -1

    def __call__(self, done: int, total: int, failed: int) -> None:
        if self.start is None:
            self.start = time.perf_counter()
        fraction = done / total if total else 1.0
        if not self.tty:
            decile = int(10 * fraction)
            if decile == self.shown:
                return
            self.shown = decile
        elapsed = time.perf_counter() - self.start
        eta = elapsed / fraction - elapsed if fraction > 0 else math.nan
        filled = int(self.width * fraction)
        text = (
            f"[{'#' * filled}{'.' * (self.width - filled)}] {done}/{total} {self.noun}"
            + (f", {failed} failed" if failed else "")
            + f", {elapsed:.0f} s"
            + (f", {eta:.0f} s to go" if done < total and math.isfinite(eta) else "")
        )
        end = "\n" if not self.tty or done >= total else ""
        print(("\r" if self.tty else "") + text, end=end, file=self.stream, flush=True)
