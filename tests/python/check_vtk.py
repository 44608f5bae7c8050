#!/usr/bin/env python3
"""Independent check of sphfsi's VTK output: reads what write_sample.cpp wrote with VTK's own
vtkXMLUnstructuredGridReader (the reader ParaView uses) and the .pvd collections with xml.etree, and compares
point counts, cells, field names, types and values with the formulas of write_sample.cpp.

usage: check_vtk.py <folder written by sphfsi_vtk_write_sample>
Exit status: 0 passed, 1 failed, 77 skipped (the Python vtk module is missing; the .pvd checks still ran).
"""
import math
import os
import sys
import types
import xml.etree.ElementTree as ET

SKIP = 77
SERIES = ["2d_double_raw", "3d_float_raw", "2d_float_base64", "3d_double_base64"]
TIMES = [0.0, 0.5]
VECTORS = ["velocity", "acceleration", "normal", "xsph_velocity", "force"]
SCALARS = ["density", "pressure", "mass", "smoothing_length", "sound_speed", "density_rate", "temperature"]
INTEGERS = ["kind", "body", "id"]

failures = []


def fail(msg):
    failures.append(msg)
    print("FAIL:", msg)


def expected(i, dim, t):
    """Values of particle id i at time t, as write_sample.cpp sets them (3 components, z = 0 in 2D)."""
    pad = lambda v: list(v) + [0.0] * (3 - len(v))
    v = [0.1 * (d + 1) - 0.003 * i for d in range(dim)]
    return {
        "position": pad([0.01 * i + 0.5 * d + v[d] * t for d in range(dim)]),
        "velocity": pad(v),
        "acceleration": pad([-9.81 if d == dim - 1 else 0.5 * i for d in range(dim)]),
        "normal": pad([1.0 if (i % 2 and d == 0) else 0.0 for d in range(dim)]),
        "xsph_velocity": pad([-0.001 * i] * dim),
        "force": pad([float(i), -float(i)] + [0.0] * (dim - 2)),
        "density": [1000 + 0.25 * i],
        "pressure": [3.5 * i - 20],
        "mass": [0.001 * (1 + i % 4)],
        "smoothing_length": [0.013],
        "sound_speed": [20 + 0.01 * i],
        "density_rate": [0.125 * i],
        "temperature": [300.0 + i],
        "kind": [i % 3],
        "body": [i % 4 - 1],
    }


def close(a, b, rel):
    return abs(a - b) <= rel * max(1.0, abs(b))


def check_pvd(folder, name):
    """The collection lists every snapshot, in order, with its time; returns the .vtu paths."""
    path = os.path.join(folder, name + ".pvd")
    if not os.path.isfile(path):
        fail(f"{path} is missing")
        return []
    root = ET.parse(path).getroot()
    if root.tag != "VTKFile" or root.get("type") != "Collection":
        fail(f"{path}: root is <{root.tag} type={root.get('type')}>, expected <VTKFile type=Collection>")
    sets = root.findall("./Collection/DataSet")
    times = [float(s.get("timestep")) for s in sets]
    if times != TIMES:
        fail(f"{path}: timesteps {times}, expected {TIMES}")
    files = []
    for k, s in enumerate(sets):
        f = os.path.join(folder, s.get("file"))
        if s.get("file") != f"{name}_{k:06d}.vtu" or not os.path.isfile(f):
            fail(f"{path}: DataSet {k} names '{s.get('file')}', missing or misnamed")
        files.append(f)
    return files


def check_vtu(vtk, path, dim, double, time):
    errors = []
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.AddObserver("ErrorEvent", lambda obj, ev: errors.append(ev))
    reader.SetFileName(path)
    reader.Update()
    grid = reader.GetOutput()
    if errors or reader.GetErrorCode() != 0:
        fail(f"{path}: VTK reader reported an error")
        return
    n = 50 if dim == 2 else 40
    if grid.GetNumberOfPoints() != n or grid.GetNumberOfCells() != n:
        fail(f"{path}: {grid.GetNumberOfPoints()} points, {grid.GetNumberOfCells()} cells, expected {n} each")
        return
    for c in range(n):
        if grid.GetCellType(c) != vtk.VTK_VERTEX or grid.GetCell(c).GetPointId(0) != c:
            fail(f"{path}: cell {c} is not a VTK_VERTEX on point {c}")
            return

    pd = grid.GetPointData()
    names = {pd.GetArrayName(k) for k in range(pd.GetNumberOfArrays())}
    wanted = set(VECTORS + SCALARS + INTEGERS)
    if names != wanted:
        fail(f"{path}: point data arrays {sorted(names)}, expected {sorted(wanted)}")
        return
    real_type = vtk.VTK_DOUBLE if double else vtk.VTK_FLOAT
    if grid.GetPoints().GetDataType() != real_type:
        fail(f"{path}: points are VTK type {grid.GetPoints().GetDataType()}, expected {real_type}")
    for name in VECTORS + SCALARS:
        arr = pd.GetArray(name)
        want_comp = 3 if name in VECTORS else 1
        if arr.GetDataType() != real_type or arr.GetNumberOfComponents() != want_comp:
            fail(f"{path}: '{name}' has type {arr.GetDataTypeAsString()} with {arr.GetNumberOfComponents()} "
                 f"components, expected {'double' if double else 'float'} x {want_comp}")
    for name, vtk_type in (("kind", vtk.VTK_UNSIGNED_CHAR), ("body", vtk.VTK_INT), ("id", vtk.VTK_UNSIGNED_INT)):
        if pd.GetArray(name).GetDataType() != vtk_type:
            fail(f"{path}: '{name}' has type {pd.GetArray(name).GetDataTypeAsString()}")

    fd = grid.GetFieldData().GetArray("TimeValue")
    if fd is None or fd.GetValue(0) != time:
        fail(f"{path}: field data TimeValue is {None if fd is None else fd.GetValue(0)}, expected {time}")

    ids = [int(pd.GetArray("id").GetTuple1(s)) for s in range(n)]
    if sorted(ids) != list(range(n)):
        fail(f"{path}: ids are not a permutation of 0..{n - 1}")
        return
    rel = 1e-12 if double else 2e-6
    points = grid.GetPoints()
    bad = 0
    for s, i in enumerate(ids):
        want = expected(i, dim, time)
        got = {"position": points.GetPoint(s)}
        for name in VECTORS + SCALARS + ["kind", "body"]:
            got[name] = pd.GetArray(name).GetTuple(s)
        for name, w in want.items():
            g = got[name]
            if len(g) != len(w) or not all(close(a, b, rel) for a, b in zip(g, w)):
                bad += 1
                if bad <= 5:
                    fail(f"{path}: slot {s} id {i} '{name}' = {tuple(g)}, expected {tuple(w)}")
    if ids[0] != (n - 1 if time == TIMES[1] else 0):
        fail(f"{path}: slot order not as written (first id {ids[0]})")


def main():
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    folder = sys.argv[1]
    if not os.path.isdir(folder):
        fail(f"sample folder {folder} does not exist (did sphfsi_vtk_write_sample run?)")
        return 1
    files = {name: check_pvd(folder, name) for name in SERIES}

    try:
        # Only the modules needed (importing the whole `vtk` package also loads rendering).
        from vtkmodules import vtkCommonCore, vtkCommonDataModel, vtkIOXML
        vtk = types.SimpleNamespace(**{k: v for m in (vtkCommonCore, vtkCommonDataModel, vtkIOXML)
                                       for k, v in vars(m).items() if not k.startswith("_")})
    except ImportError:
        try:
            import vtk
        except ImportError as e:
            print(f"SKIPPED: the Python vtk module is not available to {sys.executable} ({e}); "
                  f".pvd checks {'failed' if failures else 'passed'}")
            return 1 if failures else SKIP
    print(f"VTK {vtk.vtkVersion.GetVTKVersion()} from {sys.executable}")

    for name in SERIES:
        dim = int(name[0])
        double = "_double_" in name
        for k, path in enumerate(files[name]):
            if os.path.isfile(path):
                check_vtu(vtk, path, dim, double, TIMES[k])
                print(f"checked {path}")

    if failures:
        print(f"{len(failures)} failure(s)")
        return 1
    print("all VTK checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
