"""Surface elevation at the two gauges of examples/refined_wave, uniform against refined, and the refined run's
fine-particle count and active-mass change (counts.csv).

Usage: /usr/bin/python3 examples/refined_wave/plot_gauges.py <refined output> <uniform output> <png>
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np


def load(path):
    with open(path) as f:
        f.readline()  # '#' comment
        names = f.readline().strip().split(",")
    return names, np.loadtxt(path, delimiter=",", skiprows=2)


refined, uniform, png = sys.argv[1:4]
names, r = load(f"{refined}/gauges.csv")
_, u = load(f"{uniform}/gauges.csv")
_, c = load(f"{refined}/counts.csv")
fig, ax = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
for k, where in ((1, "upstream"), (2, "downstream")):
    a = ax[k - 1]
    a.plot(u[:, 0], 1e3 * u[:, k], "k-", lw=0.8, label="uniform dp")
    a.plot(r[:, 0], 1e3 * r[:, k], "r-", lw=0.8, label="refined box (APR)")
    a.set_ylabel(f"eta (mm), {where}\n{names[k]}")
    a.legend(loc="upper left", fontsize=8)
a = ax[2]
a.plot(c[:, 0], c[:, 3], "b-", label="fine (level-1) particles, active + passive")
a.set_ylabel("fine particles")
a.set_xlabel("t (s)")
b = a.twinx()
b.plot(c[:, 0], c[:, 4], "g--", label="relative active-mass change")
b.set_ylabel("active mass change")
a.legend(loc="lower left", fontsize=8)
b.legend(loc="lower right", fontsize=8)
fig.tight_layout()
fig.savefig(png, dpi=110)
