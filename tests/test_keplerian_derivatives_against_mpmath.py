"""KeplerianOrbit.derivatives_tt (velocity, acceleration, jerk; exact on jets) against
mpmath's numerical differentiation (``mp.diff``) of the same orbit written in mpmath at
40 digits: two-body and J2-secular, circular to e = 0.9, in ICRF and EME2000."""

import mpmath as mp
import numpy as np
import pytest

from attitude.environment.frames import eme2000_to_icrf
from attitude.environment.keplerian import KeplerianOrbit

mp.mp.dps = 40
EPOCH = "2024-06-15T00:00:00"


def _mp_position(orbit: KeplerianOrbit, bias):
    """r(dt) in mpmath from the orbit's elements and rates (the module's formulas)."""
    a, e, i = mp.mpf(orbit.a), mp.mpf(orbit.e), mp.mpf(orbit.i)

    def position(dt):
        M = mp.mpf(orbit.m0) + mp.mpf(orbit.mean_anomaly_rate) * dt
        raan = mp.mpf(orbit.raan) + mp.mpf(orbit.raan_rate) * dt
        argp = mp.mpf(orbit.argp) + mp.mpf(orbit.argp_rate) * dt
        E = mp.findroot(lambda x: x - e * mp.sin(x) - M, M)
        x_p = a * (mp.cos(E) - e)
        y_q = a * mp.sqrt(1 - e**2) * mp.sin(E)
        cO, sO, cw, sw, ci, si = (
            mp.cos(raan),
            mp.sin(raan),
            mp.cos(argp),
            mp.sin(argp),
            mp.cos(i),
            mp.sin(i),
        )
        P = [cO * cw - sO * sw * ci, sO * cw + cO * sw * ci, sw * si]
        Q = [-cO * sw - sO * cw * ci, -sO * sw + cO * cw * ci, cw * si]
        r = mp.matrix([x_p * p + y_q * q for p, q in zip(P, Q, strict=True)])
        return bias * r

    return position


@pytest.mark.parametrize(
    "e, j2, frame",
    [(0.0, False, "ICRF"), (0.0012, True, "ICRF"), (0.3, True, "EME2000"), (0.9, False, "ICRF")],
)
def test_derivatives_against_mpmath(e, j2, frame):
    orbit = KeplerianOrbit(
        EPOCH, 7.1e6 / (1.0 - e), e, 1.2, 0.4, 2.2, mean_anomaly=0.3, j2=j2, frame=frame
    )
    bias = mp.matrix(eme2000_to_icrf().as_matrix().tolist()) if frame == "EME2000" else mp.eye(3)
    position = _mp_position(orbit, bias)
    jd1 = np.full(4, orbit._epoch_jd[0])
    jd2 = orbit._epoch_jd[1] + np.array([0.0, 0.013, 0.21, 0.77])
    ours = orbit.derivatives_tt(jd1, jd2, order=3)
    r, v = orbit.state_tt(jd1, jd2)
    assert np.array_equal(ours[0], r)
    for n, dt in enumerate(((jd1 - orbit._epoch_jd[0]) + (jd2 - orbit._epoch_jd[1])) * 86400.0):
        for k in (1, 2, 3):
            want = np.array(
                [float(mp.diff(lambda t, c=c: position(t)[c], mp.mpf(dt), k)) for c in range(3)]
            )
            error = np.linalg.norm(ours[k][n] - want) / np.linalg.norm(want)
            assert error < 1e-13, (k, dt, error)
        assert np.linalg.norm(v[n] - ours[1][n]) < 1e-12 * np.linalg.norm(v[n])
