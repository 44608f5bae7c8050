"""Chart and table of the Antoci-gate coupling comparison (benchmarks/run_coupling_comparison.sh).

usage: /usr/bin/python3 benchmarks/coupling_chart.py <runs folder> <docs folder> [recorded runs CSV]
Writes <docs>/img/coupling_error_vs_time.png, <docs>/img/coupling_tip_curves.png and prints a Markdown table.
Runs are read from <runs>/<coupling>_<solid>_<A/dp>[_r<refinement>]/summary.csv and, for runs whose folders are
gone, from the recorded CSV (docs/data/antoci_coupling_runs.csv: one row per run, the table of the docs).
"""
import csv
import glob
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path) as f:
        rows = list(csv.reader(line for line in f if not line.startswith("#")))
    def value(text):
        try:
            return float(text) if text else float("nan")
        except ValueError:
            return text  # a label column (coupling, solid)

    return {name: [value(r[i]) for r in rows[1:]] for i, name in enumerate(rows[0])}


runs, docs = sys.argv[1], sys.argv[2]
results = []
for summary in sorted(glob.glob(os.path.join(runs, "*", "summary.csv"))):
    name = os.path.basename(os.path.dirname(summary))
    parts = name.split("_")
    coupling, solid, res = parts[:3]
    refinement = int(parts[3][1:]) if len(parts) > 3 else 1
    s = read(summary)
    results.append(dict(coupling=coupling, solid=solid, res=int(res), refinement=refinement,
                        dir=os.path.dirname(summary), **{k: v[0] for k, v in s.items()}))
if len(sys.argv) > 3:
    recorded = read(sys.argv[3])
    have = {(r["coupling"], r["solid"], r["res"], r["refinement"]) for r in results}
    with open(sys.argv[3]) as f:
        labels = list(csv.reader(line for line in f if not line.startswith("#")))[1:]
    for k, row in enumerate(labels):
        key = (row[0], row[1], int(row[2]), int(row[3]))
        if key in have:
            continue
        results.append(dict(coupling=row[0], solid=row[1], res=int(row[2]), refinement=int(row[3]), dir=None,
                            **{n: recorded[n][k] for n in recorded if n not in ("coupling", "solid", "res",
                                                                                "solid_refinement")}))
results.sort(key=lambda r: (r["coupling"], r["solid"], r["res"], r["refinement"]))

print("| coupling | solid | A/dp | gate spacing | particles | wall time (s) | reached t (s) | RMS dx (mm) "
      "| RMS dy (mm) | max stretch | fluid inside gate (max) | blow-up |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|")
for r in results:
    blew = "yes" if r["blew_up"] else "no"
    dx = "n/a" if r["rms_dx"] != r["rms_dx"] else f"{1e3 * r['rms_dx']:.2f}"
    dy = "n/a" if r["rms_dy"] != r["rms_dy"] else f"{1e3 * r['rms_dy']:.2f}"
    spacing = "dp" if r["refinement"] == 1 else f"dp/{r['refinement']}"
    print(f"| {r['coupling']} | {r['solid']} | {r['res']} | {spacing} | {int(r['particles'])} | {r['wall_s']:.0f} | "
          f"{r['end_time']:.3f} | {dx} | {dy} | {r['max_stretch']:.2f} | {int(r['fluid_inside_max'])} | {blew} |")

os.makedirs(os.path.join(docs, "img"), exist_ok=True)
markers = {"repulsive": "o", "interface": "s", "interface-mirror": "x", "stress": "^"}
colors = {"tl": "tab:blue", "ul": "tab:orange", "ul-gms": "tab:green", "ul-v1": "tab:gray"}
fig, axes = plt.subplots(1, 2, figsize=(11, 4))
for ax, key, ref in ((axes[0], "rms_dx", 3.9), (axes[1], "rms_dy", 1.8)):
    no_score = 60.0 if key == "rms_dx" else 20.0  # runs that stopped before 0.36 s have no score: drawn here
    for r in results:
        scored = r[key] == r[key]
        y = 1e3 * r[key] if scored else no_score
        marker = markers[r["coupling"]] if r["refinement"] == 1 else "D"
        ax.loglog(r["wall_s"], y, marker, color=colors[r["solid"]],
                  mfc="none" if r["blew_up"] else colors[r["solid"]], ms=5 + r["res"] / 20)
        label = str(r["res"])  # stopped runs: where they stopped is in the table
        if r["refinement"] != 1:
            label += f", gate dp/{r['refinement']}"
        ax.annotate(label, (r["wall_s"], y), fontsize=6)
    ax.axhline(no_score, color="gray", ls=":", lw=1)
    ax.text(ax.get_xlim()[0], no_score * 1.05, "no score (run stopped)", fontsize=6, color="gray")
    ax.axhline(ref, color="k", ls="--", lw=1, label=f"Antoci 2007 SPH ({ref} mm)")
    ax.set_xlabel("wall time for 0.4 s on the shared 2-core machine (s)")
    ax.set_ylabel(f"RMS error {key[-2:]} (mm)")
    ax.grid(alpha=0.3, which="both")
for c, m in markers.items():
    axes[0].plot([], [], m, color="gray", label=c)
for s, col in colors.items():
    axes[0].plot([], [], "o", color=col, label=f"solid {s}")
axes[0].plot([], [], "o", mfc="none", color="gray", label="stopped (blow-up / break)")
axes[0].plot([], [], "D", color="gray", label="gate finer than the fluid")
axes[0].legend(fontsize=7)
fig.suptitle("Antoci gate: error against cost (label = A/dp)")
fig.tight_layout()
fig.savefig(os.path.join(docs, "img", "coupling_error_vs_time.png"), dpi=120)

fig, axes = plt.subplots(1, 2, figsize=(11, 4))
for r in results:
    if r["res"] != 80 or r["dir"] is None or r["refinement"] != 1:
        continue
    tip = read(os.path.join(r["dir"], "gate_tip.csv"))
    for ax, key in ((axes[0], "dx"), (axes[1], "dy")):
        ax.plot(tip["t"], [1e3 * v for v in tip[key]], "-" if r["solid"] == "tl" else "--",
                label=f"{r['coupling']} / {r['solid']}")
for ax, key in ((axes[0], "dx"), (axes[1], "dy")):
    exp = read(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data",
                            "antoci2007_gate_tip_experiment.csv"))
    ax.plot(exp["t"], [1e3 * v for v in exp[key]], "ks", label="experiment")
    ax.set_xlabel("t (s)")
    ax.set_ylabel(f"{key} (mm)")
    ax.grid(alpha=0.3)
axes[0].legend(fontsize=7)
fig.tight_layout()
fig.savefig(os.path.join(docs, "img", "coupling_tip_curves.png"), dpi=120)

# Code-to-code: RMS difference of each A/dp = 80 run from the published simulations at t = 0.04 ... 0.36 s.
published = {}
with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data",
                       "antoci2007_gate_tip_published_simulations.csv")) as f:
    for row in list(csv.reader(line for line in f if not line.startswith("#")))[1:]:
        published.setdefault((row[0], row[1]), []).append((float(row[2]), float(row[3])))


def interpolate(ts, vs, t):
    """Linear interpolation, held at the ends (Yang 2012's digitized curve stops at 0.354 s, before 0.36 s)."""
    pairs = sorted(zip(ts, vs))
    if t <= pairs[0][0]:
        return pairs[0][1]
    if t >= pairs[-1][0]:
        return pairs[-1][1]
    for (t0, v0), (t1, v1) in zip(pairs, pairs[1:]):
        if t0 <= t <= t1:
            return v0 + (v1 - v0) * (t - t0) / (t1 - t0) if t1 > t0 else v0
    return float("nan")


times = [0.04 * k for k in range(1, 10)]
methods = sorted({m for m, _ in published})
print("\n| run (A/dp = 80) | " + " | ".join(f"vs {m}: dx / dy (mm)" for m in methods) + " |")
print("|---|" + "---|" * len(methods))
for r in results:
    if r["res"] != 80 or r["dir"] is None or r["refinement"] != 1 or r["blew_up"]:
        continue
    tip = read(os.path.join(r["dir"], "gate_tip.csv"))
    cells = []
    for m in methods:
        rms = []
        for key, comp in (("dx", "x"), ("dy", "y")):
            ref = published[(m, comp)]
            diff = [interpolate(tip["t"], tip[key], t) - interpolate([p[0] for p in ref], [p[1] for p in ref], t)
                    for t in times]
            rms.append(1e3 * (sum(d * d for d in diff) / len(diff)) ** 0.5)
        cells.append(f"{rms[0]:.1f} / {rms[1]:.1f}")
    print(f"| {r['coupling']} / {r['solid']} | " + " | ".join(cells) + " |")
