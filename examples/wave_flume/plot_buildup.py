"""Height of every zero up-crossing wave against time at each gauge of a wave_flume run: shows when the wave train
at a gauge has reached its steady height. Usage: plot_buildup.py OUT.png FOLDER [ramp_s group_velocity_m_s]
(defaults: 2 periods of 1.4286 s and c_g = 1.0672 m/s, the validation wave; dotted lines mark ramp + x / c_g + T,
where the default analysis window opens)."""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

out, folder = sys.argv[1], sys.argv[2]
ramp = float(sys.argv[3]) if len(sys.argv) > 3 else 2 * 1.4286
cg = float(sys.argv[4]) if len(sys.argv) > 4 else 1.0672
with open(f"{folder}/gauges.csv") as f:
    comment = [line for line in f if line.startswith("#")]
with open(f"{folder}/gauges.csv") as f:
    rows = list(csv.reader(line for line in f if not line.startswith("#")))
header, data = rows[0], [[float(v) for v in r] for r in rows[1:]]
t = [r[0] for r in data]
target = 0.028
for c in comment:  # "target H = 0.028 m"
    if "target H = " in c:
        target = float(c.split("target H = ")[1].split()[0])
fig, ax = plt.subplots(figsize=(7.5, 4.2))
for j, name in enumerate(header[1:], 1):
    x = float(name[4:])
    e = [r[j] for r in data]
    up = [i for i in range(len(e) - 1) if e[i] < 0 <= e[i + 1]]
    times, heights = [], []
    for a, b in zip(up, up[1:]):
        seg = e[a + 1 : b + 1]
        if max(seg) - min(seg) > 0.1 * target:
            times.append(t[a])
            heights.append((max(seg) - min(seg)) / target)
    line = ax.plot(times, heights, "o-", ms=3, label=f"x = {x:.2f} m")[0]
    ax.axvline(ramp + x / cg + 1.4286, color=line.get_color(), ls=":", lw=0.8)
ax.axhline(1.0, color="k", lw=0.8)
ax.set_xlabel("t (s), time of the wave's up-crossing")
ax.set_ylabel("H / H_target (each wave)")
ax.set_title(folder.rstrip("/").split("/")[-1])
ax.legend(fontsize=7, ncol=2)
fig.tight_layout()
fig.savefig(out, dpi=110)
print(f"plot: {out}")
