"""Where the folded blade's drag comes from: mean posture and load along the blade (examples/blade_in_current's
shape_<Ca>.csv) against Luhar & Nepf's (2011) static posture and local law.

usage: /usr/bin/python3 examples/blade_in_current/posture.py PNG C_D "LABEL=CA=shape.csv" [...]

C_D is the rigid blade's drag coefficient of the runs (it sets the law's load and the Cauchy number's meaning). Each
shape file is one flexible case at Cauchy number CA; the left panel draws its mean posture with Luhar & Nepf's at the
same Ca, the right one the horizontal load per unit length along the blade (where the file has the force columns)
with the load that Luhar & Nepf's law (normal drag on the normal velocity: cos^3 theta horizontally) puts on the
same posture. Lengths are in blade lengths l = 0.05 m, loads in units of (1/2) rho U^2 C_D (U = 0.2 m/s).
"""
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "plotting"))
from sphfsi_csv import read_columns  # noqa: E402

LENGTH, SPEED, RHO = 0.05, 0.2, 1000.0


def luhar_nepf_posture(ca, steps=2000):
    """Static posture (x downstream, z up, in l) under the cos^2 normal law: shooting from the tip on its angle, as
    include/sphfsi/analysis/reconfiguration.hpp does (theta'' = Ca (sin theta G_z - cos theta G_x))."""

    def rate(y):
        th, dth, gx, gz, x, z = y
        c, s = math.cos(th), math.sin(th)
        fn = c * c
        return np.array([dth, ca * (s * gz - c * gx), -fn * c, fn * s, s, c])

    def shoot(tip_angle, keep=False):
        y = np.array([tip_angle, 0.0, 0.0, 0.0, 0.0, 0.0])
        h = -1.0 / steps
        path = [y.copy()]
        for _ in range(steps):
            k1 = rate(y)
            k2 = rate(y + 0.5 * h * k1)
            k3 = rate(y + 0.5 * h * k2)
            k4 = rate(y + h * k3)
            y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            if keep:
                path.append(y.copy())
        return y, path

    lo, hi = 0.0, math.pi / 2
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        if shoot(mid)[0][0] < 0:
            lo = mid
        else:
            hi = mid
    y, path = shoot(0.5 * (lo + hi), keep=True)
    path = np.array(path)  # from the tip to the base: positions relative to the tip
    return path[:, 4] - y[4], path[:, 5] - y[5]


png, drag_coefficient = sys.argv[1], float(sys.argv[2])
q = 0.5 * RHO * SPEED**2 * drag_coefficient  # load per unit length of the upright rigid blade (law), N/m^2
fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 4.2))
colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
drawn_models = set()
for k, arg in enumerate(sys.argv[3:]):
    label, ca, path = arg.split("=", 2)
    ca = float(ca)
    d = read_columns(path)
    x, z = -np.array(d["dx"]) / LENGTH, np.array(d["dy"]) / LENGTH  # downstream positive
    color = colors[k % len(colors)]
    ax.plot(x, z, "-", color=color, label=f"{label}, Ca = {ca:g}")
    if round(ca) not in drawn_models:
        mx, mz = luhar_nepf_posture(ca)
        ax.plot(mx, mz, "--", color=color, label=f"Luhar & Nepf static posture, Ca = {ca:g}")
        drawn_models.add(round(ca))
    if "force_x" not in d:
        continue
    ds = np.hypot(np.diff(x), np.diff(z))
    s = np.concatenate([[0], np.cumsum(ds)])
    cell = np.concatenate([[ds[0] / 2], (ds[:-1] + ds[1:]) / 2, [ds[-1] / 2]])
    load = -np.array(d["force_x"]) / (q * LENGTH * cell)  # drag per unit length over the law's upright load
    theta = np.arctan2(np.gradient(x), np.gradient(z))
    law = np.cos(theta) ** 3
    bx.plot(s, load, "o-", ms=3, color=color,
            label=f"{label}, Ca = {ca:g}: SPH, total {np.sum(load * cell):.3f}")
    bx.plot(s, law, ":", color=color, label=f"Luhar & Nepf's law on that posture, total {np.sum(law * cell):.3f}")
ax.set_xlabel("x / l (downstream)")
ax.set_ylabel("z / l")
ax.set_aspect("equal")
ax.set_ylim(-0.05, 1.05)
ax.legend(fontsize=7)
ax.set_title("mean posture")
bx.set_xlabel("arc length s / l from the base")
bx.set_ylabel("drag per unit length / ((1/2) rho U^2 C_D)")
bx.set_title("where the drag acts (total: l_e / l)")
bx.legend(fontsize=7)
for a in (ax, bx):
    a.grid(alpha=0.3)
fig.tight_layout()
fig.savefig(png, dpi=120)
print(f"wrote {png}")
