"""Effective length l_e / l against Ca from several blade_in_current output folders (e.g. two coupling variants).

usage: /usr/bin/python3 examples/blade_in_current/compare.py out.png "label=folder[,folder...]" ...
Each folder holds case_<Ca>.csv files written by examples/blade_in_current; a label's folders are searched in
order for each case, so reruns of single cases can complement a sweep. l_e / l = mean drag / mean drag of the rigid
blade of the same folder, averaged over the window the example uses (after the ramp plus 3 blade lengths).
"""
import csv
import glob
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

L, U, RHO, C_D_NOMINAL, RAMP, FROM = 0.05, 0.2, 1000.0, 2.0, 0.25, 3.0


def mean_drag(path):
    with open(path) as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    t = np.array([float(r["t"]) for r in rows])
    drag = np.array([float(r["drag"]) for r in rows])
    window = drag[t >= RAMP + FROM * L / U]
    blocks = np.array([b.mean() for b in np.array_split(window, 8)])
    return window.mean(), blocks.std(ddof=1) / np.sqrt(8)


out = sys.argv[1]
fig, ax = plt.subplots(figsize=(6.5, 4.2))
grid = np.logspace(-0.3, 3.4, 200)
ax.semilogx(grid, 1 - (1 - 0.9 * grid ** (-1 / 3)) / (1 + 8 * grid ** (-1.5)), "k-", label="Luhar & Nepf (2011), B = 0")
ax.fill_between(grid, 0.9 * (1 - (1 - 0.9 * grid ** (-1 / 3)) / (1 + 8 * grid ** (-1.5))),
                1.1 * (1 - (1 - 0.9 * grid ** (-1 / 3)) / (1 + 8 * grid ** (-1.5))), color="gray", alpha=0.2,
                label="model +-10 %")
for spec, marker in zip(sys.argv[2:], "osd^"):
    label, folders = spec.split("=", 1)
    folders = folders.split(",")
    cases = sorted({os.path.basename(p)[5:-4] for d in folders for p in glob.glob(os.path.join(d, "case_*.csv"))}
                   - {"rigid"}, key=float)
    ca, le, err = [], [], []
    for case in cases:
        folder = next(d for d in folders if os.path.exists(os.path.join(d, f"case_{case}.csv")))
        rigid, rigid_err = mean_drag(os.path.join(folder, "case_rigid.csv"))
        drag, drag_err = mean_drag(os.path.join(folder, f"case_{case}.csv"))
        c_d = rigid / (0.5 * RHO * U * U * L)
        ca.append(float(case) * c_d / C_D_NOMINAL)
        le.append(drag / rigid)
        err.append(drag / rigid * np.hypot(drag_err / drag, rigid_err / rigid))
    ax.errorbar(ca, le, yerr=err, fmt=marker, label=label, capsize=2)
ax.set_xlabel("Cauchy number Ca")
ax.set_ylabel("effective length l_e / l = F / F_rigid")
ax.grid(alpha=0.3, which="both")
ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(out, dpi=120)
print("wrote", out)
