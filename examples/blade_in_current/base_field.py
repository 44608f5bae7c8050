"""The mean flow about the blade's base: examples/blade_in_current's base_field_<Ca>.csv (bins of dp / 4 in the
blade's frame, averaged over the drag's window), drawn as maps of the mean pressure and of the particle occupancy.

usage: /usr/bin/python3 examples/blade_in_current/base_field.py PNG DP "LABEL=base_field.csv" [...]

DP is the fluid spacing of the runs (m). The bins are merged to dp / 2 so that each holds particles of one lattice
column or row at most; a bin's pressure is the mean over the particles that were in it, in units of rho U^2
(U = 0.2 m/s, rho = 1000 kg/m^3), wall particles below the bed included. The blade stands at x = 0 from z = 0 up and
moves towards +x (its front face is on the right). One row of panels per file: pressure, and the mean number of
particles in a bin of dp / 2 (an empty band is a gap the fluid keeps from a wall).
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "plotting"))
from sphfsi_csv import read_columns  # noqa: E402

SPEED, RHO = 0.2, 1000.0
HALF_WINDOW = 4  # the maps show x within +-4 dp and z from -2 dp to 4 dp


def merged(path, dp):
    """(x edges, z edges, mean pressure / rho U^2, occupancy) on bins of dp / 2 (x, z in dp)."""
    c = read_columns(path)
    x, z = np.array(c["x"]) / dp, np.array(c["z"]) / dp
    p, n = np.array(c["pressure"]), np.array(c["occupancy"])
    ix, iz = np.floor(x / 0.5).astype(int), np.floor(z / 0.5).astype(int)
    xs, zs = np.arange(-2 * HALF_WINDOW, 2 * HALF_WINDOW), np.arange(-4, 2 * HALF_WINDOW)
    pressure = np.full((len(zs), len(xs)), np.nan)
    occupancy = np.zeros((len(zs), len(xs)))
    for j, kz in enumerate(zs):
        for i, kx in enumerate(xs):
            sel = (ix == kx) & (iz == kz) & (n > 0)
            occupancy[j, i] = n[sel].sum()
            if occupancy[j, i] > 0:
                pressure[j, i] = (p[sel] * n[sel]).sum() / occupancy[j, i] / (RHO * SPEED**2)
    return np.append(xs, xs[-1] + 1) * 0.5, np.append(zs, zs[-1] + 1) * 0.5, pressure, occupancy


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    png, dp = sys.argv[1], float(sys.argv[2])
    runs = [a.rsplit("=", 1) for a in sys.argv[3:]]
    fig, axes = plt.subplots(len(runs), 2, figsize=(10, 3.6 * len(runs)), squeeze=False)
    fields = [merged(path, dp) for _, path in runs]
    finite = np.concatenate([f[2][np.isfinite(f[2])] for f in fields])
    lo, hi = np.percentile(finite, [2, 98])
    for row, ((label, _), (xe, ze, pressure, occupancy)) in enumerate(zip(runs, fields)):
        ax = axes[row][0]
        m = ax.pcolormesh(xe, ze, pressure, cmap="coolwarm", vmin=lo, vmax=hi, shading="flat")
        fig.colorbar(m, ax=ax, label="mean p / (rho U^2)")
        ax.set_title(f"{label}: pressure", fontsize=9)
        ax = axes[row][1]
        m = ax.pcolormesh(xe, ze, occupancy, cmap="viridis", shading="flat")
        fig.colorbar(m, ax=ax, label="particles per dp/2 bin")
        ax.set_title(f"{label}: occupancy", fontsize=9)
        for ax in axes[row]:
            ax.plot([0, 0], [0, HALF_WINDOW], "k-", lw=2)  # the blade
            ax.axhline(0, color="k", lw=0.8)  # the bed
            ax.set_xlabel("x / dp (blade moves towards +x)")
            ax.set_ylabel("z / dp")
            ax.set_aspect("equal")
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    print(f"wrote {png}")


if __name__ == "__main__":
    main()
