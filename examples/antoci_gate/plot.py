"""Plot the gate-tip displacement of examples/antoci_gate against the Antoci et al. (2007) experiment and the
published simulations.

usage: /usr/bin/python3 plot.py <output folder with gate_tip.csv> <data folder>   -> <output>/gate_tip.png
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path) as f:
        rows = list(csv.reader(line for line in f if not line.startswith("#")))
    return rows[0], rows[1:]


out, data = sys.argv[1], sys.argv[2]
h, rows = read(os.path.join(out, "gate_tip.csv"))
sim = {name: [float(r[i]) for r in rows] for i, name in enumerate(h)}
h, rows = read(os.path.join(data, "antoci2007_gate_tip_experiment.csv"))
exp = {name: [float(r[i]) if r[i] else float("nan") for r in rows] for i, name in enumerate(h)}
h, rows = read(os.path.join(data, "antoci2007_gate_tip_published_simulations.csv"))
published = {}
for method, component, t, d in rows:
    published.setdefault((method, component), ([], []))
    published[(method, component)][0].append(float(t))
    published[(method, component)][1].append(float(d))

fig, axes = plt.subplots(1, 2, figsize=(11, 4))
for ax, comp, key in ((axes[0], "x", "dx"), (axes[1], "y", "dy")):
    for (method, c), (t, d) in sorted(published.items()):
        if c == comp:
            ax.plot(t, [1e3 * v for v in d], "--", lw=1, label=method)
    ax.plot(exp["t"], [1e3 * v for v in exp[key]], "ks", label="experiment (Antoci 2007)")
    ax.plot(exp["t"], [1e3 * v for v in exp[key + "_alt"]], "k^", mfc="none", label="experiment, 2nd digitization")
    ax.plot(sim["t"], [1e3 * v for v in sim[key]], "r-", lw=2, label="sphfsi")
    ax.set_xlabel("t (s)")
    ax.set_ylabel(f"{key} of the free end (mm)")
    ax.set_xlim(0, 0.4)
    ax.grid(alpha=0.3)
axes[0].legend(fontsize=7)
fig.tight_layout()
path = os.path.join(out, "gate_tip.png")
fig.savefig(path, dpi=120)
print(f"wrote {path}")
