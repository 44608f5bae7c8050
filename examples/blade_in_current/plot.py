"""Effective length of a blade in a current against Luhar & Nepf (2011): examples/blade_in_current.

usage: /usr/bin/python3 examples/blade_in_current/plot.py <output folder>
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

folder = sys.argv[1]
with open(os.path.join(folder, "summary.csv")) as f:
    rows = [r for r in csv.DictReader(line for line in f if not line.startswith("#"))]
flex = [r for r in rows if float(r["target_ca"]) > 0]
ca = np.array([float(r["ca"]) for r in flex])
le = np.array([float(r["effective_length"]) for r in flex])
err = np.array([float(r["effective_length_error"]) for r in flex])
grid = np.logspace(-0.5, 3.5, 200)
model = 1 - (1 - 0.9 * grid ** (-1 / 3)) / (1 + 8 * grid ** (-1.5))

fig, axes = plt.subplots(1, 2, figsize=(11, 4))
ax = axes[0]
ax.semilogx(grid, model, "k-", label="Luhar & Nepf (2011), B = 0")
ax.fill_between(grid, 0.9 * model, 1.1 * model, color="gray", alpha=0.2, label="model +-10 %")
ax.errorbar(ca, le, yerr=err, fmt="o", color="tab:red", label="sphfsi (rod + repulsive coupling)")
ax.set_xlabel("Cauchy number Ca")
ax.set_ylabel("effective length l_e / l = F / F_rigid")
ax.grid(alpha=0.3, which="both")
ax.legend(fontsize=8)
ax = axes[1]
for r in rows:
    label = "rigid" if float(r["target_ca"]) == 0 else f"Ca = {float(r['ca']):.3g}"
    tag = "rigid" if float(r["target_ca"]) == 0 else f"{float(r['target_ca']):g}"
    path = os.path.join(folder, f"case_{tag}.csv")
    if not os.path.exists(path):
        continue
    with open(path) as f:
        data = [d for d in csv.DictReader(line for line in f if not line.startswith("#"))]
    t = [float(d["t"]) for d in data]
    ax.plot(t, [float(d["drag"]) for d in data], lw=0.8, label=label)
ax.set_xlabel("t (s)")
ax.set_ylabel("drag F (N/m)")
ax.grid(alpha=0.3)
ax.legend(fontsize=7)
fig.tight_layout()
out = os.path.join(folder, "effective_length.png")
fig.savefig(out, dpi=120)
print("wrote", out)
