#!/usr/bin/python3
"""The outside anchor of bench_iso (issue 17): VTK's vtkContourFilter (Debian's python3-vtk9) on the
same mesh and field as bench_iso, at the isovalues bench_iso picks for about 0.1 %, 1 % and 10 % of the
tets crossed, timed with the same crossing rule (min < v <= max of a tet's corner values).

    bench/peers/iso_vtk_contour.py [MESHBASE] [REPEATS]

MESHBASE: TetGen .node/.ele base name, by default the 0.97M-tet box bench_iso writes
(/tmp/foxi-bench-box-2-1-1-4e-06/box.1: run bench_iso once first). Field: sin(3x) cos(4y) + z at the
nodes. Prints one JSON line per crossing fraction: the values, tets crossed, triangles VTK made, and the
filter's wall time (the best and the median of REPEATS runs, default 5; the grid is built once, outside
the timing). VTK's filter is a full pass over all tets (it has no interval structure unless asked for a
scalar tree); foxi's pruned query + order + draw is the figure to set beside it.
"""
import json
import statistics
import sys
import time

import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray


def load(base):
    with open(base + ".node") as f:
        n = int(f.readline().split()[0])
    nodes = np.loadtxt(base + ".node", skiprows=1, max_rows=n, comments="#")
    with open(base + ".ele") as f:
        m = int(f.readline().split()[0])
    ele = np.loadtxt(base + ".ele", skiprows=1, max_rows=m, comments="#", dtype=np.int64)
    first = int(nodes[0, 0])  # TetGen numbers from 0 or 1, as the .node file does
    return nodes[:, 1:4].copy(), ele[:, 1:5] - first


def grid(P, T, values):
    pts = vtk.vtkPoints()
    pts.SetData(numpy_to_vtk(P, deep=True))
    ca = vtk.vtkCellArray()
    ca.SetData(numpy_to_vtkIdTypeArray(np.arange(0, 4 * len(T) + 1, 4, dtype=np.int64), deep=True),
               numpy_to_vtkIdTypeArray(T.ravel().astype(np.int64), deep=True))
    ug = vtk.vtkUnstructuredGrid()
    ug.SetPoints(pts)
    ug.SetCells(vtk.VTK_TETRA, ca)
    arr = numpy_to_vtk(values, deep=True)
    arr.SetName("f")
    ug.GetPointData().SetScalars(arr)
    return ug


def crossing_any(tmin, tmax, vs):
    hit = np.zeros(len(tmin), dtype=bool)
    for v in vs:
        hit |= (tmin < v) & (v <= tmax)
    return int(hit.sum())


def pick_values(f, T):
    """bench_iso's choice: of 400 evenly spaced values the one nearest 0.1 % and 1 % crossed; for 10 %
    the fewest evenly spaced values (k from 2) that cross 10 %."""
    c = f[T]
    tmin, tmax = c.min(1), c.max(1)
    lo, hi = f.min(), f.max()
    n = len(T)
    out = []
    for frac in (0.001, 0.01):
        best = None
        for i in range(1, 400):
            v = lo + (hi - lo) * i / 400
            k = crossing_any(tmin, tmax, [v])
            if best is None or abs(k - n * frac) < best[0]:
                best = (abs(k - n * frac), [v], k)
        out.append(("0.1%" if frac == 0.001 else "1%", best[1], best[2]))
    for k in range(2, 200):
        vs = [lo + (hi - lo) * (i + 0.5) / k for i in range(k)]
        hits = crossing_any(tmin, tmax, vs)
        if hits >= 0.1 * n:
            out.append(("10%", vs, hits))
            break
    return out


def main():
    base = sys.argv[1] if len(sys.argv) > 1 else "/tmp/foxi-bench-box-2-1-1-4e-06/box.1"
    repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 5
    P, T = load(base)
    f = np.sin(3 * P[:, 0]) * np.cos(4 * P[:, 1]) + P[:, 2]
    ug = grid(P, T, f)
    for label, vs, crossing in pick_values(f, T):
        times = []
        triangles = 0
        for _ in range(repeats):
            cf = vtk.vtkContourFilter()
            cf.SetInputData(ug)
            cf.SetNumberOfContours(len(vs))
            for i, v in enumerate(vs):
                cf.SetValue(i, v)
            cf.ComputeNormalsOff()
            cf.ComputeScalarsOff()
            t0 = time.perf_counter()
            cf.Update()
            times.append(1e3 * (time.perf_counter() - t0))
            triangles = cf.GetOutput().GetNumberOfCells()
        print(json.dumps(dict(mesh=base, tets=len(T), fraction=label, values=len(vs), crossing=crossing,
                              triangles=triangles, vtk_version=vtk.vtkVersion.GetVTKVersion(),
                              best_ms=round(min(times), 2), median_ms=round(statistics.median(times), 2))))


if __name__ == "__main__":
    main()
