"""Convergence of the elastic rod against the elastica and Euler-Bernoulli (docs/thin-blades.md).

Usage: /usr/bin/python3 plot.py elastic_rod_static.csv elastic_rod_vibration.csv out.png
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


static, vibration, out = sys.argv[1], sys.argv[2], sys.argv[3]
fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
data = rows(static)
for alpha in sorted({float(r["alpha"]) for r in data}):
    sel = [r for r in data if float(r["alpha"]) == alpha]
    edges = [int(r["nodes"]) - 1 for r in sel]
    err = [abs(float(r["deflection"]) / float(r["deflection_elastica"]) - 1) for r in sel]
    a.loglog(edges, err, "o-", label=f"alpha = {alpha:g}")
ref = [10, 20, 40, 80]
a.loglog(ref, [0.5 / n**2 for n in ref], "k--", label="1/(2 n^2) (trapezoid)")
a.set_xlabel("edges n")
a.set_ylabel("|tip deflection error| (relative)")
a.set_title("tip load vs elastica")
a.legend(fontsize=7)
vib = rows(vibration)
edges = [int(r["nodes"]) - 1 for r in vib]
err = [float(r["period"]) / float(r["period_euler_bernoulli"]) - 1 for r in vib]
b.loglog(edges, err, "o-", label="first period error")
b.loglog(edges, [0.84 / n**2 for n in edges], "k--", label="0.84 / n^2")
b.set_xlabel("edges n")
b.set_ylabel("T1 / T1_EB - 1")
b.set_title("free vibration vs Euler-Bernoulli")
b.legend(fontsize=7)
fig.tight_layout()
fig.savefig(out, dpi=120)
