"""The command line: ``attitude run``, ``check``, ``montecarlo`` and ``envelope`` (also
``python -m attitude``).

    attitude run SCENARIO.toml --out DIR   propagate, write the outputs into DIR
    attitude check SCENARIO.toml           validate the file and describe the run
    attitude montecarlo SCENARIO.toml --out DIR   the [dispersions] samples, on Dask
    attitude envelope SCENARIO.toml --out DIR     the [envelope] of control losses, on Dask

``run`` and ``check`` take ``--formats csv,parquet,aem,plots,report`` (the outputs to
write; default ``csv,aem,plots,report``, or the file's ``[output] formats``) and
``--aem-tolerance "1e-6 rad"`` (the accuracy the AEM is sampled for; an angle with its
unit).  ``montecarlo`` and ``envelope`` write their own outputs (``docs/montecarlo.md``,
``docs/envelope.md``).
``check`` goes through the same checks as ``run`` up to the sampling
(``attitude.report.plan``): what ``check`` accepts, ``run`` computes, and it states the
size of each chosen output.  ``--out`` given to ``check`` also checks the folder and
its disk's free space; without it, the disk of the current folder (where a relative
``--out`` goes) is checked, and said.  Both commands say on stderr what they are doing
from their first second, on a clock from the process's start (``--quiet``: nothing).

The output folder (``attitude.outputs.folder``): ``run`` writes into a new or empty
folder, or one it wrote before, where it replaces only its own previous outputs; it
never removes or overwrites a file it did not write.

Exit status, with one line on stderr and never a traceback (docs/cli.md has the
table): 0 success; 2 a bad scenario file, a run that cannot fit, an output folder that
is not ours, cannot be written (found before computing) or that another run holds, a
job's ``--resume`` of another job (the line names the file, the key and the value); 1
the machine failed the run (a full disk, memory; a job's lost scheduler, workers that
keep dying: :class:`~attitude.base.errors.MachineError`); 130 interrupted (Ctrl-C),
143 terminated (SIGTERM), 129 hung up (SIGHUP), 128 + N for a process of the run that
another signal N killed, and nothing of the run is left behind but a job's checkpoint,
which its line names (a signal the caller ignores, as ``nohup`` does SIGHUP, stays
ignored: ``attitude.base.signals``); 3 a bug (an exception this tool did not expect,
also in a job's task: ``attitude.jobs.failures``; ``ATTITUDE_TRACEBACK=1`` shows its
traceback).  Warnings are one line each, ``attitude: warning: FILE: KEY: ...``, and so
are notes (``attitude: note: ...``: a clamped precision, a far TLE epoch).

This module imports the package only inside :func:`main`, after the signal handlers
are installed, so that even a Ctrl-C while numpy loads ends with one line.
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import os
import signal
import sys
import threading
from pathlib import Path
from typing import Any

__all__ = ["main"]


def _raise_stopped(number: int, frame) -> None:
    from attitude.base.signals import Stopped

    raise Stopped(number)


def _one_line(text: str) -> str:
    return " / ".join(line.strip() for line in str(text).splitlines() if line.strip())


def _error(message: str) -> None:
    print(f"attitude: error: {_one_line(message)}", file=sys.stderr, flush=True)


def _parser() -> argparse.ArgumentParser:
    from attitude.base.version import __version__

    parser = argparse.ArgumentParser(prog="attitude", description="Exact spacecraft attitude.")
    parser.add_argument("-V", "--version", action="version", version=f"attitude {__version__}")
    commands = parser.add_subparsers(dest="command", required=True)
    run = commands.add_parser("run", help="propagate a scenario and write its outputs")
    run.add_argument("scenario", type=Path, help="scenario file (TOML)")
    run.add_argument(
        "--out",
        type=Path,
        required=True,
        help="output folder: new, empty, or written by attitude before (only its own "
        "files are replaced; a folder holding other files is refused)",
    )
    run.add_argument("--quiet", action="store_true", help="no progress messages")
    check = commands.add_parser("check", help="validate a scenario file and describe the run")
    check.add_argument("scenario", type=Path, help="scenario file (TOML)")
    check.add_argument(
        "--out",
        type=Path,
        help="also check this output folder, and its disk's free space (default: the "
        "current folder's disk, where a relative --out goes)",
    )
    check.add_argument("--quiet", action="store_true", help="no progress messages")
    for command in (run, check):
        command.add_argument(
            "--formats",
            help="the outputs to write, comma-separated, from csv, parquet, aem, plots, report "
            "(default: the file's [output] formats, else csv,aem,plots,report); "
            "summary.json, and intervals.csv with [pointing], are always written",
        )
        command.add_argument(
            "--aem-tolerance",
            metavar="ANGLE",
            help="the AEM is sampled so that its declared interpolation stays within this "
            'of the exact attitude, with its unit: "1e-6 rad" (the default), "0.2 arcsec"',
        )
    _montecarlo_parser(commands)
    _envelope_parser(commands)
    from attitude.cli.fit import add_parser as add_fit_parser

    add_fit_parser(commands)
    return parser


def _montecarlo_parser(commands) -> None:
    """``attitude montecarlo``: the dispersed samples of a scenario on Dask."""
    mc = commands.add_parser(
        "montecarlo",
        help="run the [dispersions] samples of a scenario on Dask (docs/montecarlo.md)",
    )
    mc.add_argument("scenario", type=Path, help="scenario file (TOML) with [dispersions]")
    mc.add_argument("--out", type=Path, help="output folder (the rules of run --out)")
    mc.add_argument("--samples", type=int, help="sample count (replaces the file's)")
    mc.add_argument("--seed", type=int, help="seed (replaces the file's)")
    _dask_arguments(mc, "samples")
    mc.add_argument(
        "--sample", type=int, action="append", help="with --emit-scenario: sample K (repeatable)"
    )
    mc.add_argument(
        "--emit-scenario",
        type=Path,
        metavar="DIR",
        help="write sample K as DIR/sample_K.toml, an ordinary scenario, instead of running",
    )
    mc.add_argument("--quiet", action="store_true", help="no progress bar or messages")


def _envelope_parser(commands) -> None:
    """``attitude envelope``: the loss-of-control envelope of a scenario on Dask."""
    envelope = commands.add_parser(
        "envelope",
        help="a control loss at every failure time of [envelope], on Dask (docs/envelope.md)",
    )
    envelope.add_argument("scenario", type=Path, help="scenario file (TOML) with [envelope]")
    envelope.add_argument("--out", type=Path, help="output folder (the rules of run --out)")
    _dask_arguments(envelope, "failures")
    envelope.add_argument("--quiet", action="store_true", help="no progress bar or messages")


def _dask_arguments(parser, items: str) -> None:
    """Where a Dask job runs, how many of its ``items`` a task takes, and ``--resume``."""
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--scheduler", help="address of a Dask scheduler (default: local)")
    where.add_argument(
        "--workers",
        type=int,
        help="local worker processes (default: all cores; 1: this process, no cluster)",
    )
    parser.add_argument("--batch-size", type=int, help=f"{items} per task (default: from costs)")
    parser.add_argument(
        "--resume",
        action="store_true",
        help=f"continue the interrupted job whose checkpoint --out holds (its finished {items}); "
        "without it, a checkpoint found there is discarded",
    )


def _outputs(args, outputs):
    """``outputs`` (the file's) with the command line's --formats and --aem-tolerance."""
    import dataclasses
    import re

    from attitude.base.errors import InputError
    from attitude.base.quantities import convert_unit
    from attitude.outputs.aem_sampling import check_tolerance
    from attitude.outputs.formats import parse_formats

    if args.formats is not None:
        outputs = dataclasses.replace(outputs, formats=parse_formats(args.formats))
    if args.aem_tolerance is not None:
        text = args.aem_tolerance
        found = re.fullmatch(r"\s*([-+]?[0-9.]+(?:[eE][-+]?\d+)?)\s*(\S.*)?", text)
        if not found or not found.group(2):
            raise InputError(
                f'--aem-tolerance: {text!r} needs an angle with its unit, e.g. "1e-6 rad" '
                'or "0.2 arcsec"'
            )
        value = convert_unit(
            float(found.group(1)), found.group(2).strip(), "angle", "--aem-tolerance"
        )
        outputs = dataclasses.replace(
            outputs,
            aem_tolerance_rad=check_tolerance(float(value), "--aem-tolerance"),
            tolerance_key="--aem-tolerance",
        )
    return outputs


def _describe(loaded, plan, out: Path | None = None) -> str:
    """What ``attitude check`` prints: the run as it will be done."""
    import math

    import numpy as np

    scenario = loaded.scenario
    craft = scenario.spacecraft
    lines = [
        f"{loaded.path}: OK",
        f"  scenario    {scenario.name}",
        f"  epoch       {scenario.format_epoch(0.0)}",
        f"  span        {scenario.stop_s:.12g} s, to {scenario.format_epoch(scenario.stop_s)}",
        f"  output      every {scenario.step_s:.12g} s from "
        f"{scenario.format_epoch(scenario.start_s)}",
        f"  formats     {','.join(plan.outputs.formats)}",
        f"  outputs     {plan.budget.describe()}",
        f"  spacecraft  {craft.name}, principal moments "
        f"[{', '.join(f'{v:.6g}' for v in craft.principal_moments)}] kg m²",
    ]
    initial = scenario.initial_state
    if initial.law is not None:
        lines.append(f"  law         {initial.law.name}: {initial.law.describe()} (at the epoch)")
    if initial.angular_velocity is not None:
        rate = ", ".join(f"{v:.6g}" for v in np.degrees(initial.angular_velocity))
        lines.append(f"  rate        [{rate}] deg/s (body, at the epoch)")
    for index, item in enumerate(plan.motion):
        period = "" if math.isinf(item.period_s) else f", body period {item.period_s:.6g} s"
        if item.flip_count is None:
            flips = ", flips located by run"
        elif item.flip_count:
            flips = f", {item.flip_count} flip{'' if item.flip_count == 1 else 's'}"
        else:
            flips = ""
        how = "splitting" if item.formula in ("torqued", "gyrostat") else f"formula {item.formula}"
        if item.formula in ("guided", "slew"):  # a law holds the attitude
            how = plan.trajectory.segments[index].solver.describe()
        lines.append(
            f"  segment {index}   from {scenario.format_epoch(item.start_s)}: {item.motion} "
            f"({how}{period}{flips})"
        )
    from attitude.report.torques import is_exact, torques_lines

    lines += [f"  {line}" for line in torques_lines(plan)]
    from attitude.report.guidance import guidance_lines

    lines += [f"  {line}" for line in guidance_lines(plan)]
    lines.append(f"  events      {len(scenario.events)}")
    lines += [
        f"    {scenario.format_epoch(t)} (+{t:.12g} s)  {event.kind}"
        f"{f' ({event.label})' if event.label else ''}"
        for t, event in scenario.events
    ]
    from attitude.pointing.spec import describe_lines

    lines += [f"  {line}" for line in describe_lines(loaded.pointing)]
    if plan.aem is not None:
        lines.append(f"  aem         {plan.aem.describe(is_exact(plan))}")
    from attitude.outputs.budget import free_disk_bytes, size_text

    if out is None:
        lines.append(
            f"  disk        {size_text(free_disk_bytes(Path.cwd()))} free on the current "
            "folder's disk, where `run --out DIR` writes a relative DIR: enough "
            "(`check --out DIR` checks another)"
        )
    else:
        lines.append(f"  disk        {size_text(free_disk_bytes(out))} free for {out}: enough")
    lines += [f"  note        {note}" for note in plan.notes]
    return "\n".join(lines)


def _run(args, state: dict) -> int:
    """``run`` or ``check``, with every warning shown as one line naming the file."""
    import warnings

    def show_warning(message, category, filename, lineno, file=None, line=None):
        text = _one_line(str(message))
        name = state.get("file")
        if name and not text.startswith(f"{name}:"):
            text = f"{name}: {text}"
        print(f"attitude: warning: {text}", file=sys.stderr, flush=True)

    with warnings.catch_warnings():
        warnings.showwarning = show_warning
        if args.command == "fit":
            from attitude.cli.fit import command

            return command(args, own_process=state.get("argv") is None)
        return _checked_run(args, state)


def _checked_run(args, state: dict) -> int:
    # What is being done, from the first second (before numpy and astropy load), on a
    # clock that counts from the process's start: `done` states the whole wait.
    from attitude.base.progress import Progress, process_started_at

    progress = Progress(
        None if args.quiet else lambda line: print(line, file=sys.stderr, flush=True),
        # The command line's clock starts with its process; main([...]) called from a
        # Python session that has run for hours starts its own.
        start=process_started_at() if state.get("argv") is None else None,
    )
    progress(f"reading {args.scenario}")
    from attitude.base.errors import InputError, MachineError
    from attitude.files.scenario_reader import ScenarioFileError, load_scenario
    from attitude.jobs.failures import TaskError
    from attitude.outputs.folder import OutputFolderError, claim
    from attitude.outputs.formats import OUTPUT_NAMES, OutputChoice
    from attitude.outputs.lock import folder_lock

    try:
        # The command line's own options first: their errors name the option, not a file.
        try:
            if args.command not in ("montecarlo", "envelope"):  # they write no time series
                _outputs(args, OutputChoice())
        except InputError as exc:
            _error(str(exc))
            return 2
        loaded = load_scenario(args.scenario)
        state["file"] = loaded.path.name
        with contextlib.ExitStack() as held:
            if args.command == "run":  # the folder checked and held before any computing
                claim(args.out, OUTPUT_NAMES, dry_run=True)
                held.enter_context(folder_lock(args.out, "run"))
            elif args.command == "check" and args.out is not None:
                claim(args.out, _folder_names(loaded), dry_run=True)
            return _command(args, loaded, progress)
    except (ScenarioFileError, OutputFolderError) as exc:
        _error(_with_notes(str(exc), exc))
        return 2
    except InputError as exc:  # from the file's values: named after the file, unless it names one
        _error(
            _with_notes(
                str(exc if exc.file else exc.located(file=state.get("file") or args.scenario.name)),
                exc,
            )
        )
        return 2
    except MachineError as exc:  # the machine or the cluster: the disk, a lost scheduler
        _error(_with_notes(str(exc), exc))
        return 1
    except TaskError as exc:  # a bug met by a job's task: the sample or failure named
        if os.environ.get("ATTITUDE_TRACEBACK") and exc.details:
            print(exc.details, file=sys.stderr, end="", flush=True)
        _error(_with_notes(f"internal error: {exc} ({_BUG})", exc))
        return 3
    except MemoryError:
        _error(f"{args.scenario.name}: out of memory: use a longer output.step or a shorter span")
        return 1
    except BrokenPipeError:
        raise  # stdout closed by the reader: see main
    except OSError as exc:  # the file system: a full disk, a folder we cannot write
        where = f" ({exc.filename})" if getattr(exc, "filename", None) else ""
        _error(_with_notes(f"{exc.strerror or exc}{where}", exc))
        return 1


_BUG = "a bug: please report it; ATTITUDE_TRACEBACK=1 shows the traceback"


def _left_behind(exc: BaseException) -> str:
    """What a stopped run leaves: nothing, or what its job's checkpoint kept."""
    notes = getattr(exc, "__notes__", None)
    return "; ".join(notes) if notes else "nothing of this run was left behind"


def _with_notes(line: str, exc: BaseException) -> str:
    """``line`` and the notes the job added to ``exc`` (what its checkpoint kept)."""
    notes = getattr(exc, "__notes__", None) or []
    return "; ".join([line, *notes])


def _command(args, loaded, progress) -> int:
    """The command of ``args`` on the scenario file ``loaded`` (errors: the caller's)."""
    from attitude.outputs.budget import check_fits
    from attitude.report.plan import horizon_beside, plan_run

    if args.command == "montecarlo":
        from attitude.cli.montecarlo import command

        return command(args, loaded, progress)
    if args.command == "envelope":
        from attitude.cli.envelope import command as envelope_command

        return envelope_command(args, loaded, progress)
    outputs = _outputs(args, loaded.outputs)
    # A run computes the validity horizon beside its outputs (attitude.report.run).
    checking = args.command == "check"
    if "envelope" in loaded.document:  # the table in a moment, before the long checks
        from attitude.envelope.plan import check_envelope_table

        check_envelope_table(loaded)
    plan = plan_run(
        loaded.scenario,
        loaded.pointing,
        outputs,
        horizon=checking,
        progress=progress,
        check=checking,
    )
    montecarlo = None
    if "dispersions" in loaded.document:  # checked by run too: one reading of the file
        from attitude.montecarlo.plan import plan_montecarlo

        montecarlo = plan_montecarlo(loaded, plan)
    envelope = None
    if "envelope" in loaded.document:  # the same checks as `attitude envelope`
        from attitude.envelope.plan import plan_envelope

        envelope = plan_envelope(loaded, plan=plan)
    if args.command == "check":
        if args.out is not None:
            check_fits(plan.budget, args.out)
            _check_folder(args.out, montecarlo, envelope)
        else:  # the disk a run writes to without a path: the current folder's
            check_fits(plan.budget, Path.cwd(), shown=f"the current folder ({Path.cwd()})")
        print(_describe(loaded, plan, args.out), flush=True)
        for line in _folder_lines(args.out) if args.out is not None else []:
            print(line, flush=True)
        if montecarlo is not None:
            print("\n".join(montecarlo.describe()), flush=True)
            print(_job_time(progress, "samples", montecarlo.samples, montecarlo), flush=True)
        if envelope is not None:
            print("\n".join(envelope.describe()), flush=True)
            print(_job_time(progress, "failures", envelope.count, envelope), flush=True)
        return 0
    for note in plan.notes:
        print(f"attitude: note: {loaded.path.name}: {note}", file=sys.stderr, flush=True)
    # The horizon's screen, and the splitting beside the run if the screen cannot
    # answer, before the writers and plots are imported.
    with horizon_beside(plan) or contextlib.nullcontext() as horizon:
        from attitude.report.run import write_report

        write_report(
            loaded.scenario,
            args.out,
            loaded.pointing,
            loaded.path.name,
            progress,
            plan,
            horizon=horizon,
            lock=False,  # held since the start (_checked_run)
        )
    return 0


def _folder_names(loaded) -> set[str]:
    """The files the commands a scenario file allows may write into one folder (a
    folder of ``run``'s, ``montecarlo``'s or ``envelope``'s): what ``check --out``
    takes the folder for."""
    from attitude.outputs.formats import OUTPUT_NAMES

    names = set(OUTPUT_NAMES)
    if "dispersions" in loaded.document:
        from attitude.montecarlo.report import OUTPUT_NAMES as MONTECARLO_NAMES

        names |= set(MONTECARLO_NAMES)
    if "envelope" in loaded.document:
        from attitude.envelope.report import OUTPUT_NAMES as ENVELOPE_NAMES

        names |= set(ENVELOPE_NAMES)
    return names


def _check_folder(out: Path, montecarlo, envelope) -> None:
    """``check --out``: the disk for a job's table, and the folder again (checked
    before the plan: :func:`_checked_run`)."""
    if montecarlo is not None:
        from attitude.montecarlo.report import check_folder as check_montecarlo_folder

        check_montecarlo_folder(montecarlo, out)
    if envelope is not None:
        from attitude.envelope.report import check_folder as check_envelope_folder

        check_envelope_folder(envelope, out)


def _folder_lines(out: Path) -> list[str]:
    """What ``check --out`` says of the folder: a run writing into it, a checkpoint."""
    from attitude.jobs.checkpoint import checkpoint_summary
    from attitude.outputs.lock import lock_holder

    lines = []
    holder = lock_holder(out)
    if holder is not None:
        lines.append(f"  folder      {out}: another run, {holder}, is writing into it now")
    kept = checkpoint_summary(out)
    if kept is not None:
        lines.append(f"  checkpoint  {kept}")
    return lines


def _job_time(progress, noun: str, count: int, plan) -> str:
    """``check``'s time estimate of a job: one item timed beside (a forked process,
    given twice the check's budget), times the items, over the cores here."""
    from attitude.envelope.plan import failure_cost_s
    from attitude.montecarlo.plan import sample_cost_s
    from attitude.report.beside import Beside
    from attitude.trajectory.steps import CHECK_BUDGET_S

    one = noun[:-1]
    cost: Any = sample_cost_s if noun == "samples" else failure_cost_s
    progress(f"timing a {one} for the job's time estimate")
    cores = len(os.sched_getaffinity(0))
    budget = 2 * CHECK_BUDGET_S
    with Beside(cost, plan) as timing:
        per_item = timing.result() if timing.ready(budget) else None
    if per_item is None:
        return (
            f"  time        not timed: a {one} took more than {budget:g} s here (the check's "
            f"budget), so {count:,} {noun} take more than {_duration(budget * count)} of CPU"
        )
    total = per_item * count
    return (
        f"  time        about {_duration(total)} of CPU ({per_item:.3g} s a {one}, timed "
        f"now), about {_duration(total / cores)} on this machine's {cores} "
        f"core{'s' if cores > 1 else ''} (and a few seconds to start a local cluster)"
    )


def _duration(seconds: float) -> str:
    if seconds < 120:
        return f"{seconds:.2g} s"
    if seconds < 7200:
        return f"{seconds / 60:.3g} min"
    return f"{seconds / 3600:.3g} h"


# Python's full collections during a command: at most one per this many younger ones
# (Python's default: 10).  See _collect_for_a_command.
_FULL_COLLECTION_EVERY = 100


@contextlib.contextmanager
def _collect_for_a_command(own_process: bool):
    """The garbage collector of a command's own process (``attitude ...``, not
    ``main([...])`` called from a Python session, whose collector is left alone).

    What a command imports (numpy, scipy, astropy, matplotlib: some 200 000 objects
    that live until the process ends) makes Python's full collections, each of which
    walks every object, frequent while it loads and long each time: a quarter of a
    second of a one-hour run's CPU.  They come ten times less often here; the younger
    generations, where a run's own cycles die, are collected as usual.  At the end,
    what is left is frozen (``gc.freeze``): the interpreter's exit would otherwise
    walk it all again, collection after collection, as it empties the modules (0.2 s
    more).  The exit still runs its atexit handlers, flushes the standard streams and
    frees every object that no cycle holds; the command's files are closed by then."""
    if not own_process:
        yield
        return
    young, middle, _ = gc.get_threshold()
    gc.set_threshold(young, middle, _FULL_COLLECTION_EVERY)
    try:
        yield
    finally:
        gc.freeze()


def main(argv: list[str] | None = None) -> int:
    with _collect_for_a_command(argv is None):
        return _main(argv)


def _main(argv: list[str] | None) -> int:
    try:  # a few small modules, no numpy: the handlers go in right after
        from attitude.base.signals import STOPPING, Stopped, caller_ignores
    except KeyboardInterrupt:
        _error("interrupted; nothing of this run was left behind")
        return 130
    state: dict = {}
    previous = {}
    in_main_thread = threading.current_thread() is threading.main_thread()
    try:
        if in_main_thread:
            # SIGINT is Python's KeyboardInterrupt; a signal the caller ignores
            # (nohup's SIGHUP, a background job's SIGINT) stays ignored.
            for number in STOPPING:
                if number != signal.SIGINT and not caller_ignores(number):
                    previous[number] = signal.signal(number, _raise_stopped)
        args = _parser().parse_args(argv)
        state["argv"] = argv
        return _run(args, state)
    except KeyboardInterrupt as exc:
        _error(f"interrupted; {_left_behind(exc)}")
        return 130
    except Stopped as stop:
        _error(f"{stop.text}; {_left_behind(stop)}")
        return stop.exit_status
    except BrokenPipeError:  # `attitude check x | head -1`
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 0
    except Exception as exc:  # a bug: one line, and the traceback on request
        if os.environ.get("ATTITUDE_TRACEBACK"):
            raise
        _error(
            f"internal error: {type(exc).__name__}: {exc} (a bug: please report it; "
            "ATTITUDE_TRACEBACK=1 shows the traceback)"
        )
        return 3
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)


if __name__ == "__main__":
    sys.exit(main())
