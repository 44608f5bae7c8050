"""Plot of examples/posidonia_flume: H(x) with and without plants, plant tip x(t) and z(t).

Usage: plot.py OUTPUT_FOLDER [PNG]   (reads comparison.csv and plants/tips.csv; writes OUTPUT_FOLDER/posidonia_flume.png
or PNG)"""
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "plotting"))
from sphfsi_csv import read_columns as read  # noqa: E402


out = sys.argv[1]
png = sys.argv[2] if len(sys.argv) > 2 else f"{out}/posidonia_flume.png"
c = read(f"{out}/comparison.csv")
tips_path = f"{out}/plants/tips.csv"
tips = read(tips_path) if os.path.exists(tips_path) else None
plant_x = []
if tips is not None:
    with open(tips_path) as f:
        first = f.readline()
    if "x = " in first:
        plant_x = [float(v) for v in first.split("x = ")[1].split(" m")[0].split(",")]

fig, (a, b, d) = plt.subplots(3, 1, figsize=(8, 9))
for key, label, style in (("H_empty", "empty flume", "s--"), ("H_plants", "with plant(s)", "o-")):
    if any(not math.isnan(v) for v in c[key]):
        a.plot(c["x"], [1000 * v for v in c[key]], style, label=label)
for x in plant_x:
    a.axvline(x, color="g", lw=0.8)
a.set_xlabel("x (m)")
a.set_ylabel("H (mm), zero up-crossing mean")
a.set_title("wave height at the gauges (green: plants)")
a.legend(fontsize=8)
if tips is not None:
    for k in range(len([n for n in tips if n.startswith("dx_")])):
        b.plot(tips["t"], [1000 * v for v in tips[f"dx_{k}"]], lw=0.9, label=f"plant {k}")
        d.plot(tips["t"], [1000 * v for v in tips[f"dz_{k}"]], lw=0.9, label=f"plant {k}")
    b.legend(fontsize=7, ncol=4)
b.set_xlabel("t (s)")
b.set_ylabel("tip dx (mm)")
d.set_xlabel("t (s)")
d.set_ylabel("tip dz (mm)")
fig.tight_layout()
fig.savefig(png, dpi=110)
print(f"plot: {png}")
