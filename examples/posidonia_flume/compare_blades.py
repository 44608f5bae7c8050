"""Side-by-side of posidonia_flume runs at equal resolution (e.g. --blade drag, rod and scaled): the change of H at
the gauges against the empty flume, and the tip displacement of the first plant with the water beside it.

Usage: /usr/bin/python3 examples/posidonia_flume/compare_blades.py PNG [--empty DIR] LABEL=DIR [LABEL=DIR ...]
With --empty DIR the heights of every run are compared with DIR/empty/wave_heights.csv (for runs made with
--runs plants and no --empty-from); otherwise each run's own comparison.csv is used.
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "plotting"))
from sphfsi_csv import read_columns as read  # noqa: E402


args = sys.argv[1:]
png = args.pop(0)
empty = None
if args and args[0] == "--empty":
    empty = read(os.path.join(args[1], "empty", "wave_heights.csv"))
    args = args[2:]
runs = [a.rsplit("=", 1) for a in args]  # the folder after the last "="
fig, (ax, bx, cx) = plt.subplots(1, 3, figsize=(15, 4))
width = 0.8 / len(runs)
for k, (label, folder) in enumerate(runs):
    if empty is not None:
        h = read(os.path.join(folder, "plants", "wave_heights.csv"))
        x, change = h["x"], [a / b - 1 for a, b in zip(h["H"], empty["H"])]
    else:
        c = read(os.path.join(folder, "comparison.csv"))
        x, change = c["x"], c["relative_change"]
    ax.bar([i + k * width for i in range(len(x))], [100 * v for v in change], width, label=label)
    t = read(os.path.join(folder, "plants", "tips.csv"))
    (line,) = bx.plot(t["t"], [1e3 * v for v in t["dx_0"]], lw=0.8, label=label)
    if "water_dx_0" in t:
        bx.plot(t["t"], [1e3 * v for v in t["water_dx_0"]], lw=0.6, ls=":", color=line.get_color())
    cx.plot(t["t"], [1e3 * v for v in t["dz_0"]], lw=0.8, label=label)
ax.set_xticks([i + 0.4 - width / 2 for i in range(len(x))])
ax.set_xticklabels([f"{v:.1f} m" for v in x])
ax.set_ylabel("H with the plant / H empty - 1 (%)")
ax.axhline(0, color="k", lw=0.6)
ax.legend(fontsize=8)
bx.set_xlabel("t (s)")
bx.set_ylabel("tip dx (mm); dotted: the water beside the tip")
cx.set_xlabel("t (s)")
cx.set_ylabel("tip dz (mm)")
for a in (ax, bx, cx):
    a.grid(alpha=0.3)
bx.legend(fontsize=8)
fig.tight_layout()
fig.savefig(png, dpi=120)
print("plot:", png)
