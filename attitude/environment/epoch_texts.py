"""ISO 8601 texts of many epochs, fast: integer nanoseconds and numpy's calendar.

A report writes one epoch text per output sample and per AEM record: millions of
them on a long run.  astropy writes them exactly but slowly (about 3 µs each, most
of it in Python), so this module writes the same texts from integers:

- The scenario epoch is read once, through astropy, as whole seconds and nanoseconds
  in a *uniform* count of its scale: TT, TAI, TDB, TCG, TCB count their own seconds;
  for UTC the count is TAI's, since UTC's seconds are not uniform (leap seconds).
- A sample ``t_s`` TT seconds after the epoch is the epoch's count plus ``t_s``
  (TT, TAI and UTC's TAI count advance together), plus, for TDB, TCG and TCB, how
  much more or less their clocks have advanced than TT's.  That difference is smooth
  (TDB − TT: 1.7 ms over a year; TCG and TCB: a rate) and is taken from astropy at
  nodes every 6 h and joined by a cubic spline (5e-14 s off ERFA's series, whose
  fastest large terms are monthly), so it costs nothing per sample.
- UTC's leap-second guard: the TAI count is turned into UTC by subtracting TAI − UTC
  from astropy's leap-second table (the one it ships, as ERFA holds it once astropy
  has loaded it).  A sample inside an inserted second is written ``23:59:60.…``, as
  UTC writes it and astropy does.
- The calendar date comes from ``numpy.datetime64`` (proleptic Gregorian, like
  astropy's ``isot``), converted once per distinct day; the time of day and the
  nine decimals are integer arithmetic, assembled as bytes.

The texts are astropy's ``Time(...).isot`` at precision 9, character for character,
except where the exact instant lies within 3e-11 s of half a nanosecond: astropy's
two-part Julian dates carry that much rounding, and the two round differently there,
by 1 ns; ``tests/test_epoch_texts_against_astropy.py``
compares them, over a leap second and in every scale.  UTC before 1972, when TAI −
UTC was not a whole number of seconds and drifted, goes through astropy itself.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from attitude.environment.timescales import iso_texts, offline_time, time_from_tt_seconds

if TYPE_CHECKING:
    from scipy.interpolate import CubicSpline

__all__ = ["TEXT_LENGTH", "EpochTexts"]

# "YYYY-MM-DDThh:mm:ss.fffffffff": four-digit years (0001-9999), nanoseconds.
TEXT_LENGTH = 29
_NS = 1_000_000_000
_DAY_S = 86_400
# Nodes of the TDB/TCG/TCB clock difference (TT seconds apart).
_CLOCK_NODE_S = 6 * 3600.0
# UTC is integer seconds from TAI from 1972-01-01 on (days since 1970-01-01).
_UTC_INTEGER_FROM_DAY = int(np.datetime64("1972-01-01", "D").astype(np.int64))
_DIGITS = np.frombuffer(b"0123456789", dtype=np.uint8)


def _uniform_count(text: str) -> tuple[int, int]:
    """(seconds since 1970-01-01T00:00 of the same uniform count, nanoseconds) of an
    ISO text with nine decimals and no leap second (TAI, TT, TDB, ...)."""
    whole, fraction = text.split(".")
    seconds = np.datetime64(whole, "s").astype(np.int64)
    return int(seconds), int(fraction)


class EpochTexts:
    """ISO texts of epochs given as TT seconds after ``epoch`` (a scalar astropy ``Time``),
    written in ``epoch``'s scale, as :meth:`attitude.scenario.scenario.Scenario.iso` writes them."""

    def __init__(self, epoch: Any) -> None:
        from astropy.time import Time

        self.epoch = epoch
        self.scale = epoch.scale
        self._fallback = False
        with offline_time():
            uniform = epoch.tai if self.scale == "utc" else epoch
            self._fallback = self.scale == "utc" and bool(
                np.datetime64(uniform.isot[:10], "D").astype(np.int64) < _UTC_INTEGER_FROM_DAY + 1
            )
            text = iso_texts(Time(uniform, precision=9))  # four-digit years
            self._seconds0, self._ns0 = _uniform_count(text)
            # What the nine decimals leave out of the epoch (a user may give more).
            written = Time(text, scale=uniform.scale, format="isot")
            self._residual_s = float(
                ((uniform.jd1 - written.jd1) + (uniform.jd2 - written.jd2)) * _DAY_S
            )
        if self.scale == "utc":
            import erfa

            table = erfa.leap_seconds.get()  # astropy's table once it has loaded it
            first = np.array(
                [np.datetime64(f"{y:04d}-{m:02d}-01", "D") for y, m in table[["year", "month"]]]
            ).astype(np.int64)
            keep = first >= _UTC_INTEGER_FROM_DAY
            self._offsets = np.round(table["tai_utc"][keep]).astype(np.int64)
            # The TAI count at which each offset takes effect (00:00 UTC of its day).
            self._changes = first[keep] * _DAY_S + self._offsets
        self._clock: CubicSpline | None = None
        self._clock_span = (0.0, 0.0)

    # --- the uniform count -------------------------------------------------------

    def _clock_difference(self, seconds: NDArray[np.float64]) -> NDArray[np.float64]:
        """Seconds the scale's clock has gained on TT since the epoch, at ``seconds``.

        TCG runs faster than TT by the constant rate L_G, and TCB faster than TDB by
        L_B (IAU 2000 B1.9, IAU 2006 B3: dTT/dTCG = 1 − L_G, dTDB/dTCB = 1 − L_B);
        TDB − TT is ERFA's ``dtdb`` series at the geocentre, as astropy takes it.
        """
        import erfa

        if self.scale in ("utc", "tt", "tai"):
            return np.zeros_like(seconds)
        if self.scale == "tcg":
            return seconds * (erfa.ELG / (1.0 - erfa.ELG))
        tdb = self._tdb_gain(seconds)
        if self.scale == "tdb":
            return tdb
        return (seconds * erfa.ELB + tdb) / (1.0 - erfa.ELB)

    def _tdb_gain(self, seconds: NDArray[np.float64]) -> NDArray[np.float64]:
        """(TDB − TT) at ``seconds`` minus its value at the epoch: a cubic spline through
        ERFA's series every 6 h (5e-14 s off it)."""
        low, high = float(np.min(seconds)), float(np.max(seconds))
        clock = self._clock
        if clock is None or low < self._clock_span[0] or high > self._clock_span[1]:
            clock = self._clock = self._tdb_spline(low, high)
        return clock(seconds) - self._clock_at_epoch

    def _tdb_spline(self, low: float, high: float) -> CubicSpline:
        import erfa
        from scipy.interpolate import CubicSpline

        # Nodes over the asked span and a day beyond each end, so that the chunks of a
        # stream rarely rebuild it; at least 4 for a cubic.
        start = low - 86400.0
        count = max(4, int(np.ceil((high - start + 86400.0) / _CLOCK_NODE_S)) + 1)
        nodes = np.concatenate([[0.0], start + _CLOCK_NODE_S * np.arange(count)])
        with offline_time():
            tt = time_from_tt_seconds(self.epoch, nodes)
            difference = erfa.dtdb(tt.jd1, tt.jd2, 0.0, 0.0, 0.0, 0.0)
        self._clock_at_epoch = float(difference[0])
        self._clock_span = (float(nodes[1]), float(nodes[-1]))
        return CubicSpline(nodes[1:], difference[1:])

    def _counts(self, seconds: NDArray[np.float64]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """(whole seconds, nanoseconds) of the uniform count at ``seconds``, rounded to 1 ns."""
        whole = np.floor(seconds)
        # The fraction is exact; the small terms are added to it before rounding.
        fraction = (seconds - whole) + (self._clock_difference(seconds) + self._residual_s)
        ns = np.rint(fraction * 1e9).astype(np.int64) + self._ns0
        carry = np.floor_divide(ns, _NS)
        return whole.astype(np.int64) + self._seconds0 + carry, ns - carry * _NS

    # --- texts -------------------------------------------------------------------

    def __call__(self, seconds: ArrayLike) -> NDArray[np.bytes_]:
        """ASCII texts (numpy ``S29``) of the epochs ``seconds`` TT s after the epoch."""
        seconds = np.asarray(seconds, dtype=np.float64)
        if self._fallback:
            with offline_time():
                times = getattr(time_from_tt_seconds(self.epoch, seconds.ravel()), self.scale)
                times.precision = 9
                texts = np.atleast_1d(iso_texts(times))
            return np.char.encode(texts, "ascii").reshape(seconds.shape)
        whole, ns = self._counts(seconds.ravel())
        leap = np.zeros(whole.shape, dtype=bool)
        if self.scale == "utc":
            whole, leap = self._utc(whole)
        return _assemble(whole, ns, leap).reshape(seconds.shape)

    def strings(self, seconds: ArrayLike) -> NDArray[np.str_]:
        """The same texts as ``str`` (numpy ``U29``)."""
        return np.char.decode(self(seconds), "ascii")

    def _utc(self, tai: NDArray[np.int64]) -> tuple[NDArray[np.int64], NDArray[np.bool_]]:
        """UTC seconds (a count without leap seconds) from TAI ones, and which samples
        fall in an inserted leap second (to be written as second 60)."""
        k = np.searchsorted(self._changes, tai, side="right") - 1
        # Before the first change of the table (from 1972 on) its first offset applies.
        offset = self._offsets[np.maximum(k, 0)]
        # Inside the second(s) inserted before the next change: 23:59:60 of the day before.
        following = np.minimum(k + 1, self._changes.size - 1)
        inserted = self._offsets[following] - offset
        leap = (k + 1 < self._changes.size) & (inserted > 0)
        leap &= tai >= self._changes[following] - inserted
        utc = np.where(leap, tai - self._offsets[following], tai - offset)
        return utc, leap


def _assemble(
    seconds: NDArray[np.int64], ns: NDArray[np.int64], leap: NDArray[np.bool_]
) -> NDArray[np.bytes_]:
    """The texts of (seconds since 1970-01-01 in a count without leap seconds, ns);
    ``leap``: the second is 23:59:59 in the count and written 23:59:60."""
    days = np.floor_divide(seconds, _DAY_S)
    of_day = seconds - days * _DAY_S
    out = np.empty((seconds.size, TEXT_LENGTH), dtype=np.uint8)
    # The date: one datetime64 conversion per distinct day (a chunk spans few days).
    if seconds.size:
        unique, where = np.unique(days, return_inverse=True)
        dates = np.datetime_as_string(unique.astype("datetime64[D]")).astype("S10")
        out[:, :10] = dates.view(np.uint8).reshape(-1, 10)[where]
    hours, rest = np.divmod(of_day, 3600)
    minutes, secs = np.divmod(rest, 60)
    secs = secs + leap
    out[:, 10] = ord("T")
    out[:, 13] = out[:, 16] = ord(":")
    out[:, 19] = ord(".")
    for column, value in ((11, hours), (14, minutes), (17, secs)):
        out[:, column] = _DIGITS[value // 10]
        out[:, column + 1] = _DIGITS[value % 10]
    for column in range(28, 19, -1):
        ns, digit = np.divmod(ns, 10)
        out[:, column] = _DIGITS[digit]
    return out.view(f"S{TEXT_LENGTH}").ravel()
