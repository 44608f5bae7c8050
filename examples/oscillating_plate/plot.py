#!/usr/bin/python3
"""Plots the oscillating-plate runs: tip deflection against time and the period error against resolution.

usage: /usr/bin/python3 examples/oscillating_plate/plot.py RUN_DIR OUTPUT.png
RUN_DIR holds the CSV files written by `oscillating_plate --output`, named {tl,ul,gms}_vf01_r{N}.csv
(N = H/dp; gms: ULSPH with --gms, the original Gray-Monaghan-Swift sums); see docs/solids.md for the commands.
"""
import glob
import math
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

E, NU, RHO, H, L, KL = 2e6, 0.3975, 1000.0, 0.02, 0.2, 1.875
OMEGA = math.sqrt(E / (1 - NU**2) * H**2 * (KL / L) ** 4 / (12 * RHO))
PERIOD = 2 * math.pi / OMEGA


def period_of(t, w):
    """Mean period from upward zero crossings (linear interpolation), or nan."""
    up = [t[i - 1] + (t[i] - t[i - 1]) * (-w[i - 1]) / (w[i] - w[i - 1])
          for i in range(1, len(w)) if w[i - 1] < 0 <= w[i]]
    return (up[-1] - up[0]) / (len(up) - 1) if len(up) >= 2 else float("nan")


def main(run_dir, output):
    fig, (ax_t, ax_c) = plt.subplots(1, 2, figsize=(12, 4.5))
    convergence = {"tl": [], "ul": [], "gms": []}
    names = {"tl": "TLSPH", "ul": "ULSPH", "gms": "ULSPH, original GMS"}
    runs = [(p, re.search(r"(tl|ul|gms)_vf01_r(\d+)\.csv$", p)) for p in glob.glob(os.path.join(run_dir, "*_vf01_r*.csv"))]
    for path, match in sorted((r for r in runs if r[1]), key=lambda r: (r[1].group(1), int(r[1].group(2)))):
        model, n = match.groups()
        d = np.genfromtxt(path, delimiter=",", names=True)
        style = {"tl": "-", "ul": "--", "gms": ":"}[model]
        ax_t.plot(d["t"] / PERIOD, d["tip_deflection"] * 1e3, style, label=f"{names[model]} H/dp = {n}")
        convergence[model].append((int(n), 100 * (period_of(d["t"], d["tip_deflection"]) - PERIOD) / PERIOD))
    ax_t.set_xlabel("t / T_EB")
    ax_t.set_ylabel("tip deflection (mm)")
    ax_t.set_title("Oscillating plate, V_f = 0.01")
    ax_t.legend(fontsize=8)
    for model, marker in (("tl", "o"), ("ul", "s"), ("gms", "^")):
        pts = sorted(p for p in convergence[model] if not math.isnan(p[1]))
        if pts:
            ax_c.loglog([p[0] for p in pts], [abs(p[1]) for p in pts], marker + ("-" if model == "tl" else "--"),
                        label=names[model], fillstyle="full" if model == "tl" else "none")
    n_ref = np.array([4, 16])
    ax_c.loglog(n_ref, 3.7 * (4 / n_ref) ** 2, "k:", label="slope -2")
    ax_c.axhline(3, color="grey", lw=0.8)
    ax_c.set_xlabel("H / dp")
    ax_c.set_ylabel("|period error| vs Euler-Bernoulli (%)")
    ax_c.set_title("Convergence of the period")
    ax_c.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(output, dpi=120)
    for model, pts in convergence.items():
        for n, err in sorted(pts):
            print(f"{model} H/dp = {n}: period error {err:+.2f} %")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
