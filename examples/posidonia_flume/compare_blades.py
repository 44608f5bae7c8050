"""Side-by-side of two posidonia_flume runs at equal resolution (e.g. --blade rod and --blade scaled): the change
of H at the gauges against the empty flume, and the tip displacement of the first plant.

Usage: /usr/bin/python3 examples/posidonia_flume/compare_blades.py PNG LABEL=DIR [LABEL=DIR ...]
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path) as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith("#"))]
    return {name: [float(r[i]) for r in rows[1:]] for i, name in enumerate(rows[0])}


png, runs = sys.argv[1], [a.split("=", 1) for a in sys.argv[2:]]
fig, (ax, bx, cx) = plt.subplots(1, 3, figsize=(15, 4))
width = 0.8 / len(runs)
for k, (label, folder) in enumerate(runs):
    c = read(os.path.join(folder, "comparison.csv"))
    ax.bar([i + k * width for i in range(len(c["x"]))], [100 * v for v in c["relative_change"]], width, label=label)
    t = read(os.path.join(folder, "plants", "tips.csv"))
    bx.plot(t["t"], [1e3 * v for v in t["dx_0"]], lw=0.8, label=label)
    cx.plot(t["t"], [1e3 * v for v in t["dz_0"]], lw=0.8, label=label)
ax.set_xticks([i + 0.4 - width / 2 for i in range(len(c["x"]))])
ax.set_xticklabels([f"{x:.1f} m" for x in c["x"]])
ax.set_ylabel("H with the plant / H empty - 1 (%)")
ax.axhline(0, color="k", lw=0.6)
ax.legend(fontsize=8)
bx.set_xlabel("t (s)")
bx.set_ylabel("tip dx (mm)")
cx.set_xlabel("t (s)")
cx.set_ylabel("tip dz (mm)")
for a in (ax, bx, cx):
    a.grid(alpha=0.3)
bx.legend(fontsize=8)
fig.tight_layout()
fig.savefig(png, dpi=120)
print("plot:", png)
