"""Draw docs/images/law_*.png: the body axes each attitude law gives along an orbit.

Run from the repository root: ``python docs/examples/draw_law_axes.py``.  Every arrow is
computed by the law itself (``attitude.NadirLaw`` ...), on a sun-synchronous orbit
(700 km, 98.2°) on 2025-05-01: body x red, y green, z blue, 1500 km long (the Earth
and the orbit to scale), at 10 epochs over half an orbit.  The nadir figure adds the
yaw angle of each steering over an orbit (the angle from LVLH's x to the body x,
about z), which the 3-D view cannot show: zero-Doppler steering is a few degrees.
"""

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from astropy.time import Time
from scipy.spatial.transform import Rotation

from attitude import (
    AlignConstrainLaw,
    GroundSite,
    InertialLaw,
    KeplerianOrbit,
    NadirLaw,
    OrbitFrameLaw,
    SunLaw,
    TargetLaw,
)
from attitude.environment.frames import lvlh_to_icrf

EPOCH = Time("2025-05-01T10:00:00", scale="utc")
ORBIT = KeplerianOrbit(
    EPOCH, 7_078_137.0, 0.001, math.radians(98.2), math.radians(170.0), 0.0,
    mean_anomaly=0.0, j2=True,
)  # fmt: skip
PERIOD = 2 * math.pi / ORBIT.n
SITE = GroundSite(math.radians(43.56), math.radians(1.47), 150.0, name="Toulouse")
ARROW_KM = 1500.0
COLOURS = ("#c0392b", "#1e8449", "#2e6db4")  # body x, y, z
OUT = Path(__file__).parents[1] / "images"


def _earth(ax) -> None:
    u, v = np.mgrid[0 : 2 * np.pi : 40j, 0 : np.pi : 20j]
    r = 6378.0
    ax.plot_surface(
        r * np.cos(u) * np.sin(v), r * np.sin(u) * np.sin(v), r * np.cos(v),
        color="#9cc3e6", alpha=0.35, linewidth=0, zorder=0,
    )  # fmt: skip


def _axes_along(ax, law, seconds, title, extra=None) -> None:
    bound = law.bind(EPOCH, 0.0, PERIOD, ORBIT)
    track = bound.at(np.linspace(0.0, PERIOD, 200)).position.value / 1e3
    ax.plot(*track.T, color="0.55", lw=1)
    _earth(ax)
    state = bound.state(seconds)
    where = bound.at(seconds).position.value / 1e3
    for k, colour in enumerate(COLOURS):
        axis = state.attitude.apply(np.eye(3)[k]) * ARROW_KM
        ax.quiver(*where.T, *axis.T, color=colour, lw=1.6, arrow_length_ratio=0.25)
    if extra is not None:
        extra(ax, bound, where)
    limit = 7600.0
    ax.set_xlim(-limit, limit)
    ax.set_ylim(-limit, limit)
    ax.set_zlim(-limit, limit)
    ax.set_box_aspect((1, 1, 1), zoom=1.45)
    ax.set_axis_off()
    ax.view_init(elev=18, azim=-60)
    ax.set_title(title, fontsize=10)


def _sun_arrow(ax, bound, where) -> None:
    sun = bound.at([0.0]).apparent("sun").value[0]
    sun = sun / np.linalg.norm(sun) * 9000.0
    ax.quiver(0, 0, 0, *sun, color="#e1a100", lw=2.5, arrow_length_ratio=0.08)
    ax.text(*(sun * 0.9), "Sun", color="#b07d00", fontsize=10)


def _site_lines(ax, bound, where) -> None:
    at = bound.at(np.linspace(0.0, PERIOD / 2, 10))
    site = np.einsum("nij,j->ni", at.itrs_to_gcrs.value, SITE.itrs_m) / 1e3
    ax.scatter(*site[0], color="k", s=14)
    ax.text(*(site[0] * 1.08), "Toulouse", fontsize=8)
    for p, s in zip(where, site, strict=True):
        ax.plot(*np.column_stack([p, s]), color="0.25", lw=0.6, ls=":")


def _legend(fig) -> None:
    handles = [plt.Line2D([], [], color=c, lw=2) for c in COLOURS]
    fig.legend(handles, ["body x", "body y", "body z"], loc="lower center", ncol=3, fontsize=9)


def _single(name, law, title, extra=None) -> None:
    fig = plt.figure(figsize=(5.6, 5.4), dpi=110)
    ax = fig.add_subplot(projection="3d")
    seconds = np.linspace(0.0, PERIOD / 2, 10)
    _axes_along(ax, law, seconds, title, extra)
    _legend(fig)
    fig.savefig(OUT / f"law_{name}.png", bbox_inches="tight")
    plt.close(fig)


def _yaw(law) -> np.ndarray:
    """The yaw of the law's body x from LVLH x, about LVLH z, degrees, over an orbit."""
    seconds = np.linspace(0.0, PERIOD, 721)
    bound = law.bind(EPOCH, 0.0, PERIOD, ORBIT)
    at = bound.at(seconds)
    lvlh = lvlh_to_icrf(at.position.value, at.velocity.value)
    x = (lvlh.inv() * bound.attitude(seconds)).apply([1.0, 0.0, 0.0])
    return np.degrees(np.arctan2(x[:, 1], x[:, 0]))


def _nadir() -> None:
    fig = plt.figure(figsize=(13.0, 4.8), dpi=110)
    steerings = (("none", "no yaw steering: +x towards v"), ("sun", "Sun yaw steering: Sun in x–z"))
    for k, (steering, title) in enumerate(steerings):
        ax = fig.add_subplot(1, 3, k + 1, projection="3d")
        extra = _sun_arrow if steering == "sun" else None
        _axes_along(ax, NadirLaw(steering), np.linspace(0.0, PERIOD / 2, 10), title, extra)
    ax = fig.add_subplot(1, 3, 3)
    minutes = np.linspace(0.0, PERIOD, 721) / 60.0
    for steering, colour in (("none", "0.4"), ("zero_doppler", "#8e44ad"), ("sun", "#e1a100")):
        ax.plot(minutes, _yaw(NadirLaw(steering)), color=colour, label=steering)
    ax.set_xlabel("minutes")
    ax.set_ylabel("yaw from LVLH x (deg)")
    ax.set_title("the yaw over an orbit", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    _legend(fig)
    fig.savefig(OUT / "law_nadir.png", bbox_inches="tight")
    plt.close(fig)


def main() -> None:
    _single(
        "inertial",
        InertialLaw(Rotation.from_rotvec([0.4, -0.9, 0.3])),
        "inertial: a fixed attitude",
    )
    _single(
        "orbit_frame",
        OrbitFrameLaw("lvlh"),
        "orbit_frame, LVLH (identity):\nz nadir, y = −h, x = y × z",
    )
    _nadir()
    _single("sun", SunLaw(), "sun: +z on the Sun,\n+x towards the celestial north", _sun_arrow)
    _single(
        "target",
        TargetLaw(SITE),
        "target: +z on Toulouse, +x towards v\n(through the Earth when below the horizon)",
        _site_lines,
    )
    _single(
        "align_constrain",
        AlignConstrainLaw("+x", "sun", "+z", "orbit_normal"),
        "align_constrain: +x on the Sun,\n+z as close as possible to the orbit normal",
        _sun_arrow,
    )
    print(sorted(p.name for p in OUT.glob("law_*.png")))


if __name__ == "__main__":
    main()
