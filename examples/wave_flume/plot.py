"""Plots of examples/wave_flume: gauge records and H(x). Usage: plot.py OUTPUT_FOLDER"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "plotting"))
from sphfsi_csv import read_columns as read  # noqa: E402


out = sys.argv[1]
g = read(f"{out}/gauges.csv")
h = read(f"{out}/wave_heights.csv")
fig, (a, b) = plt.subplots(2, 1, figsize=(8, 7))
names = [n for n in g if n.startswith("eta_")]
for k, n in enumerate(names):
    a.plot(g["t"], [1000 * v + 40 * k for v in g[n]], lw=0.8, label=f"x = {float(n[4:]):.2f} m (+{40 * k} mm)")
a.set_xlabel("t (s)")
a.set_ylabel("eta (mm), offset per gauge")
a.legend(fontsize=7, loc="upper left")
b.plot(h["x_over_L"], h["H_over_target"], "o-", label="SPH (zero up-crossing mean)")
if "H_theory_over_target" in h:
    b.plot(h["x_over_L"], h["H_theory_over_target"], "k--", lw=0.8, label="second-order theory, this paddle signal")
b.axhline(1.0, color="k", lw=0.8, label="target (Biesel, linear theory)")
b.axhspan(0.95, 1.05, color="g", alpha=0.1, label="+-5 %")
b.set_xlabel("x / L")
b.set_ylabel("H / H_target")
b.legend(fontsize=8)
fig.tight_layout()
fig.savefig(f"{out}/wave_flume.png", dpi=110)
print(f"plot: {out}/wave_flume.png")
