"""H(x)/H_target of several wave_flume runs on one plot.
Usage: plot_resolutions.py OUT.png [--ylim=LO,HI] LABEL=FOLDER [LABEL=FOLDER ...] (each FOLDER holds a
wave_heights.csv)"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

fig, ax = plt.subplots(figsize=(7, 4.2))
ylim = (0.4, 1.15)
for arg in sys.argv[2:]:
    if arg.startswith("--ylim="):
        ylim = tuple(float(v) for v in arg[len("--ylim="):].split(","))
        continue
    label, folder = arg.rsplit("=", 1)
    with open(f"{folder}/wave_heights.csv") as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    ax.plot([float(r["x_over_L"]) for r in rows], [float(r["H_over_target"]) for r in rows], "o-", label=label)
    if "H_theory_over_target" in rows[0] and "order 1" in label:
        ax.plot([float(r["x_over_L"]) for r in rows], [float(r["H_theory_over_target"]) for r in rows], ":", lw=0.8,
                color=ax.lines[-1].get_color(), label="second-order theory, first-order paddle (beating)")
ax.axhline(1.0, color="k", lw=0.8)
ax.axhspan(0.95, 1.05, color="g", alpha=0.1, label="target +-5 %")
ax.set_xlabel("distance from the paddle, x / L")
ax.set_ylabel("H / H_target")
ax.set_ylim(*ylim)
ax.legend(fontsize=8)
ax.set_title("empty flume, h = 0.16 m, T = 1.4286 s, H = 0.028 m (piston)")
fig.tight_layout()
fig.savefig(sys.argv[1], dpi=110)
print(f"plot: {sys.argv[1]}")
