"""Effective length against the Cauchy number for several blade_in_current sweeps (summary.csv files), with Luhar &
Nepf's (2011) fit and its deviation.

usage: /usr/bin/python3 examples/blade_in_current/compare.py PNG LABEL=CSV[,CSV...] [LABEL=CSV ...]
Each LABEL's CSV files (summary.csv of runs, or their copies in docs/data) are merged.
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def fit(ca):
    return 1 - (1 - 0.9 * ca ** (-1 / 3)) / (1 + 8 * ca ** (-1.5))


png = sys.argv[1]
fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4))
grid = np.logspace(-0.3, 3.3, 200)
ax.semilogx(grid, fit(grid), "k-", label="Luhar & Nepf (2011) fit, B = 0")
ax.fill_between(grid, 0.9 * fit(grid), 1.1 * fit(grid), color="gray", alpha=0.2, label="fit +-10 %")
bx.axhspan(-10, 10, color="gray", alpha=0.2)
bx.axhline(0, color="k", lw=0.6)
for k, arg in enumerate(sys.argv[2:]):
    label, files = arg.rsplit("=", 1)
    rows = []
    for name in files.split(","):
        with open(name) as f:
            rows += [r for r in csv.DictReader(line for line in f if not line.startswith("#"))]
    flex = sorted((float(r["ca"]), float(r["effective_length"])) for r in rows if float(r["target_ca"]) > 0)
    ca, le = np.array([c for c, _ in flex]), np.array([v for _, v in flex])
    marker = "osd^v"[k % 5]
    ax.semilogx(ca, le, marker, label=label)
    bx.semilogx(ca, 100 * (le / fit(ca) - 1), marker + "-", label=label)
ax.set_xlabel("Cauchy number Ca")
ax.set_ylabel("effective length l_e / l")
ax.legend(fontsize=7)
bx.set_xlabel("Cauchy number Ca")
bx.set_ylabel("deviation from the fit (%)")
bx.legend(fontsize=7)
for a in (ax, bx):
    a.grid(alpha=0.3, which="both")
fig.tight_layout()
fig.savefig(png, dpi=120)
print("plot:", png)
