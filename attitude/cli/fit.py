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


def _quantity(text: str | None, kind: str, option: str):
    """'1e-4 rad/s' as SI numbers (one value, or several separated by commas)."""
    if text is None:
        return None
    import re

    from attitude.base.errors import InputError
    from attitude.base.quantities import convert_unit

    number = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
    found = re.fullmatch(rf"\s*({number}(?:\s*,\s*{number})*)\s*(\S.*)?", text)
    if not found or not found.group(2):
        raise InputError(
            f'{text!r} needs a value with its unit, e.g. "1e-4 rad/s"', key=option, value=text
        )
    try:
        values = [float(v) for v in found.group(1).split(",")]
    except ValueError:
        raise InputError(f"{text!r}: not a number", key=option, value=text) from None
    converted = [float(convert_unit(v, found.group(2).strip(), kind, option)) for v in values]
    if not all(v > 0.0 for v in converted):
        raise InputError(f"must be positive, got {text!r}", key=option, value=text)
    return converted[0] if len(converted) == 1 else converted


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


def command(args: argparse.Namespace) -> int:
    """Run ``attitude fit`` (options parsed by attitude.cli.main); the exit status."""
    from attitude.base.errors import InputError
    from attitude.outputs.folder import OutputFolderError, claim

    def say(line: str) -> None:
        if not args.quiet:
            print(line, file=sys.stderr, flush=True)

    try:
        from attitude.estimation.fit import fit_spin_state
        from attitude.estimation.report import OUTPUT_NAMES, write_fit_report
        from attitude.estimation.telemetry_files import read_telemetry

        gyro_sigma = _quantity(args.gyro_sigma, "angular_velocity", "--gyro-sigma")
        attitude_sigma = _quantity(args.attitude_sigma, "angle", "--attitude-sigma")
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
        say(f"attitude fit: {args.telemetry.name}: {len(telemetry.times)} rows read; fitting")
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
        )
        fit.notes[:0] = telemetry.notes
        say(fit.summary())
        name = args.name or f"{args.telemetry.stem} (fitted)"
        write_fit_report(fit, args.out, args.telemetry.name, name, context)
        say(f"done: {Path(args.out) / 'report.html'}")
        return 0
    except OutputFolderError as exc:
        print(f"attitude: error: {exc}", file=sys.stderr, flush=True)
        return 2
    except InputError as exc:
        # Errors that name no file (an option, a fit's refusal) are the telemetry's.
        located = (
            exc
            if exc.file or (exc.key or "").startswith("--")
            else exc.located(file=args.telemetry.name)
        )
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
