#!/usr/bin/python3
"""Figure of the refined tank (examples/refined_tank): the particles at the end coloured by level, the pressure on
the centre line against rho0 g (H_s - z), and the mid-depth error and kinetic energy over time (refined and
uniform runs).

usage: /usr/bin/python3 examples/refined_tank/plot.py <refined output> <uniform output> <png>
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np


def read(path):
    with open(path) as f:
        lines = [line for line in f if not line.startswith("#")]
    return np.genfromtxt(lines, delimiter=",", names=True)


def main():
    refined, uniform, png = sys.argv[1], sys.argv[2], sys.argv[3]
    parts = read(f"{refined}/particles.csv")
    prof = read(f"{refined}/profile.csv")
    pr, pu = read(f"{refined}/probe.csv"), read(f"{uniform}/probe.csv")
    fig, ax = plt.subplots(1, 3, figsize=(13, 4.6))
    sizes = {0: 14, 1: 4, 2: 1}
    for level, colour in ((0, "tab:blue"), (1, "tab:orange"), (2, "tab:red")):
        sel = np.abs(parts["level"] - level) < 0.3
        ax[0].scatter(parts["x"][sel], parts["z"][sel], s=sizes[level], c=colour, label=f"level {level}")
    ax[0].set_aspect("equal")
    ax[0].set_xlabel("x (m)")
    ax[0].set_ylabel("z (m)")
    ax[0].set_title("particles at the end, by level")
    ax[0].legend(loc="upper right", fontsize=8)
    ax[1].plot(prof["p_theory"], prof["z"], "k-", label="rho0 g (H_s - z)")
    ax[1].plot(prof["p_sph"], prof["z"], "r.", ms=3, label="SPH (Shepard), centre line")
    ax[1].set_xlabel("p (Pa)")
    ax[1].set_ylabel("z (m)")
    ax[1].legend(fontsize=8)
    ax[1].set_title("pressure profile at the end")
    ax[2].semilogy(pr["t"], pr["kinetic_energy"], "r-", label="kinetic energy, refined")
    ax[2].semilogy(pu["t"], pu["kinetic_energy"], "b-", label="kinetic energy, uniform")
    ax[2].set_xlabel("t (s)")
    ax[2].set_ylabel("E_k (J/m)")
    a2 = ax[2].twinx()
    a2.plot(pr["t"], 100 * pr["relative_error"], "r:", label="mid-depth error, refined")
    a2.plot(pu["t"], 100 * pu["relative_error"], "b:", label="mid-depth error, uniform")
    a2.set_ylim(-5, 5)
    a2.set_ylabel("p error at mid-depth (%)")
    ax[2].legend(loc="upper right", fontsize=7)
    a2.legend(loc="lower right", fontsize=7)
    ax[2].set_title("settling")
    fig.tight_layout()
    fig.savefig(png, dpi=110)


if __name__ == "__main__":
    main()
