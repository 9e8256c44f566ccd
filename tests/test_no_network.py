"""The pointing layer works offline and quietly: no socket is opened, nothing warns.

A guard replaces every way of reaching the network (``socket.socket.connect`` and
``connect_ex``, ``socket.create_connection``, ``socket.getaddrinfo``) by one that
records the attempt and raises.  Under it, with warnings as errors, the test takes
a UTC epoch in 2029 (past the 2028-12-31 from which ERFA warns "dubious year", and
past the expiry of astropy's bundled leap-second file), Sun vectors, and a TLE orbit
with a 2029 epoch through ``attitude.environment.timescales``, ``attitude.environment.ephemeris``,
``attitude.environment.orbit`` and ``attitude.pointing.eclipse``.

Loading DE421 and astropy's leap-second check happen once per process, so the same
code also runs in a fresh interpreter (``-X dev -W error``), where it is the first
use, and where a file left open would warn at exit.
"""

import socket
import subprocess
import sys
import textwrap

import pytest

EXERCISE = textwrap.dedent(
    """
    import numpy as np
    from sgp4.io import fix_checksum

    from attitude.pointing.eclipse import eclipse_intervals, sunlit_fraction
    from attitude.environment.ephemeris import (
        moon_position_from_earth,
        sun_direction_from_earth,
        sun_position_from_earth,
        sun_position_from_observer,
    )
    from attitude.environment.orbit import TleOrbit
    from attitude.environment.timescales import as_time, time_from_tt_seconds, tt_seconds

    # The ISS elements moved to 2029-06-15 12:00 UTC (day 166.5), checksums redone.
    LINE1 = fix_checksum(
        "1 25544U 98067A   29166.50000000  .00009878  00000-0  18200-3 0  508"
    )
    LINE2 = "2 25544  51.6498 109.4756 0003572  55.9686 274.8005 15.49815350868473"

    def exercise():
        epoch = as_time("2029-06-15T12:00:00")  # UTC
        times = time_from_tt_seconds(epoch, np.arange(0.0, 7200.0, 10.0))
        assert abs(float(tt_seconds(times[-1], epoch)) - 7190.0) < 1e-9
        new_year = as_time("2029-12-31T23:59:59.5", scale="utc")
        assert abs(float(tt_seconds(new_year, epoch)) - (199 * 86400 + 43199.5)) < 1e-6
        sun_m = sun_position_from_earth(times)
        assert np.allclose(np.linalg.norm(sun_m, axis=-1), 1.0158 * 1.496e11, rtol=1e-3)  # June
        assert sun_direction_from_earth("2029-06-21T00:00:00")[2] > 0.39  # solstice
        orbit = TleOrbit(LINE1, LINE2, "ISS moved to 2029")
        r_m, v_m_s = orbit.position_velocity(times)
        assert np.all(np.abs(np.linalg.norm(r_m, axis=-1) - 6.79e6) < 2e4)
        assert sun_position_from_observer(times, r_m, v_m_s).shape == (720, 3)
        assert moon_position_from_earth(times).shape == (720, 3)
        assert np.ptp(sunlit_fraction(r_m, sun_m)) == 1.0  # both sunlit and eclipsed
        intervals = eclipse_intervals(orbit, epoch, times[-1])
        assert len(intervals.umbra) >= 1
    """
)


@pytest.fixture
def no_network(monkeypatch):
    """Every route to the network records the attempt and raises."""
    attempts = []

    def refuse(name):
        def guard(*args, **kwargs):
            attempts.append((name, args[1:] if name.startswith("socket.") else args))
            raise OSError(f"network access attempted by {name}{args!r}")

        return guard

    monkeypatch.setattr(socket.socket, "connect", refuse("socket.connect"))
    monkeypatch.setattr(socket.socket, "connect_ex", refuse("socket.connect_ex"))
    monkeypatch.setattr(socket, "create_connection", refuse("create_connection"))
    monkeypatch.setattr(socket, "getaddrinfo", refuse("getaddrinfo"))
    yield attempts
    assert attempts == [], f"network access attempted: {attempts}"


def test_the_guard_works(no_network):
    with pytest.raises(OSError, match="network access attempted"):
        socket.create_connection(("example.org", 443))
    assert len(no_network) == 1
    no_network.clear()


@pytest.mark.filterwarnings("error")
def test_pointing_layer_offline_in_this_process(no_network):
    namespace = {}
    exec(EXERCISE, namespace)
    namespace["exercise"]()
    assert no_network == []


def test_pointing_layer_offline_in_a_fresh_interpreter():
    guard = textwrap.dedent(
        """
        import socket

        def refuse(*args, **kwargs):
            raise SystemExit(f"network access attempted: {args!r}")

        socket.socket.connect = socket.socket.connect_ex = refuse
        socket.create_connection = socket.getaddrinfo = refuse
        """
    )
    code = guard + EXERCISE + "\nexercise()\nprint('done')\n"
    run = subprocess.run(
        [sys.executable, "-X", "dev", "-W", "error", "-c", code],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "done"
    assert run.stderr == ""  # no warning, not even a ResourceWarning at exit
