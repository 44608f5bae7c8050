"""Standing-wave records at the antinode x = L/2 of several standing_wave runs, one panel.

usage: /usr/bin/python3 examples/standing_wave/plot.py OUT.png "label=DIR" ["label=DIR" ...]
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    fig, ax = plt.subplots(figsize=(9, 3.6))
    for spec in sys.argv[2:]:
        label, folder = spec.rsplit("=", 1)
        data = np.loadtxt(f"{folder}/gauges.csv", delimiter=",", comments="#", skiprows=2)
        ax.plot(data[:, 0], 1000 * data[:, 1], lw=1.2, label=label)
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("eta at x = L/2 (mm)")
    ax.legend(fontsize=8, ncol=3)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(sys.argv[1], dpi=130)


if __name__ == "__main__":
    main()
