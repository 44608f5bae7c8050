#!/usr/bin/python3
"""Particles of a refined_wave run (<output>/particles.csv, written with --end-time) near the refinement box,
coloured by speed, the fine ones smaller: where the refined flume goes unstable.

usage: /usr/bin/python3 examples/refined_wave/plot_particles.py <output> <x_min> <x_max> <png>
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np


def main():
    out, x_min, x_max, png = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
    with open(f"{out}/particles.csv") as f:
        lines = [line for line in f if not line.startswith("#")]
    p = np.genfromtxt(lines, delimiter=",", names=True)
    sel = (p["x"] > x_min) & (p["x"] < x_max)
    p = p[sel]
    fig, ax = plt.subplots(figsize=(12, 3.4))
    size = np.where(p["level"] > 0.75, 5, 18)
    sc = ax.scatter(p["x"], p["z"], s=size, c=p["speed"], cmap="viridis", vmin=0, vmax=np.percentile(p["speed"], 99))
    fig.colorbar(sc, ax=ax, label="speed (m/s)")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)")
    ax.set_title("refined flume before the wave arrives (large: base spacing, small: level 1)")
    fig.tight_layout()
    fig.savefig(png, dpi=110)


if __name__ == "__main__":
    main()
