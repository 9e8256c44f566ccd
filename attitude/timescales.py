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
import warnings
from collections.abc import Iterator
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from attitude.errors import InputError

__all__ = [
    "SAME_INSTANT_S",
    "SCALES",
    "as_time",
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
        raise InputError(f"{name}: time scale must be one of {', '.join(SCALES)}, got {scale!r}")
    try:
        with offline_time():
            return Time(value, scale=scale, precision=9)
    except (ValueError, TypeError) as exc:
        raise InputError(f"{name}: not an ISO 8601 epoch: {value!r} ({exc})") from None


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
