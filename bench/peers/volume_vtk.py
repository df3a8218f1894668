#!/usr/bin/python3
# The outside anchor of bench_translucent's volume_frame (issue 23): VTK's projected-tetrahedra volume
# renderer (vtkProjectedTetrahedraMapper) on the same TetGen box mesh, the same node field
# sin(3x) cos(4y) + z, the same transfer function (colour scale -1..2, opacity curve -1:0.02, 0.5:0.1,
# 2:0.6 per 0.25 world units, turned into VTK's per-unit-distance form), the same view direction and
# 1920x1080, the camera turning 7 degrees a frame. Prints the wall clock per frame (Render() and a
# glFinish by reading the pixels back), after one warm-up frame.
#
# Run under Xvfb with Mesa (Debian python3-vtk9, xvfb):
#   xvfb-run -s "-screen 0 1920x1080x24" /usr/bin/python3 bench/peers/volume_vtk.py \
#       /tmp/foxi-bench-box-2-1-1-4e-06/box.1 [frames]
# (the TetGen files bench_translucent caches; run it once first to make them).
import sys
import time

import numpy as np
import vtk
from vtk.util import numpy_support


def read_tetgen(base):
    with open(base + ".node") as f:
        n = int(f.readline().split()[0])
        node = np.array(f.read().split()[: 4 * n], dtype=float).reshape(n, 4)
    with open(base + ".ele") as f:
        m = int(f.readline().split()[0])
        ele = np.array(f.read().split()[: 5 * m], dtype=np.int64).reshape(m, 5)
    first = int(node[0, 0])
    return node[:, 1:4].copy(), ele[:, 1:5] - first


def main():
    if len(sys.argv) < 2:
        sys.exit("usage: volume_vtk.py TETGEN_BASE [frames]")
    frames = int(sys.argv[2]) if len(sys.argv) > 2 else 5
    xyz, tet = read_tetgen(sys.argv[1])
    grid = vtk.vtkUnstructuredGrid()
    pts = vtk.vtkPoints()
    pts.SetData(numpy_support.numpy_to_vtk(xyz, deep=True))
    grid.SetPoints(pts)
    cells = np.hstack([np.full((len(tet), 1), 4, dtype=np.int64), tet]).ravel()
    ca = vtk.vtkCellArray()
    ca.SetCells(len(tet), numpy_support.numpy_to_vtkIdTypeArray(cells, deep=True))
    grid.SetCells(vtk.VTK_TETRA, ca)
    field = np.sin(3 * xyz[:, 0]) * np.cos(4 * xyz[:, 1]) + xyz[:, 2]
    arr = numpy_support.numpy_to_vtk(field, deep=True)
    arr.SetName("f")
    grid.GetPointData().SetScalars(arr)

    color = vtk.vtkColorTransferFunction()
    color.AddRGBPoint(-1, 0.27, 0.0, 0.33)  # viridis-like ends; the colours do not change the cost
    color.AddRGBPoint(0.5, 0.13, 0.57, 0.55)
    color.AddRGBPoint(2, 0.99, 0.91, 0.14)
    opacity = vtk.vtkPiecewiseFunction()
    for v, a in ((-1, 0.02), (0.5, 0.1), (2, 0.6)):
        opacity.AddPoint(v, a)
    prop = vtk.vtkVolumeProperty()
    prop.SetColor(color)
    prop.SetScalarOpacity(opacity)
    prop.SetScalarOpacityUnitDistance(0.25)
    prop.ShadeOff()
    prop.SetInterpolationTypeToLinear()

    mapper = vtk.vtkProjectedTetrahedraMapper()
    mapper.SetInputData(grid)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)

    ren = vtk.vtkRenderer()
    ren.SetBackground(1, 1, 1)
    ren.AddVolume(volume)
    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(1920, 1080)
    win.AddRenderer(ren)
    cam = ren.GetActiveCamera()
    lo, hi = xyz.min(axis=0), xyz.max(axis=0)
    centre = 0.5 * (lo + hi)
    d = np.array([-1.0, 1.6, -0.9])
    d /= np.linalg.norm(d)
    cam.SetFocalPoint(*centre)
    cam.SetPosition(*(centre - 4 * d))
    cam.SetViewUp(0, 0, 1)
    cam.SetViewAngle(30)
    ren.ResetCamera()

    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.ReadFrontBufferOff()
    grab.ShouldRerenderOff()  # read what Render() drew, do not render a second time

    def frame():
        win.Render()
        grab.Modified()
        grab.Update()  # reads the pixels back: the frame is finished

    t0 = time.perf_counter()
    frame()
    print(f"tets {len(tet)} first frame (with VTK's setup) {1000 * (time.perf_counter() - t0):.0f} ms", flush=True)
    times = []
    for _ in range(frames):
        cam.Azimuth(7)
        t0 = time.perf_counter()
        frame()
        times.append(1000 * (time.perf_counter() - t0))
    times.sort()
    print("frame ms: " + " ".join(f"{t:.0f}" for t in times) + f"  median {times[len(times) // 2]:.0f}")


if __name__ == "__main__":
    main()
