"""What reading a CCSDS OEM or AEM file takes, shared by :mod:`attitude.environment.oem` and
:mod:`attitude.files.aem_reader`: the parser, time systems, epochs, and interpolation.

**The parser** is ccsds-ndm-py (import name ``ccsds_ndm``, a Rust implementation of
the CCSDS Navigation Data Messages, KVN and XML, https://pypi.org/project/ccsds-ndm-py/):
it reads the structure, the keywords and the numbers.  It is lenient where these
readers are not, so they check in numpy what it lets through: a data line with too
few values (it reads a missing velocity as 0), epochs that do not increase, numbers
that are not finite, time systems and frames the package cannot place.

**Time systems** (SANA registry, CCSDS 502.0-B-3 annex B): UTC, TT, TAI, TDB, TCG,
TCB as astropy's scales, and GPS as TAI − 19 s.  **Epochs** are ``YYYY-MM-DDThh:mm:ss``
or ``YYYY-DDDThh:mm:ss`` (day of year), with any fraction of a second, optionally
ending in ``Z``.

**Interpolation** between records, as a file's metadata declares it, on the records
around each epoch (§ "INTERPOLATION" of the ODM and ADM standards): ``LAGRANGE`` of
degree d through d + 1 records, ``HERMITE`` of degree d through ⌈(d + 1)/2⌉ records
with values and derivatives (the polynomial of degree d that matches both; Orekit reads
d + 1 records instead, a higher degree), ``LINEAR`` through 2.  The records are centred
on the interval that holds the epoch (shifted inward at the ends of a segment).  The
polynomial of each window is solved once in the Chebyshev basis on [−1, 1] (well
conditioned up to the degree 15 allowed here) and evaluated, with its derivative, at
every epoch of that window.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
from numpy.polynomial import chebyshev
from numpy.typing import NDArray

from attitude.base.errors import InputError
from attitude.environment.timescales import offline_time

__all__ = [
    "MAX_DEGREE",
    "MAX_FILE_BYTES",
    "interpolate",
    "parse_epochs",
    "read_message",
    "scale_of",
]

# Files larger than this are refused before parsing (a month of 1 s OEM states is 0.2 GB).
MAX_FILE_BYTES = 512 << 20
MAX_DEGREE = 15
_SCALES = {"UTC": "utc", "TT": "tt", "TAI": "tai", "TDB": "tdb", "TCG": "tcg", "TCB": "tcb"}
_DAY_OF_YEAR = re.compile(r"^(\d{4})-(\d{3})T(\d{2}):(\d{2}):(\d{2}(?:\.\d*)?)Z?$")
_CALENDAR = re.compile(r"^\d{4}-\d{2}-\d{2}T\d{2}:\d{2}:\d{2}(?:\.\d*)?Z?$")


def read_message(path: Path, kind: str) -> Any:
    """The ``kind`` ("Oem" or "Aem") message in the file at ``path``, parsed by
    ccsds-ndm-py; :class:`InputError` naming the file for anything that is not one."""
    import ccsds_ndm

    name = path.name
    try:
        size = path.stat().st_size
        if not path.is_file():
            raise InputError(f"{path}: not a file (a folder, a device...)")
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {exc.strerror or exc}") from None
    if size > MAX_FILE_BYTES:
        raise InputError(f"{name}: larger than {MAX_FILE_BYTES >> 20} MiB: not read")
    try:
        text = path.read_bytes().decode("ascii")
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise InputError(
            f"{name}: not a CCSDS {kind.upper()} in KVN: not ASCII text (byte {exc.start})"
        ) from None
    try:
        message = getattr(ccsds_ndm, kind).from_str(text, "kvn")
    except (ValueError, TypeError, OSError) as exc:
        reason = " / ".join(line.strip() for line in str(exc).splitlines() if line.strip())
        raise InputError(f"{name}: not a CCSDS {kind.upper()} (KVN): {reason[:200]}") from None
    if not message.segments:
        raise InputError(f"{name}: no segment")
    return message, text


def scale_of(time_system: str, where: str) -> tuple[str, float]:
    """The astropy scale of a CCSDS TIME_SYSTEM, and the seconds to add to its epochs
    read in that scale (GPS: TAI − 19 s)."""
    system = (time_system or "").strip().upper()
    if system == "GPS":
        return "tai", 19.0
    if system not in _SCALES:
        raise InputError(
            f"{where}: TIME_SYSTEM = {time_system!r}: expected one of "
            f"{', '.join([*_SCALES, 'GPS'])}"
        )
    return _SCALES[system], 0.0


def parse_epochs(texts: list[str], scale: str, offset_s: float, where: str):
    """CCSDS epoch texts as a ``Time`` in ``scale`` (plus ``offset_s`` seconds)."""
    from astropy.time import Time, TimeDelta

    converted = []
    for text in texts:
        text = text.strip()
        found = _DAY_OF_YEAR.match(text)
        if found:
            year, day, hour, minute, second = found.groups()
            converted.append(f"{year}:{day}:{hour}:{minute}:{second}")
        elif _CALENDAR.match(text):
            converted.append(text.removesuffix("Z"))
        else:
            raise InputError(f"{where}: not a CCSDS epoch: {text!r}")
    read = []
    with offline_time():
        # Each text in its own format: isot and yday may mix in one file.
        for text, given in zip(converted, texts, strict=True):
            try:
                read.append(Time(text, format="yday" if ":" in text[:8] else "isot", scale=scale))
            except (ValueError, TypeError) as exc:
                # ERFA names the bad field ("bad month"); astropy's own words are not ours.
                found = re.search(r'of "([^"]+)"', str(exc))
                why = found.group(1) if found else "not a calendar date and time"
                raise InputError(f"{where}: epoch {given.strip()!r}: {why}") from None
        times = Time(read)
        if offset_s:
            times = times + TimeDelta(offset_s, format="sec")
        return times


def _window(count: int, nodes: int, interval: NDArray[np.intp]) -> NDArray[np.intp]:
    """The first record of the ``nodes`` records centred on each ``interval`` [k, k+1]."""
    return np.clip(interval - (nodes - 1) // 2, 0, count - nodes)


def interpolate(
    method: str,
    degree: int,
    node_s: NDArray[np.float64],
    values: NDArray[np.float64],
    derivatives: NDArray[np.float64] | None,
    at_s: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Values and first derivatives at ``at_s`` of the records (``node_s`` increasing,
    ``values`` (n, k), ``derivatives`` (n, k) per second or None) interpolated by
    ``method`` ("LAGRANGE", "HERMITE" or "LINEAR") of ``degree`` (see the module notes).
    ``at_s`` must lie within [node_s[0], node_s[-1]]."""
    count = node_s.size
    if method == "LINEAR":
        method, degree = "LAGRANGE", 1
    if method == "HERMITE":
        nodes = min(count, max(2, (degree + 2) // 2))
        order = 2 * nodes  # coefficients of the polynomial through values and slopes
    else:
        nodes = min(count, degree + 1)
        order = nodes
    interval = np.clip(np.searchsorted(node_s, at_s, side="right") - 1, 0, count - 2)
    first = _window(count, nodes, interval)
    windows, which = np.unique(first, return_inverse=True)
    index = windows[:, None] + np.arange(nodes)[None, :]  # (w, nodes)
    t = node_s[index]
    centre = 0.5 * (t[:, :1] + t[:, -1:])
    half = np.maximum(0.5 * (t[:, -1:] - t[:, :1]), 1e-300)
    x = (t - centre) / half  # nodes on [−1, 1]
    basis = chebyshev.chebvander(x, order - 1)  # (w, nodes, order)
    rows = [basis]
    right = [values[index]]
    if method == "HERMITE":
        if derivatives is None:
            raise ValueError("HERMITE interpolation needs the derivatives at the nodes")
        # d/dx T_k(x) at the nodes, and the slopes in x: dv/dx = dv/dt · half.
        slope_basis = np.stack(
            [chebyshev.chebval(x, chebyshev.chebder(np.eye(order)[k])) for k in range(order)],
            axis=-1,
        )
        rows.append(slope_basis)
        right.append(derivatives[index] * half[:, :, None])
    system = np.concatenate(rows, axis=1)  # (w, order, order)
    coefficients = np.linalg.solve(system, np.concatenate(right, axis=1))  # (w, order, k)
    c = np.transpose(coefficients[which], (1, 2, 0))  # (order, k, n)
    y = (np.asarray(at_s, dtype=np.float64) - centre[which, 0]) / half[which, 0]
    value = chebyshev.chebval(y, c, tensor=False)  # (k, n)
    slope = chebyshev.chebval(y, chebyshev.chebder(c, axis=0), tensor=False)
    return value.T, slope.T / half[which, 0][:, None]
