"""Fixtures for the windowed-sinc test: VTK's vtkWindowedSincPolyDataFilter on the bent tube.

Run with a Python that has VTK and numpy (the peers' venv):  python tests/peers/sinc_reference.py

Writes into tests/data/:
  sinc_vtk_tube_closed.bin     smoothed positions of synthetic_bent_tube_r3.5.ply (f32 LE, x y z per vertex)
  sinc_vtk_tube_open.bin       the same for the open tube (triangles with all corners above Z_CUT removed)
  sinc_vtk_tube_open_tris.bin  the open tube's triangles (u32 LE, 3 per triangle, original vertex indices)

VTK settings: NormalizeCoordinates on, FeatureEdgeSmoothing off, default window (Nuttall),
BoundarySmoothing on, PassBand 0.1, 20 iterations. EdgeAngle is set to 180 degrees: VTK otherwise
pins every boundary vertex where the boundary turns by more than 15 degrees, while our definition
(ALGORITHMS.md) smooths every boundary vertex along the boundary (at the default 15 degrees, 53
vertices of the open tube differ by more than 1e-3 of the diagonal). The open mesh keeps the
vertices of removed triangles, now isolated: we never move them; VTK moves them by (1 - f(0))
times their offset from the box centre, under 1e-4 mm here.
The point array is handed to VTK as-is, so point order is the PLY's.
"""
import pathlib
import sys

import numpy as np
import vtk
from vtk.util import numpy_support

ROOT = pathlib.Path(__file__).resolve().parents[2]
MESH = ROOT / ".." / "shared" / "data" / "synthetic" / "synthetic_bent_tube_r3.5.ply"
OUT = ROOT / "tests" / "data"
Z_CUT = 20.0
PASSBAND = 0.1
ITERATIONS = 20


def load_ply(path):
    """Binary little-endian PLY with float x y z and uchar/int triangle lists (the shared meshes)."""
    data = path.read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    assert "format binary_little_endian 1.0" in header, "binary little-endian PLY expected"
    counts = {}
    for line in header:
        words = line.split()
        if words[:1] == ["element"]:
            counts[words[1]] = int(words[2])
    assert header.count("property float x") == 1 and "property list uchar int vertex_indices" in header
    nv, nf = counts["vertex"], counts["face"]
    points = np.frombuffer(data, dtype="<f4", count=nv * 3, offset=end).reshape(nv, 3)
    faces = np.frombuffer(data, dtype=np.dtype([("n", "u1"), ("i", "<i4", (3,))]), count=nf, offset=end + nv * 12)
    assert (faces["n"] == 3).all(), "triangles only"
    return points.copy(), faces["i"].astype(np.int64)


def smooth_vtk(points, triangles):
    poly = vtk.vtkPolyData()
    vpoints = vtk.vtkPoints()
    vpoints.SetData(numpy_support.numpy_to_vtk(points.astype(np.float32), deep=True))
    poly.SetPoints(vpoints)
    cells = vtk.vtkCellArray()
    offsets = np.arange(0, 3 * len(triangles) + 1, 3, dtype=np.int64)
    cells.SetData(
        numpy_support.numpy_to_vtkIdTypeArray(offsets, deep=True),
        numpy_support.numpy_to_vtkIdTypeArray(triangles.ravel().copy(), deep=True),
    )
    poly.SetPolys(cells)
    f = vtk.vtkWindowedSincPolyDataFilter()
    f.SetInputData(poly)
    f.SetNumberOfIterations(ITERATIONS)
    f.SetPassBand(PASSBAND)
    f.NormalizeCoordinatesOn()
    f.FeatureEdgeSmoothingOff()
    f.BoundarySmoothingOn()
    f.SetEdgeAngle(180.0)
    f.Update()
    out = numpy_support.vtk_to_numpy(f.GetOutput().GetPoints().GetData())
    assert out.shape == points.shape
    return out.astype("<f4")


def boundary_edge_counts(triangles, n):
    """Per vertex, how many of its edges are used by exactly one triangle."""
    e = np.sort(np.vstack([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]]), axis=1)
    uniq, count = np.unique(e, axis=0, return_counts=True)
    b = uniq[count == 1]
    return np.bincount(b.ravel(), minlength=n)


def main():
    points, triangles = load_ply(MESH)
    closed = smooth_vtk(points, triangles)
    keep = ~(points[triangles][:, :, 2] > Z_CUT).all(axis=1)
    open_tris = triangles[keep]
    per_vertex = boundary_edge_counts(open_tris, len(points))
    on_boundary = per_vertex > 0
    # VTK pins boundary vertices with other than two boundary edges; keep the cut clean of them.
    assert (per_vertex[on_boundary] == 2).all(), "boundary vertex with more than two boundary edges"
    opened = smooth_vtk(points, open_tris)
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "sinc_vtk_tube_closed.bin").write_bytes(closed.tobytes())
    (OUT / "sinc_vtk_tube_open.bin").write_bytes(opened.tobytes())
    (OUT / "sinc_vtk_tube_open_tris.bin").write_bytes(open_tris.astype("<u4").tobytes())
    unused = len(points) - len(np.unique(open_tris))
    moved_unused = np.abs(opened - points).max(axis=1)[np.setdiff1d(np.arange(len(points)), open_tris)]
    print(
        f"VTK {vtk.vtkVersion.GetVTKVersion()}: {len(points)} vertices; open tube keeps {len(open_tris)} of "
        f"{len(triangles)} triangles, {on_boundary.sum()} boundary vertices, {unused} unused "
        f"(largest move of an unused vertex: {moved_unused.max() if unused else 0.0})",
        file=sys.stderr,
    )


if __name__ == "__main__":
    main()
