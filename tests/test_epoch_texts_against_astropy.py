"""ISO epoch texts written from integers (attitude.environment.epoch_texts) against astropy's own.

The authority is astropy: ``Time`` of the epoch plus TT seconds, converted to the
scenario's scale, written with ``isot`` at precision 9, as ``Scenario.iso`` does.  Over
the leap seconds of 2015-06-30 and 2016-12-31 (UTC's 23:59:60), in every scale, for
the years 0001 and 9999, and before 1972 (where UTC drifted from TAI), the texts are
equal character for character.  At random instants they are equal except where the
exact instant lies within 0.03 ns of half a nanosecond: astropy's two-part Julian
dates carry 0.005 to 0.02 ns of rounding (more in TDB and TCB, converted twice), and
the two round that tie differently.
"""

from fractions import Fraction

import erfa
import numpy as np
import pytest

from attitude.environment.epoch_texts import EpochTexts
from attitude.environment.timescales import as_time, iso_texts, offline_time, time_from_tt_seconds


def _astropy(epoch, seconds):
    with offline_time():
        times = getattr(time_from_tt_seconds(epoch, seconds), epoch.scale)
        times.precision = 9
        return np.atleast_1d(iso_texts(times))


def test_utc_across_the_leap_seconds():
    for epoch_text in ("2016-12-31T23:59:50", "2015-06-30T23:59:58.75"):
        epoch = as_time(epoch_text, "utc")
        seconds = np.arange(0.0, 30.0, 0.25)
        ours = EpochTexts(epoch).strings(seconds)
        assert list(ours) == list(_astropy(epoch, seconds))
        assert sum(text[17:19] == "60" for text in ours) == 4  # 60.00, .25, .50, .75
    epoch = as_time("2016-12-31T23:59:59.5", "utc")
    assert list(EpochTexts(epoch).strings([0.0, 0.5, 1.0, 1.5])) == [
        "2016-12-31T23:59:59.500000000",
        "2016-12-31T23:59:60.000000000",
        "2016-12-31T23:59:60.500000000",
        "2017-01-01T00:00:00.000000000",
    ]


def test_an_epoch_inside_the_leap_second():
    epoch = as_time("2016-12-31T23:59:60.25", "utc")
    seconds = np.arange(0.0, 3.0, 0.125)
    assert list(EpochTexts(epoch).strings(seconds)) == list(_astropy(epoch, seconds))


def _gain_ns(scale, epoch, seconds):
    """What the scale's clock gains on TT over ``seconds``, ns (for the tie test)."""
    if scale in ("utc", "tt", "tai"):
        return np.zeros_like(seconds)
    with offline_time():
        tt = time_from_tt_seconds(epoch, np.concatenate([[0.0], seconds]))
        tdb = erfa.dtdb(tt.jd1, tt.jd2, 0.0, 0.0, 0.0, 0.0)
    tdb = tdb[1:] - tdb[0]
    if scale == "tdb":
        return tdb * 1e9
    if scale == "tcg":
        return seconds * erfa.ELG / (1.0 - erfa.ELG) * 1e9
    return (seconds * erfa.ELB + tdb) / (1.0 - erfa.ELB) * 1e9


@pytest.mark.parametrize("scale", ["utc", "tt", "tai", "tdb", "tcg", "tcb"])
def test_every_scale_at_random_instants_and_on_a_grid(scale):
    epoch = as_time("2027-06-21T00:00:00.123456789", scale)
    rng = np.random.default_rng(7)
    seconds = np.concatenate([rng.uniform(0.0, 3e6, 20000), np.arange(0.0, 86400.0 * 2, 7.25)])
    ours = EpochTexts(epoch).strings(seconds)
    theirs = _astropy(epoch, seconds)
    gain = _gain_ns(scale, epoch, seconds)
    # The exact instant's nanoseconds past the epoch's (whose text has 9 decimals).
    fraction = np.array(
        [float((Fraction(t) * 10**9 + Fraction(g)) % 1) for t, g in zip(seconds, gain, strict=True)]
    )
    near_a_tie = np.abs(fraction - 0.5) < 0.03
    differ = ours != theirs
    assert not np.any(differ & ~near_a_tie), list(zip(ours[differ], theirs[differ], strict=True))[
        :3
    ]
    assert np.mean(differ) < 0.03
    # Where they differ, by one in the last digit.
    for a, b in zip(ours[differ], theirs[differ], strict=True):
        assert a[:20] == b[:20] and abs(int(a[20:]) - int(b[20:])) == 1


@pytest.mark.parametrize(
    ("scale", "epoch_text"),
    [("tai", "0001-01-01T00:00:00"), ("tt", "9999-12-30T12:00:00"), ("utc", "1971-12-31T23:58:00")],
    ids=["year 0001", "year 9999", "UTC before 1972"],
)
def test_the_ends_of_the_calendar_and_utc_before_1972(scale, epoch_text):
    epoch = as_time(epoch_text, scale)
    seconds = np.arange(0.0, 86400.0, 3.5)
    ours = EpochTexts(epoch).strings(seconds)
    assert list(ours) == list(_astropy(epoch, seconds))
    assert ours[0].startswith(epoch_text[:4])  # four-digit years, as ISO 8601 writes them


def test_the_texts_are_ascii_bytes_of_fixed_width():
    texts = EpochTexts(as_time("2027-06-21T00:00:00", "utc"))(
        np.array([0.0, 1e-9, 86399.9999999996])
    )
    assert texts.dtype == np.dtype("S29")
    assert list(texts) == [
        b"2027-06-21T00:00:00.000000000",
        b"2027-06-21T00:00:00.000000001",
        b"2027-06-22T00:00:00.000000000",
    ]
