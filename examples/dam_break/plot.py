"""Plot the simulated surge front of examples/dam_break against Martin & Moyce (1952).

usage: /usr/bin/python3 plot.py <surge_front.csv> <martin_moyce1952_surge_front.csv> [comparison.csv]
Writes surge_front.png next to the simulation CSV.
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "plotting"))
from sphfsi_csv import read_columns as read  # noqa: E402


sim = read(sys.argv[1])
exp = read(sys.argv[2])
fig, ax = plt.subplots(figsize=(6, 4))
ax.plot(sim["T"], sim["front_over_a"], "-", label="sphfsi")
cmp_path = os.path.join(os.path.dirname(sys.argv[1]), "comparison.csv")
if os.path.exists(cmp_path):
    cmp = read(cmp_path)
    ax.plot(cmp["T_experiment"], cmp["front_aligned"], "s", mfc="none", label="sphfsi, time origin aligned")
ax.plot(exp["time"], exp["surge_front"], "k^", label="Martin & Moyce (1952)")
ax.set_xlabel(r"$T = n\,t\,\sqrt{g/a}$")
ax.set_ylabel(r"surge front $x_f / a$")
ax.set_xlim(0, max(sim["T"]))
ax.grid(alpha=0.3)
ax.legend()
fig.tight_layout()
out = os.path.join(os.path.dirname(sys.argv[1]), "surge_front.png")
fig.savefig(out, dpi=120)
print(f"wrote {out}")
