"""Scenario files written back: a scenario document (the TOML that
:mod:`attitude.files.scenario_reader` reads) as text that reads back to the same document.

``tomli_w`` writes every float with ``repr``, the shortest text that reads back as the
same double, so a number drawn by a Monte Carlo job and written here is the number
the job used, to the last bit.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

__all__ = ["files_named", "scenario_text", "with_absolute_files"]


def scenario_text(document: dict[str, Any], comments: Sequence[str] = ()) -> str:
    """The TOML text of ``document``, after ``comments`` (each a ``#`` line)."""
    import tomli_w

    head = "".join(f"# {' '.join(line.split())}\n" for line in comments)
    return head + ("\n" if head else "") + tomli_w.dumps(document)


def with_absolute_files(document: dict[str, Any], folder: Path) -> dict[str, Any]:
    """``document`` with the files it names (``pointing.oem``, ``initial_state.aem``, an
    attitude reset's ``aem``), which the reader takes relative to the scenario file's
    folder, made absolute from ``folder``: the same files, wherever the document is
    written or read.  The tables it changes are copies."""
    folder = Path(folder).absolute()

    def resolved(table: Any, key: str) -> Any:
        if not isinstance(table, dict) or not isinstance(table.get(key), str):
            return table
        return {**table, key: str(folder / Path(table[key]).expanduser())}

    document = dict(document)
    if "pointing" in document:
        document["pointing"] = resolved(document["pointing"], "oem")
    if "initial_state" in document:
        document["initial_state"] = resolved(document["initial_state"], "aem")
    if isinstance(document.get("events"), list):
        document["events"] = [resolved(event, "aem") for event in document["events"]]
    return document


def files_named(document: dict[str, Any]) -> list[str]:
    """The files ``document`` names (those :func:`with_absolute_files` makes absolute),
    as written there."""
    tables = [document.get("pointing"), document.get("initial_state")]
    if isinstance(document.get("events"), list):
        tables += document["events"]
    found = []
    for table in tables:
        if isinstance(table, dict):
            found += [table[k] for k in ("oem", "aem") if isinstance(table.get(k), str)]
    return found
