"""The command line: ``attitude run`` and ``attitude check``.

    attitude run SCENARIO.toml --out DIR   propagate, write the outputs into DIR
    attitude check SCENARIO.toml           validate the file and describe it

Exit status: 0 on success, 2 for a bad scenario file (one message naming the file,
the key and the value), 1 when the outputs cannot be written.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from attitude.errors import InputError
from attitude.report import Progress, produce
from attitude.scenario_file import load_scenario
from attitude.trajectory import propagate
from attitude.version import __version__

__all__ = ["main"]


def _describe(path: Path) -> str:
    loaded = load_scenario(path)
    scenario = loaded.scenario
    craft = scenario.spacecraft
    solver = propagate(scenario).segments[0].solver
    lines = [
        f"{path}: OK",
        f"  scenario    {scenario.name}",
        f"  epoch       {scenario.format_epoch(0.0)}",
        f"  span        {scenario.stop_s:g} s, output every {scenario.step_s:g} s from "
        f"{scenario.format_epoch(scenario.start_s)} ({scenario.output_seconds().size} samples)",
        f"  spacecraft  {craft.name}, principal moments {craft.principal_moments.tolist()} kg m²",
        f"  motion      formula {solver.formula}, period {solver.period:.6g} s at the epoch",
        f"  events      {len(scenario.events)}",
    ]
    lines += [
        f"    {scenario.format_epoch(t)}  {event.kind}{f' ({event.label})' if event.label else ''}"
        for t, event in scenario.events
    ]
    spec = loaded.pointing
    if not spec.is_empty:
        lines.append(
            f"  pointing    {len(spec.body_vectors)} body vectors, orbit: "
            f"{'TLE' if spec.tle else 'Earth centre'}"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="attitude", description="Exact spacecraft attitude.")
    parser.add_argument("--version", action="version", version=f"attitude {__version__}")
    commands = parser.add_subparsers(dest="command", required=True)
    run = commands.add_parser("run", help="propagate a scenario and write its outputs")
    run.add_argument("scenario", type=Path, help="scenario file (TOML)")
    run.add_argument("--out", type=Path, required=True, help="output folder (replaced)")
    run.add_argument("--quiet", action="store_true", help="no progress messages")
    check = commands.add_parser("check", help="validate a scenario file")
    check.add_argument("scenario", type=Path, help="scenario file (TOML)")
    args = parser.parse_args(argv)

    try:
        if args.command == "check":
            print(_describe(args.scenario))
            return 0
        progress = Progress(None if args.quiet else lambda line: print(line, file=sys.stderr))
        loaded = load_scenario(args.scenario)
        produce(loaded.scenario, args.out, loaded.pointing, loaded.path.name, progress)
        return 0
    except InputError as exc:
        print(f"attitude: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:  # the file system: a full disk, a folder we cannot write
        print(f"attitude: error: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
