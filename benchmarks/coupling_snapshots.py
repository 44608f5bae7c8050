"""Snapshots of the Antoci gate for each coupling (benchmarks/run_coupling_comparison.sh output).

usage: /usr/bin/python3 benchmarks/coupling_snapshots.py <runs folder> <resolution> <png>
Reads the second VTK snapshot (t = 0.1 s with --snapshot-interval 0.1, or the one written at a blow-up) of
<coupling>_tl_<resolution> for each coupling (interface-mirror: eqs 10-16 as printed) and draws fluid (coloured by speed),
walls (black) and the gate (red) side by side. Needs the `vtk` Python module (python3-vtk9).
"""
import glob
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import vtk  # noqa: E402
from vtk.util.numpy_support import vtk_to_numpy  # noqa: E402

runs, res, png = sys.argv[1], sys.argv[2], sys.argv[3]
couplings = ["stress", "interface-mirror", "interface", "repulsive"]  # interface-mirror: eqs 10-16 as printed
fig, axes = plt.subplots(2, 2, figsize=(12, 6.4))
axes = axes.ravel()
for ax, coupling in zip(axes, couplings):
    files = sorted(glob.glob(os.path.join(runs, f"{coupling}_tl_{res}", "antoci_gate_*.vtu")))
    if not files:
        ax.set_title(f"{coupling}: no snapshot")
        continue
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(files[min(1, len(files) - 1)])  # t = 0.1 s, or the blow-up snapshot
    reader.Update()
    grid = reader.GetOutput()
    x = vtk_to_numpy(grid.GetPoints().GetData())
    data = grid.GetPointData()
    kind = vtk_to_numpy(data.GetArray("kind"))
    speed = np.linalg.norm(vtk_to_numpy(data.GetArray("velocity")), axis=1)
    time = grid.GetFieldData().GetArray("TimeValue").GetValue(0) if grid.GetFieldData().GetArray("TimeValue") else 0
    fluid = kind == 0
    sc = ax.scatter(x[fluid, 0], x[fluid, 1], c=np.minimum(speed[fluid], 3), s=1, cmap="viridis", vmin=0, vmax=3)
    ax.scatter(x[kind == 1, 0], x[kind == 1, 1], c="k", s=0.5)
    ax.scatter(x[kind == 2, 0], x[kind == 2, 1], c="r", s=1.5)
    ax.set_xlim(-0.01, 0.35)
    ax.set_ylim(-0.01, 0.16)
    ax.set_aspect("equal")
    ax.set_title(f"{coupling}, t = {time:.3f} s", fontsize=9)
fig.colorbar(sc, ax=axes, shrink=0.8, label="fluid speed (m/s)")
fig.savefig(png, dpi=110)
print(f"wrote {png}")
