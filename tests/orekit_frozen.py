"""What the tests share about the frozen Orekit data of ``tests/data/orekit``
(written by ``tests/freeze_orekit_ccsds.py``): its CSV layout."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np


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
