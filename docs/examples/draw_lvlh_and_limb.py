"""Draw docs/images/lvlh_and_limb.png: the LVLH axes and the Earth limb angle.

Run from the repository root: ``python docs/examples/draw_lvlh_and_limb.py``.
To scale for a spacecraft 3000 km up (so that the cone is legible), with a 400 km
"atmosphere" (exaggerated, to show the sphere of radius R + h the limb angle uses).
"""

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Arc, Circle, FancyArrowPatch

R, H_ATM = 6378.0, 400.0
r = R + 3000.0
sc = np.array([0.0, r])
rho = math.asin((R + H_ATM) / r)  # angular radius of the Earth and its atmosphere
phi = rho + math.radians(20.0)  # a body vector 20° above the limb

fig, ax = plt.subplots(figsize=(8.0, 5.6), dpi=120)
ax.set_aspect("equal")
ax.axis("off")
ax.add_patch(Circle((0, 0), R, color="#9cc3e6", zorder=1))
ax.add_patch(Circle((0, 0), R + H_ATM, fill=False, ls="--", color="#5b8fc9", lw=1, zorder=1))
theta = np.linspace(math.radians(30), math.radians(150), 300)
ax.plot(r * np.cos(theta), r * np.sin(theta), color="0.6", lw=1)


def arrow(direction, length, color):
    end = sc + length * np.asarray(direction)
    ax.add_patch(
        FancyArrowPatch(sc, end, arrowstyle="-|>", mutation_scale=16, color=color, lw=2, zorder=4)
    )
    return end


def angle_arc(radius, start, stop, color, lw=1.2):
    """An arc about the spacecraft between directions ``start`` and ``stop`` (radians from
    nadir, towards +x of the page)."""
    ax.add_patch(
        Arc(
            sc,
            2 * radius,
            2 * radius,
            theta1=-90 + math.degrees(start),
            theta2=-90 + math.degrees(stop),
            color=color,
            lw=lw,
            zorder=3,
        )
    )


red, blue, green = "#c0392b", "#3f78b5", "#1e8449"
end = arrow((-1.0, 0.0), 2600.0, red)
ax.text(end[0] - 150, end[1], "x  (≈ v)", color=red, fontsize=11, ha="right", va="center")
end = arrow((0.0, -1.0), 2600.0, red)
ax.text(end[0] - 150, end[1] + 200, "z  (nadir)", color=red, fontsize=11, ha="right")
ax.plot(*sc, marker="o", ms=14, mfc="white", mec=red, zorder=6)
ax.plot(*sc, marker="x", ms=8, mec=red, mew=2, zorder=7)
ax.text(sc[0] + 400, sc[1] + 300, "y = −h, into the page", color=red, fontsize=10)
for side in (-1, 1):  # tangents to the sphere of radius R + h: the limb
    direction = np.array([side * math.sin(rho), -math.cos(rho)])
    length = math.sqrt(r * r - (R + H_ATM) ** 2)
    ax.plot(*np.column_stack([sc, sc + direction * length]), color=blue, lw=1)
end = arrow((math.sin(phi), -math.cos(phi)), 6200.0, green)
ax.text(end[0] + 250, end[1] - 200, "body vector", color=green, fontsize=11)
angle_arc(1500.0, 0.0, rho, blue)
ax.text(sc[0] + 420, sc[1] - 2100, "ρ", color=blue, fontsize=13)
angle_arc(3400.0, 0.0, phi, green)
ax.text(sc[0] + 300, sc[1] - 4000, "nadir angle θ", color=green, fontsize=10)
angle_arc(5200.0, rho, phi, "k", lw=2)
ax.text(sc[0] + 4300, sc[1] - 1500, "limb angle = θ − ρ\n(> 0: above the limb)", fontsize=11)
ax.text(-2500, 3300, "Earth", fontsize=13, color="#2c5d8f")
ax.text(-6900, 3900, "R + h", fontsize=10, color=blue)
ax.text(-r * 0.86, r * 0.55, "orbit", color="0.45", fontsize=10)
ax.set_xlim(-9000, 11000)
ax.set_ylim(2200, 10600)
ax.set_title(
    "LVLH axes (CCSDS / Fehse: z to nadir, y = −orbit normal, x = y × z) and the limb angle,\n"
    "ρ = asin((R + h) / |r|): the angular radius of the sphere of radius R + h",
    fontsize=10,
)
out = Path(__file__).parents[1] / "images" / "lvlh_and_limb.png"
fig.savefig(out, bbox_inches="tight")
print(out)
