"""A TLE's along-track timing dispersion: the line with its epoch moved by s seconds puts
the spacecraft, by SGP4 itself (the sgp4 package), where the nominal line has it
s seconds earlier, to the 0.864 ms the line writes; across a year's end too.  The
line stays a valid TLE (its checksum, by sgp4), and a dispersed scenario runs with it.
"""

import numpy as np
import pytest
from sgp4.api import Satrec
from sgp4.io import compute_checksum

from attitude.files.scenario_reader import load_scenario
from attitude.montecarlo.dispersions import draw_sample, read_dispersions, shifted_tle_epoch
from attitude.montecarlo.metrics import metric_names
from attitude.montecarlo.plan import Job, evaluate_batch

LINE1 = "1 59001U 27042A   27171.50000000  .00000120  00000-0  18000-4 0  9999"
LINE2 = "2 59001  98.2100 175.3000 0012000  95.0000 265.2000 14.57123456    14"
NEAR_NEW_YEAR = "1 59001U 27042A   27365.99000000  .00000120  00000-0  18000-4 0  9999"


def _position_km(line1: str, jd: float, fraction: np.ndarray) -> np.ndarray:
    satellite = Satrec.twoline2rv(line1, LINE2)
    error, position, _ = satellite.sgp4_array(np.full(fraction.shape, jd), fraction)
    assert not np.any(error)
    return position


@pytest.mark.parametrize(
    ("line1", "shift_s"),
    [(LINE1, 0.4), (LINE1, -37.25), (LINE1, 86400.0 * 3.5), (NEAR_NEW_YEAR, 2 * 86400.0)],
)
def test_shifted_epoch_is_the_nominal_orbit_shifted_in_time(line1, shift_s):
    line1 = line1[:68] + str(compute_checksum(line1[:68]))
    shifted, applied = shifted_tle_epoch(line1, shift_s)
    assert len(shifted) == 69 and int(shifted[68]) == compute_checksum(shifted[:68])
    assert abs(applied - shift_s) <= 0.5 * 864e-6 + 1e-9  # 1e-8 day, rounded
    nominal = Satrec.twoline2rv(line1, LINE2)
    moved = Satrec.twoline2rv(shifted, LINE2)
    assert (moved.jdsatepoch + moved.jdsatepochF) - (nominal.jdsatepoch + nominal.jdsatepochF) == (
        pytest.approx(applied / 86400.0, abs=1e-9)
    )
    jd = nominal.jdsatepoch + 2.0  # two days after the nominal epoch, over an orbit
    fraction = nominal.jdsatepochF + np.linspace(0.0, 0.07, 50)
    later = _position_km(shifted, jd, fraction)
    earlier = _position_km(line1, jd, fraction - applied / 86400.0)
    assert np.max(np.linalg.norm(later - earlier, axis=1)) < 1e-6  # km: a millimetre


def test_a_dispersed_tle_scenario_runs_and_records_the_shift(tmp_path):
    path = tmp_path / "orbit.toml"
    path.write_text(
        f"""
[scenario]
name = "orbit"
epoch = "2027-06-21T00:00:00"
[spacecraft]
name = "sat"
principal_moments = [10.0, 20.0, 25.0]
[initial_state]
quaternion = [1.0, 0.0, 0.0, 0.0]
angular_velocity = [0.01, 0.02, 0.3]
[output]
duration = 7200.0
step = 60.0
[pointing]
tle = ["{LINE1}", "{LINE2}"]
[[pointing.body_vectors]]
name = "panel"
vector = [0.0, 0.0, 1.0]
[dispersions]
seed = 3
samples = 3
[dispersions.pointing]
tle_epoch = {{ distribution = "normal", sigma = 30.0 }}
"""
    )
    loaded = load_scenario(path)
    d = read_dispersions(loaded)
    names = metric_names(loaded.scenario, loaded.pointing)
    job = Job(path, loaded.document, d, d.parameter_names(), names, 1)
    rows = evaluate_batch(job, 0, 3).rows
    assert [row["status"] for row in rows] == ["ok"] * 3
    for k, row in enumerate(rows):
        sample = draw_sample(d, loaded.document, k)
        shift = row["pointing.tle_epoch_shift_s"]
        assert sample.document["pointing"]["tle"][0] == shifted_tle_epoch(LINE1, shift)[0]
        assert 0.0 < row["eclipse_total_s"] < 7200.0
    # The eclipses move with the orbit: different shifts, different eclipse totals.
    assert len({row["eclipse_total_s"] for row in rows}) == 3
