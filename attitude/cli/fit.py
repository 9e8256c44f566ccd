"""``attitude fit``: the spin state and inertia ratios fitted to a telemetry file.

    attitude fit TELEMETRY --out DIR [--gyro-sigma "1e-4 rad/s"] [--attitude-sigma "5 arcsec"]
                 [--principal-axes] [--gyro-bias] [--scenario FILE.toml] [--time-scale utc]
                 [--epoch ISO]

TELEMETRY is a CSV, Parquet or CCSDS AEM file (attitude.estimation.telemetry_files).
``--scenario`` names a scenario file of the spacecraft whose orbit (``[pointing]``),
torques (``[torques]``: gravity gradient, burns) and angular impulses (``[[events]]``)
are known: the fit goes through them, and the fitted scenario keeps them.  The outputs
(attitude.estimation.report) go into DIR under the output folder's rules.

Exit status, one line on stderr: 0 success; 2 a bad file or option, telemetry that
does not determine the fit (``FitRefused``: the line says why), or an output folder
that is not ours; 1 the outputs cannot be written.  Signals as ``attitude run``
(``attitude.cli.main``).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

__all__ = ["add_parser", "command"]


def add_parser(commands) -> None:
    """``attitude fit``'s options (no heavy import: the parser is built before the
    signal handlers' protection ends)."""
    fit = commands.add_parser(
        "fit",
        help="fit the spin state and inertia ratios to telemetry (docs/estimation.md)",
    )
    fit.add_argument("telemetry", type=Path, help="telemetry file: CSV, Parquet or CCSDS AEM")
    fit.add_argument(
        "--out", type=Path, required=True, help="output folder (the rules of run --out)"
    )
    fit.add_argument("--gyro-sigma", metavar="RATE", help='gyro noise, with its unit: "1e-4 rad/s"')
    fit.add_argument(
        "--attitude-sigma",
        metavar="ANGLE",
        help='attitude noise per axis, with its unit: "5 arcsec"',
    )
    fit.add_argument(
        "--principal-axes",
        action="store_true",
        help="also estimate the principal axes in the telemetry's body axes (a misaligned sensor)",
    )
    fit.add_argument("--gyro-bias", action="store_true", help="also estimate a constant gyro bias")
    fit.add_argument(
        "--scenario",
        type=Path,
        help="a scenario file of the spacecraft: its orbit, torques and angular impulses are used",
    )
    fit.add_argument(
        "--time-scale", help="time scale of a 'time' column of ISO epochs (default utc)"
    )
    fit.add_argument("--epoch", help="the epoch a t_s column counts from, if the file does not say")
    fit.add_argument("--name", help="name of the fitted scenario (default: the telemetry's)")
    fit.add_argument("--quiet", action="store_true", help="no progress messages")


def _quantity(text: str | None, kind: str, option: str, counts: tuple[int, ...] = (1,)):
    """'1e-4 rad/s' as SI numbers (one value, or ``counts`` of them separated by commas:
    one per axis)."""
    if text is None:
        return None
    import math
    import re
    import warnings

    from astropy.units import UnitsWarning

    from attitude.base.errors import InputError
    from attitude.base.quantities import convert_unit

    number = r"[-+]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|nan|inf|infinity)"
    found = re.fullmatch(rf"\s*({number}(?:\s*,\s*{number})*)\s*(\S.*)?", text, flags=re.IGNORECASE)
    if not found or not found.group(2):
        raise InputError(
            f'{text!r} needs a value with its unit, e.g. "1e-4 rad/s"', key=option, value=text
        )
    values = [float(v) for v in found.group(1).split(",")]
    if len(values) not in counts:
        wanted = "one value" if counts == (1,) else "1 or 3 values (one per body axis)"
        raise InputError(f"{text!r}: {len(values)} values, where it takes {wanted}", key=option)
    with warnings.catch_warnings():  # astropy's style advice on "rad/s/s" is not ours
        warnings.simplefilter("ignore", UnitsWarning)
        converted = [float(convert_unit(v, found.group(2).strip(), kind, option)) for v in values]
    if not all(math.isfinite(v) and v > 0.0 for v in converted):
        raise InputError(f"must be positive and finite, got {text!r}", key=option, value=text)
    return converted[0] if len(converted) == 1 else converted


# The fit's parameters that refusals name, as the options of this command.
_OPTIONS = {
    "gyro_sigma": "--gyro-sigma",
    "attitude_sigma": "--attitude-sigma",
    "principal_axes": "--principal-axes",
    "gyro_bias": "--gyro-bias",
}


def _context(path: Path):
    """The orbit, torques and impulses of a scenario file: for the fit (its impulses and
    torques) and for the fitted scenario (their tables, at absolute epochs)."""
    import dataclasses

    from attitude.base.errors import InputError
    from attitude.estimation.report import FitContext
    from attitude.files.scenario_reader import load_scenario
    from attitude.files.scenario_writer import with_absolute_files

    loaded = load_scenario(path)
    scenario = loaded.scenario
    document = with_absolute_files(loaded.document, loaded.path.parent)
    raw_events = document.get("events", [])
    impulses, events = [], []
    indices = getattr(scenario, "event_indices", range(len(scenario.events)))
    for (offset, event), index in zip(scenario.events, indices, strict=True):
        if event.kind != "angular_impulse":
            raise InputError(
                f"a {event.kind} cannot be fitted through (the fit uses known angular "
                "impulses only)",
                file=path.name,
                key=f"events[{index}]",
            )
        epoch = scenario.times(offset)
        impulses.append(dataclasses.replace(event, epoch=epoch))
        table = {k: v for k, v in raw_events[index].items() if k not in ("offset", "epoch")}
        events.append((epoch, table))
    torques_table, burns = None, []
    if "torques" in document:
        torques_table = {k: v for k, v in document["torques"].items() if k != "burns"}
        placed = {b.index: b for b in scenario.burns}
        for k, burn in enumerate(document["torques"].get("burns", [])):
            table = {key: v for key, v in burn.items() if key not in ("offset", "epoch")}
            burns.append((scenario.times(placed[k].start_s), table))
    context = FitContext(
        source=loaded.path.name,
        time_scale=scenario.time_scale,
        pointing=document.get("pointing"),
        torques=torques_table,
        events=events,
        burns=burns,
    )
    torques = scenario.torques if scenario.torques.any else None
    if torques is not None and torques.burns:
        # The burns at absolute epochs: an offset counts from the file's epoch, and the
        # fit's t = 0 is the telemetry's first sample.
        at = {b.index: scenario.times(b.start_s) for b in scenario.burns}
        torques = dataclasses.replace(
            torques,
            burns=tuple(
                dataclasses.replace(burn, epoch=at[k]) for k, burn in enumerate(torques.burns)
            ),
        )
    return context, tuple(impulses), torques, scenario.orbit


def _check_time_options(args: argparse.Namespace) -> None:
    """--time-scale and --epoch refused at once when wrong, used by the file or not."""
    from attitude.base.errors import OptionError
    from attitude.environment.timescales import SCALES, as_time

    if args.time_scale is not None and args.time_scale.strip().lower() not in SCALES:
        raise OptionError(
            f"expected one of {', '.join(SCALES)}",
            key="--time-scale",
            value=args.time_scale,
        )
    if args.time_scale is not None:
        args.time_scale = args.time_scale.strip().lower()
    if args.epoch is not None:
        as_time(args.epoch, args.time_scale or "utc", "--epoch")


def command(args: argparse.Namespace, own_process: bool = False) -> int:
    """Run ``attitude fit`` (options parsed by attitude.cli.main); the exit status.

    Progress goes to stderr as ``attitude run``'s does (attitude.base.progress): each
    stage as it starts, the growing arc's stages with an estimate of the time left, on
    a clock that counts from the process's start (``own_process``)."""
    from attitude.base.errors import InputError
    from attitude.base.progress import Progress, process_started_at
    from attitude.outputs.folder import OutputFolderError, claim

    progress = Progress(
        None if args.quiet else lambda line: print(line, file=sys.stderr, flush=True),
        start=process_started_at() if own_process else None,
    )
    progress(f"reading {args.telemetry}")
    try:
        from attitude.estimation.fit import fit_spin_state
        from attitude.estimation.report import OUTPUT_NAMES, write_fit_report
        from attitude.estimation.telemetry_files import read_telemetry

        gyro_sigma = _quantity(args.gyro_sigma, "angular_velocity", "--gyro-sigma", (1, 3))
        attitude_sigma = _quantity(args.attitude_sigma, "angle", "--attitude-sigma")
        _check_time_options(args)
        claim(args.out, OUTPUT_NAMES, dry_run=True)  # a folder that is not ours: say so first
        context = impulses = torques = orbit = None
        if args.scenario is not None:
            context, impulses, torques, orbit = _context(args.scenario)
        telemetry = read_telemetry(args.telemetry, args.time_scale, args.epoch)
        if not hasattr(telemetry.times, "jd1"):
            raise InputError(
                "the times are relative seconds (t_s with no epoch): give --epoch, so that "
                "the fitted scenario has one",
                file=args.telemetry.name,
            )
        progress(f"{args.telemetry.name}: {len(telemetry.times)} rows read")
        fit = fit_spin_state(
            telemetry.times,
            angular_velocity=telemetry.angular_velocity,
            quaternions=telemetry.quaternions,
            gyro_sigma=gyro_sigma,
            attitude_sigma=attitude_sigma,
            principal_axes=args.principal_axes,
            gyro_bias=args.gyro_bias,
            impulses=impulses or (),
            torques=torques,
            orbit=orbit,
            source=args.telemetry.name,
            progress=progress,
        )
        fit.notes[:0] = telemetry.notes
        if not args.quiet:
            print(fit.summary(), file=sys.stderr, flush=True)
        name = args.name or f"{args.telemetry.stem} (fitted)"
        write_fit_report(fit, args.out, args.telemetry.name, name, context, progress=progress)
        progress(f"done: {Path(args.out) / 'report.html'}")
        return 0
    except OutputFolderError as exc:
        print(f"attitude: error: {exc}", file=sys.stderr, flush=True)
        return 2
    except InputError as exc:
        # Errors that name no file (an option, a fit's refusal) are the telemetry's; a
        # parameter of the fit is named as this command's option.
        located = exc.located(key=_OPTIONS[exc.key]) if exc.key in _OPTIONS else exc
        if not (located.file or (located.key or "").startswith("--")):
            located = located.located(file=args.telemetry.name)
        text = " / ".join(str(located).splitlines())
        print(f"attitude: error: {text}", file=sys.stderr, flush=True)
        return 2
    except MemoryError:
        print(f"attitude: error: {args.telemetry.name}: out of memory", file=sys.stderr)
        return 1
    except OSError as exc:
        where = f" ({exc.filename})" if getattr(exc, "filename", None) else ""
        print(f"attitude: error: {exc.strerror or exc}{where}", file=sys.stderr, flush=True)
        return 1
