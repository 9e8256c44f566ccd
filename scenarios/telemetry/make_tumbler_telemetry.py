"""Make tumbler_telemetry.csv: 20 minutes of a tumbling small satellite's telemetry.

The truth: principal moments (850, 1400, 1650) kg m² along body x, y, z, a tumble of
about 2.3 deg/s from 2027-03-01T00:00:00 UTC (the exact solver), sampled as a gyro at
1 Hz with 2e-4 rad/s of white noise and a star tracker every 10 s with 20 arcsec per
axis; a 60 s gap in both, and three gyro spikes.  Fit it with

    attitude fit scenarios/telemetry/tumbler_telemetry.csv --out results/fit \
        --attitude-sigma "20 arcsec"

and compare with the truth above (ratios 1 : 1.647 : 1.941).  Rerun this to remake the
file (seeded: the same bytes).
"""

from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from attitude import EulerSolver

MOMENTS = np.array([850.0, 1400.0, 1650.0])
RATE = np.radians([1.6, -0.9, 1.4])
ATTITUDE = Rotation.from_euler("ZYX", [40.0, -10.0, 25.0], degrees=True)
GYRO_SIGMA = 2e-4
STAR_TRACKER_SIGMA = np.radians(20.0 / 3600.0)


def main() -> None:
    rng = np.random.default_rng(2027)
    solver = EulerSolver(MOMENTS, MOMENTS * RATE, ATTITUDE)
    t = np.arange(0.0, 1200.0, 1.0)
    t = t[(t < 600.0) | (t >= 660.0)]  # a telemetry gap
    ω = solver.angular_velocity(t) + GYRO_SIGMA * rng.standard_normal((t.size, 3))
    ω[[100, 401, 902]] += [0.02, -0.03, 0.025]  # spikes
    noise = Rotation.from_rotvec(STAR_TRACKER_SIGMA * rng.standard_normal((t.size, 3)))
    q = (solver.attitude(t) * noise).as_quat(scalar_first=True)
    q[q[:, 0] < 0] *= -1.0  # the tracker's convention: w >= 0 (sign flips between samples)
    lines = [
        "# A tumbling small satellite: gyro at 1 Hz, star tracker every 10 s "
        "(make_tumbler_telemetry.py)",
        "# epoch: 2027-03-01T00:00:00.000000000 UTC; t_s = TT seconds since the epoch",
        "t_s,omega_body_x_rad_s,omega_body_y_rad_s,omega_body_z_rad_s,"
        "q_body_to_icrf_w,q_body_to_icrf_x,q_body_to_icrf_y,q_body_to_icrf_z",
    ]
    for k, time in enumerate(t):
        rates = ",".join(f"{x:.6e}" for x in ω[k])
        fix = ",".join(f"{x:.9f}" for x in q[k]) if time % 10.0 == 0.0 else ",,,"
        lines.append(f"{time:g},{rates},{fix}")
    path = Path(__file__).with_name("tumbler_telemetry.csv")
    path.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
