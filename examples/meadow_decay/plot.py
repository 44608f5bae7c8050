"""Plot of examples/meadow_decay: H/H0 along the meadow (raw and divided by the empty flume) against the measurement
of Luhar et al. (2017, case H1), and the tip excursion of three blades.

Usage: /usr/bin/python3 examples/meadow_decay/plot.py OUTPUT_DIR MEASURED_CSV [PNG]
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "plotting"))
from sphfsi_csv import read_columns as read  # noqa: E402


out, measured_path = sys.argv[1], sys.argv[2]
png = sys.argv[3] if len(sys.argv) > 3 else os.path.join(out, "meadow_decay.png")
d = read(os.path.join(out, "decay.csv"))
m = read(measured_path)
fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 4.2), gridspec_kw={"width_ratios": [2, 1]})
ax.plot(m["x"], m["H_over_H0"], "ko", label="measured (Luhar et al. 2017, H1)")
ax.plot(d["x"], d["H_over_H0"], "b.-", label="SPH, real blades: H / H(0)")
ax.plot(d["x"], d["H_over_H0_empty_normalised"], "r.--", label="SPH, divided by the empty flume")
ax.plot(d["x"], d["H_empty_over_H0_empty"], color="0.6", ls=":", label="SPH empty flume: H / H(0)")
ax.axvline(0, color="g", lw=0.8)
ax.set_xlabel("x from the meadow's leading edge (m)")
ax.set_ylabel("H / H0")
ax.legend(fontsize=8)
ax.grid(alpha=0.3)
tips = os.path.join(out, "meadow", "tips.csv")
if os.path.exists(tips):
    t = read(tips)
    for key, label in (("first", "first blade"), ("middle", "middle blade"), ("last", "last blade")):
        bx.plot(t["t"], [1e3 * v for v in t["dx_" + key]], lw=0.8, label=label + " dx")
    bx.set_xlabel("t (s)")
    bx.set_ylabel("tip displacement dx (mm)")
    bx.legend(fontsize=8)
    bx.grid(alpha=0.3)
fig.tight_layout()
fig.savefig(png, dpi=120)
print("plot:", png)
