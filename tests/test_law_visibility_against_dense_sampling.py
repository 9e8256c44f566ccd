"""visible_intervals (root-finding on the elevation's rate, then on the elevation)
against the elevation sampled every second over half a day (7 passes): the same passes, each end
within the second that brackets it, and the elevation at each end on the threshold."""

import math

import numpy as np

from attitude import GroundSite, KeplerianOrbit, TargetLaw, visible_intervals

EPOCH = "2024-06-15T00:00:00"
SSO = KeplerianOrbit(
    EPOCH, 7_078_137.0, 0.0012, math.radians(98.19), math.radians(63.0), math.radians(90.0),
    mean_anomaly=math.radians(10.0), j2=True,
)  # fmt: skip
SITE = GroundSite(math.radians(43.5605), math.radians(1.4688), 150.0, name="Toulouse")


def test_passes_against_one_second_sampling():
    bound = TargetLaw(SITE).bind(EPOCH, 0.0, 43200.0, SSO)
    grid = np.arange(0.0, 43200.0 + 0.5, 1.0)
    elevation, rate = SITE.elevation(bound.at(grid))
    for floor_deg in (0.0, 10.0):
        _check_intervals(bound, grid, elevation, math.radians(floor_deg))
    # The elevation's rate is its derivative (5-point central differences at 1 s).
    e = elevation
    central = (e[:-4] - 8.0 * e[1:-3] + 8.0 * e[3:-1] - e[4:]) / 12.0
    assert np.abs(central - rate[2:-2]).max() < 1e-4 * np.abs(rate).max()


def _check_intervals(bound, grid, elevation, floor):
    found = visible_intervals(bound, min_elevation=floor)
    above = elevation >= floor
    starts = grid[1:][above[1:] & ~above[:-1]]
    stops = grid[:-1][above[:-1] & ~above[1:]]
    assert len(found) == len(starts) == len(stops) > 0
    for (start, stop), sampled_start, sampled_stop in zip(found, starts, stops, strict=True):
        assert sampled_start - 1.0 < start <= sampled_start
        assert sampled_stop <= stop < sampled_stop + 1.0
        ends, _ = SITE.elevation(bound.at([start, stop]))
        assert np.abs(ends - floor).max() < 1e-9
