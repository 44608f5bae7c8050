#!/usr/bin/python3
"""Plots the hydrostatic tank results: mid-depth pressure over time and the final pressure profile p(z) vs theory.

Usage: /usr/bin/python3 plot.py OUTPUT_FOLDER [OUTPUT_FOLDER ...]
Reads probe.csv and profile.csv written by the hydrostatic_tank example in each folder and writes
OUTPUT_FOLDER/hydrostatic_tank.png (for several folders: one figure per folder). Exits 0 without a plot when
matplotlib is missing.
"""
import os
import sys


def read_csv(path):
    header, rows, comment = None, [], []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if not line:
                continue
            if line.startswith("#"):
                comment.append(line[1:].strip())
                continue
            if header is None:
                header = line.split(",")
                continue
            rows.append([float(v) for v in line.split(",")])
    return {name: [r[i] for r in rows] for i, name in enumerate(header)}, " ".join(comment)


def plot(folder, plt):
    probe, probe_title = read_csv(os.path.join(folder, "probe.csv"))
    profile, profile_title = read_csv(os.path.join(folder, "profile.csv"))
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    t = probe["t"][1:]  # the first sample is the initial state before any evaluation (no pressure yet)
    ax1.plot(t, [100 * e for e in probe["relative_error"][1:]], lw=1, label="probe (Shepard average at L/2, H/2)")
    if "band_error" in probe:
        ax1.plot(t, [100 * e for e in probe["band_error"][1:]], lw=1, alpha=0.8,
                 label="band average (|z - H/2| <= H/10, central half)")
    ax1.axhspan(-2, 2, color="green", alpha=0.12, label="2 % band")
    ax1.set_xlabel("t (s)")
    ax1.set_ylabel("mid-depth pressure error (%)")
    ax1.set_title("(p_SPH - rho0 g (H_s - z)) / rho0 g (H_s - z)", fontsize=9)
    ax1.legend(loc="best", fontsize=8)
    ax1.grid(alpha=0.3)
    ax2.plot([p / 1000 for p in profile["p_theory"]], profile["z"], "k-", label="rho0 g (H_s - z)")
    ax2.plot([p / 1000 for p in profile["p_sph"]], profile["z"], "r.", ms=3, label="SPH (Shepard average)")
    ax2.set_xlabel("p (kPa)")
    ax2.set_ylabel("z (m)")
    ax2.set_title(profile_title, fontsize=8)
    ax2.legend(loc="best", fontsize=8)
    ax2.grid(alpha=0.3)
    fig.suptitle(probe_title, fontsize=8)
    fig.tight_layout()
    out = os.path.join(folder, "hydrostatic_tank.png")
    fig.savefig(out, dpi=120)
    plt.close(fig)
    print(f"wrote {out}")


def main():
    if len(sys.argv) < 2:
        print(__doc__)
        return 2
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not available: no plot")
        return 0
    for folder in sys.argv[1:]:
        plot(folder, plt)
    return 0


if __name__ == "__main__":
    sys.exit(main())
