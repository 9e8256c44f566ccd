"""Scenario files written back: a scenario document (the TOML that
:mod:`attitude.scenario_file` reads) as text that reads back to the same document.

``tomli_w`` writes every float with ``repr``, the shortest text that reads back as the
same double, so a number drawn by a Monte Carlo job and written here is the number
the job used, to the last bit.
"""

from __future__ import annotations

from typing import Any

__all__ = ["scenario_text"]


def scenario_text(document: dict[str, Any], comments: list[str] = ()) -> str:
    """The TOML text of ``document``, after ``comments`` (each a ``#`` line)."""
    import tomli_w

    head = "".join(f"# {' '.join(line.split())}\n" for line in comments)
    return head + ("\n" if head else "") + tomli_w.dumps(document)
