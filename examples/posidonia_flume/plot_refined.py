"""Fine fluid around the plant only (issue 9 part 4): the refined run against the uniformly fine and the uniformly
coarse runs of examples/posidonia_flume: H at the gauges, the tip's dx(t) and dz(t).

Usage: plot_refined.py PNG LABEL=FOLDER ...   (each FOLDER an --output of posidonia_flume with a plants run;
reads FOLDER/plants/wave_heights.csv and FOLDER/plants/tips.csv; H at the first run's gauges)"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "plotting"))
from sphfsi_csv import read_columns as read  # noqa: E402


png = sys.argv[1]
runs = [a.rsplit("=", 1) for a in sys.argv[2:]]
fig, (ax_h, ax_x, ax_z) = plt.subplots(3, 1, figsize=(9, 10))
reference = read(f"{runs[0][1]}/plants/wave_heights.csv")
for label, folder in runs:
    h = read(f"{folder}/plants/wave_heights.csv")
    # the gauges of the first run, matched by position (a run may have more, posidonia_flume --gauges)
    by_x = {round(x, 6): H for x, H in zip(h["x"], h["H"])}
    shared = [(x, by_x[round(x, 6)], H0) for x, H0 in zip(reference["x"], reference["H"]) if round(x, 6) in by_x]
    ax_h.plot([x for x, _, _ in shared], [100 * (a / b - 1) for _, a, b in shared], "o-", label=label)
    tips = read(f"{folder}/plants/tips.csv")
    ax_x.plot(tips["t"], [1e3 * v for v in tips["dx_0"]], lw=1, label=label)
    ax_z.plot(tips["t"], [1e3 * v for v in tips["dz_0"]], lw=1, label=label)
ax_h.axhspan(-2, 2, color="0.9", label="criterion 2 %")
ax_h.set_xlabel("gauge x (m)")
ax_h.set_ylabel(f"H / H({runs[0][0]}) - 1 (%)")
ax_h.legend(fontsize=8)
ax_x.set_ylabel("tip dx (mm)")
ax_z.set_ylabel("tip dz (mm)")
ax_z.set_xlabel("t (s)")
ax_x.legend(fontsize=8)
fig.suptitle("Posidonia flume, one porous real plant (l/h = 0.4): fine fluid around the plant only")
fig.tight_layout()
fig.savefig(png, dpi=110)
print(f"plot: {png}")
