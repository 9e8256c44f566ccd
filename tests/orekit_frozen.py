"""What the tests share about the frozen Orekit data of ``tests/data/orekit``
(written by ``tests/freeze_orekit_ccsds.py``): its CSV layout, and the one example
whose AEM is known to miss its tolerance."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest

# The torqued example's AEM misses its tolerance around the burn (issue 23; fixed on
# the branch that makes burn starts and stops AEM boundaries).
TORQUED_AEM_MISSES = pytest.mark.xfail(
    strict=True,
    reason="the torqued example's AEM is off by ~1e-5 rad around its burn, against 1e-6 "
    "declared: burn starts and stops are not yet AEM segment boundaries (branch "
    "truth-torqued)",
)


def read_frozen(path: Path) -> tuple[dict[str, str], np.ndarray]:
    """A frozen CSV: its ``# key: value`` header lines, and its rows (named columns)."""
    header, rows = {}, []
    for line in path.read_text().splitlines():
        if line.startswith("#"):
            key, colon, value = line[1:].strip().partition(": ")
            if colon:
                header[key] = value
        else:
            rows.append(line)
    return header, np.genfromtxt(io.StringIO("\n".join(rows)), delimiter=",", names=True)
