"""The resolved 2D blade against Luhar & Nepf: its local force law (rigid inclined blades) and its effective length.

usage: /usr/bin/python3 examples/blade_in_current/force_law.py PNG BED_CSV MIDWATER_CSV RESOLVED_CSV POROUS_CSV[,...]
BED_CSV, MIDWATER_CSV: inclined.csv of `blade_in_current --inclinations` (base on the bed / --mount-height 2);
RESOLVED_CSV: summary.csv of the resolved flexible sweep run with --force-law; POROUS_CSV: summary.csv files of the
porous rod (--coupling drag), merged.
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def rows(names):
    out = []
    for name in names.split(","):
        with open(name) as f:
            out += list(csv.DictReader(line for line in f if not line.startswith("#")))
    return out


def fit(ca):
    return 1 - (1 - 0.9 * ca ** (-1 / 3)) / (1 + 8 * ca ** (-1.5))


png, bed, mid, resolved, porous = sys.argv[1:6]
fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.2))
theta = np.linspace(0, 90, 200)
ax.plot(theta, np.cos(np.radians(theta)) ** 2, "k-", label="cos^2 (Luhar & Nepf: normal velocity squared)")
for label, name, marker in (("SPH, base on the bed", bed, "o"), ("SPH, plate in open water", mid, "s")):
    r = rows(name)
    deg = np.array([float(x["inclination_deg"]) for x in r])
    cn = np.array([float(x["normal_load"]) for x in r])
    # standard error of the normal load from those of drag and lift (independent blocks assumed)
    c0 = float(r[0]["normal_coefficient"])
    dyn = float(r[0]["drag"]) / c0
    err = np.hypot(np.array([float(x["drag_error"]) for x in r]) * np.cos(np.radians(deg)),
                   np.array([float(x["lift_error"]) for x in r]) * np.sin(np.radians(deg))) / (dyn * c0)
    ax.errorbar(deg, cn, yerr=err, fmt=marker, capsize=3, label=label)
ax.set_xlabel("inclination from the vertical (degrees)")
ax.set_ylabel("normal force / that of the upright blade")
ax.set_title("local force law of a rigid inclined blade", fontsize=9)
ax.legend(fontsize=7)
grid = np.logspace(-0.3, 3.3, 200)
bx.semilogx(grid, fit(grid), "k-", label="Luhar & Nepf (2011) fit")
bx.fill_between(grid, 0.9 * fit(grid), 1.1 * fit(grid), color="gray", alpha=0.2, label="fit +-10 %")
r = [x for x in rows(resolved) if float(x["target_ca"]) > 0 and x["effective_length"] != "nan"]
ca = np.array([float(x["ca"]) for x in r])
bx.errorbar(ca, [float(x["effective_length"]) for x in r], yerr=[float(x["effective_length_error"]) for x in r],
            fmt="o", capsize=3, label="resolved blade (repulsive coupling), SPH")
bx.semilogx(ca, [float(x["model_2d"]) for x in r], "x", ms=8,
            label="static model with the measured force law (bed)")
p = [x for x in rows(porous) if float(x["target_ca"]) > 0]
bx.semilogx([float(x["ca"]) for x in p], [float(x["effective_length"]) for x in p], "d",
            label="porous rod (Morison drag), SPH")
bx.set_xlabel("Cauchy number Ca")
bx.set_ylabel("effective length l_e / l")
bx.set_title("blade in a current: effective length", fontsize=9)
bx.legend(fontsize=7)
for a in (ax, bx):
    a.grid(alpha=0.3, which="both")
fig.tight_layout()
fig.savefig(png, dpi=120)
print("plot:", png)
