"""Our CSV files (timeseries.csv, intervals.csv) read back by numpy, apart from our writer.

The ``#`` lines of the preamble are skipped and the header names the columns of the
structured array that ``np.genfromtxt`` returns.
"""

from pathlib import Path

import numpy as np


def read_csv(path: Path) -> np.ndarray:
    text = path.read_text()
    preamble = sum(1 for line in text.splitlines() if line.startswith("#"))
    return np.genfromtxt(
        path, delimiter=",", skip_header=preamble, names=True, dtype=None, encoding="utf-8"
    )
