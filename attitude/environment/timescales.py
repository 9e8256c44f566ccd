"""Epochs: astropy Time without a network, and exact arithmetic between epochs.

The scenario layer takes epochs as ``astropy.time.Time`` in any scale (UTC, TT,
TDB, TAI, ...).  Internally an epoch is kept as astropy keeps it, a two-part Julian
date, and the solver's time is **TT seconds since the scenario epoch**, computed
from the two parts separately, never through one float JD (which would lose 20 µs).

astropy, left to itself, may try to download leap-second and Earth-orientation
tables (from 2027-01-29 its bundled leap-second file counts as stale) and warns
about them; ERFA warns "dubious year" for any UTC date from 2028-12-31 on.  None of
that concerns UTC↔TT↔TDB conversions, which need only the leap-second table that
astropy ships.  :func:`offline_time` is the scope in which the package converts
times: no download is ever attempted, stale tables are used as they are, and only
ERFA's "dubious year" warning is silenced.  It restores astropy's settings on exit.
"""

from __future__ import annotations

import contextlib
import re
import warnings
from collections.abc import Iterator
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from attitude.base.errors import InputError

__all__ = [
    "SAME_INSTANT_S",
    "SCALES",
    "as_time",
    "check_year_range",
    "iso_texts",
    "offline_time",
    "time_from_tt_seconds",
    "tt_seconds",
]

SECONDS_PER_DAY = 86400.0
# Two epochs closer than this are the same instant: converting UTC to TT rounds at
# about 1e-12 s, and a nanosecond of torque-free motion is below anything reported.
SAME_INSTANT_S = 1e-9
# The astropy time scales a scenario may use.
SCALES = ("utc", "tt", "tai", "tdb", "tcg", "tcb")


@contextlib.contextmanager
def offline_time() -> Iterator[None]:
    """A scope in which astropy converts time scales without any network access.

    - ``iers.conf.auto_download = False``: no leap-second or IERS table is fetched;
    - ``iers.conf.auto_max_age = None``: the tables astropy ships are used however
      old, without the "expired" warning (UTC↔TT needs only leap seconds, and none
      is announced beyond the shipped table);
    - ERFA's "dubious year" warning (any UTC date from 2028-12-31 on) is ignored;
      every other warning still shows.
    astropy's leap-second check runs once per process, on the first conversion; the
    package makes its conversions in this scope, so that check happens offline.
    """
    import erfa
    from astropy.utils import iers

    with contextlib.ExitStack() as stack:
        stack.enter_context(iers.conf.set_temp("auto_download", False))
        stack.enter_context(iers.conf.set_temp("auto_max_age", None))
        stack.enter_context(warnings.catch_warnings())
        warnings.filterwarnings(
            "ignore",
            category=erfa.ErfaWarning,
            message=r'ERFA function "\w+" yielded \d+ of "dubious year',
        )
        yield


def as_time(value: Any, scale: str | None = None, name: str = "epoch"):
    """``value`` as an ``astropy.time.Time``.

    Accepts a ``Time`` (kept as it is) or an ISO 8601 string (with ``scale``, one of
    :data:`SCALES`; UTC when None), scalar or array.  Raises :class:`InputError`
    naming ``name`` otherwise.
    """
    from astropy.time import Time

    if isinstance(value, Time):
        return value
    scale = "utc" if scale is None else str(scale).lower()
    if scale not in SCALES:
        raise InputError(
            f"time scale must be one of {', '.join(SCALES)}, got {scale!r}", key=name, value=scale
        )
    import erfa

    try:
        with offline_time(), warnings.catch_warnings():
            # ERFA reads hh:mm:60 as the next minute with only a warning, on any day:
            # a second 60 exists only in a UTC leap second, so anything else is refused.
            warnings.filterwarnings("error", category=erfa.ErfaWarning, message=".*end of day")
            return Time(value, scale=scale, precision=9)
    except erfa.ErfaWarning:
        raise InputError(
            f"{value!r} names a second that does not exist: :60 is a leap second, "
            f"which only UTC has, and only at the end of the days that IERS announced",
            key=name,
            value=value,
        ) from None
    except (ValueError, TypeError, OverflowError) as exc:
        raise InputError(
            f"not an ISO 8601 epoch: {value!r}{_reason(str(exc))}", key=name, value=value
        ) from None


def _reason(text: str) -> str:
    """What astropy says about an ISO text, in a few words: its 'isot' line, where ERFA
    names the bad field ('bad day'), if there is one."""
    for line in text.splitlines():
        if line.startswith("- 'isot': "):
            found = re.search(r'of "([^"]+)"', line)
            return f" ({found.group(1)})" if found else ""
    return ""


# Julian dates of 0001-01-01T00:00 and 10000-01-01T00:00 (proleptic Gregorian, as
# astropy writes ISO dates): epochs must lie between, in their own scale.
_FIRST_JD, _END_JD = 1721425.5, 5373484.5


def check_year_range(times, name: str) -> None:
    """Raise :class:`InputError` unless every epoch of ``times`` (a ``Time``) lies in
    the years 0001–9999 of its own scale: the years ISO 8601 writes with four digits."""
    jd = np.ravel(np.asarray(times.jd1) + np.asarray(times.jd2))
    outside = ~((jd >= _FIRST_JD) & (jd < _END_JD))
    if np.any(outside):
        first = times.ravel()[np.flatnonzero(outside)[0]] if times.ndim else times
        try:
            with offline_time():
                shown = first.isot
        except (ValueError, OverflowError):
            shown = f"Julian date {float(jd[outside][0]):.1f}"
        raise InputError(
            f"epochs must lie in the years 0001-9999, got {shown} {times.scale.upper()}",
            key=name,
            value=f"{shown} {times.scale.upper()}",
        )


def iso_texts(times) -> Any:
    """``times.isot`` with four-digit years, as ISO 8601 writes them (astropy writes
    the year 1 as ``1-…``): a str for a scalar ``Time``, else an array of str."""
    with offline_time():
        texts = np.asarray(times.isot)
    short = np.char.find(texts, "-") < 4
    if np.any(short):
        texts = texts.astype(f"U{texts.dtype.itemsize // 4 + 3}")
        texts[short] = [text.zfill(len(text) + 4 - text.index("-")) for text in texts[short]]
    return str(texts) if texts.ndim == 0 else texts


def tt_seconds(times, epoch) -> NDArray[np.float64]:
    """TT seconds from ``epoch`` to ``times`` (both ``Time``), from their two-part JDs.

    (jd1 − jd1₀) is exact (whole days) and (jd2 − jd2₀) is exact to 1e-17 day, so the
    result carries the rounding of its own magnitude only: 0.5 ns at 100 days.
    """
    with offline_time():
        t, e = times.tt, epoch.tt
        return ((t.jd1 - e.jd1) + (t.jd2 - e.jd2)) * SECONDS_PER_DAY


def time_from_tt_seconds(epoch, seconds: ArrayLike):
    """The ``Time`` (scale TT) that is ``seconds`` TT seconds after ``epoch``."""
    from astropy.time import TimeDelta

    seconds = np.asarray(seconds, dtype=np.float64)
    with offline_time():
        return epoch.tt + TimeDelta(seconds, format="sec", scale="tt")
