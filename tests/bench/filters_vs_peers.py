"""Speed of the four CPU filters against the usual Python-accessible implementations.

Run with a Python that has numpy, trimesh, vtk, pymeshlab and open3d (the peers' venv), after
`cargo build --release`:

    python tests/bench/filters_vs_peers.py [--mesh PATH] [--iterations 20] [--repeats 5]

Each peer is timed at its best: inputs built and operators precomputed outside the timing, best of
`--repeats` runs. trimesh's Laplacian operator is built once (laplacian_calculation) and passed in,
with volume_constraint=False. Taubin: one iteration is a lambda step and a mu step, so trimesh
(which counts steps) runs 2x the iterations. pymeshlab's HC has no iteration count: it is called
once per iteration. Formulas differ where noted (MeshLab's Laplace includes the vertex itself and
its HC is not Vollmer's; Open3D weights neighbours by distance); the point here is speed.

Ours: `target/release/meshsmooth bench FILE --filter F --iterations N --json`, which prints
{filter, vertices, iterations, seconds, vertex_iterations_per_second, measure_seconds, backend}.
`--ours-cmd` replaces that command (placeholders {file} {filter} {iterations}).
Throughput is vertex-iterations per second: vertices x iterations / seconds.
"""
import argparse
import json
import os
import pathlib
import shlex
import subprocess
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
DEFAULT_MESH = ROOT / ".." / "shared" / "data" / "segmentations" / "seg_mni152_gm_plus_wm_p0.5_1mm.ply"
FILTERS = ["laplace", "taubin", "hc", "sinc"]


def load_ply(path):
    """Binary little-endian PLY, float x y z and uchar/int triangle lists (the shared meshes)."""
    data = pathlib.Path(path).read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    assert "format binary_little_endian 1.0" in header, "binary little-endian PLY expected"
    counts = {w[1]: int(w[2]) for w in (line.split() for line in header) if w[:1] == ["element"]}
    nv, nf = counts["vertex"], counts["face"]
    points = np.frombuffer(data, dtype="<f4", count=nv * 3, offset=end).reshape(nv, 3)
    faces = np.frombuffer(data, dtype=np.dtype([("n", "u1"), ("i", "<i4", (3,))]), count=nf, offset=end + nv * 12)
    assert (faces["n"] == 3).all(), "triangles only"
    return points.astype(np.float64), faces["i"].astype(np.int64)


def best_of(repeats, prepare, run):
    """Best wall time of `run(prepare())`, preparation untimed."""
    best = float("inf")
    for _ in range(repeats):
        arg = prepare()
        t = time.perf_counter()
        run(arg)
        best = min(best, time.perf_counter() - t)
    return best


def trimesh_peers(points, faces, its, repeats):
    import trimesh
    from trimesh import smoothing

    base = trimesh.Trimesh(points, faces, process=False)
    op = smoothing.laplacian_calculation(base)
    copy = lambda: base.copy()  # noqa: E731
    yield "laplace", "trimesh filter_laplacian", best_of(
        repeats, copy, lambda m: smoothing.filter_laplacian(m, lamb=0.5, iterations=its, volume_constraint=False, laplacian_operator=op)
    )
    yield "taubin", "trimesh filter_taubin", best_of(
        repeats, copy, lambda m: smoothing.filter_taubin(m, lamb=0.5, nu=0.53, iterations=2 * its, laplacian_operator=op)
    )
    yield "hc", "trimesh filter_humphrey", best_of(
        repeats, copy, lambda m: smoothing.filter_humphrey(m, alpha=0.1, beta=0.5, iterations=its, laplacian_operator=op)
    )


def vtk_peers(points, faces, its, repeats):
    import vtk
    from vtk.util import numpy_support

    poly = vtk.vtkPolyData()
    vpoints = vtk.vtkPoints()
    vpoints.SetData(numpy_support.numpy_to_vtk(points.astype(np.float32), deep=True))
    poly.SetPoints(vpoints)
    cells = vtk.vtkCellArray()
    cells.SetData(
        numpy_support.numpy_to_vtkIdTypeArray(np.arange(0, 3 * len(faces) + 1, 3, dtype=np.int64), deep=True),
        numpy_support.numpy_to_vtkIdTypeArray(faces.ravel().copy(), deep=True),
    )
    poly.SetPolys(cells)

    def prepare():
        f = vtk.vtkWindowedSincPolyDataFilter()
        f.SetInputData(poly)
        f.SetNumberOfIterations(its)
        f.SetPassBand(0.1)
        f.NormalizeCoordinatesOn()
        f.FeatureEdgeSmoothingOff()
        f.BoundarySmoothingOn()
        return f

    yield "sinc", "VTK vtkWindowedSincPolyDataFilter", best_of(repeats, prepare, lambda f: f.Update())


def pymeshlab_peers(points, faces, its, repeats):
    import pymeshlab

    def prepare():
        ms = pymeshlab.MeshSet()
        ms.add_mesh(pymeshlab.Mesh(points, faces))
        return ms

    yield "laplace", "pymeshlab coord_laplacian (uniform)", best_of(
        repeats, prepare, lambda ms: ms.apply_coord_laplacian_smoothing(stepsmoothnum=its, cotangentweight=False)
    )
    yield "taubin", "pymeshlab coord_taubin", best_of(
        repeats, prepare, lambda ms: ms.apply_coord_taubin_smoothing(lambda_=0.5, mu=-0.53, stepsmoothnum=its)
    )

    def hc(ms):
        for _ in range(its):
            ms.apply_coord_hc_laplacian_smoothing()

    yield "hc", "pymeshlab coord_hc_laplacian (MeshLab HC)", best_of(repeats, prepare, hc)


def open3d_peers(points, faces, its, repeats):
    import open3d as o3d

    base = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(points), o3d.utility.Vector3iVector(faces.astype(np.int32)))
    copy = lambda: o3d.geometry.TriangleMesh(base)  # noqa: E731
    yield "laplace", "open3d filter_smooth_laplacian", best_of(
        repeats, copy, lambda m: m.filter_smooth_laplacian(number_of_iterations=its, lambda_filter=0.5)
    )
    yield "taubin", "open3d filter_smooth_taubin", best_of(
        repeats, copy, lambda m: m.filter_smooth_taubin(number_of_iterations=its, lambda_filter=0.5, mu=-0.53)
    )


def ours(command, mesh, filt, its, repeats):
    cmd = [a.format(file=mesh, filter=filt, iterations=its) for a in shlex.split(command)]
    best = None
    for _ in range(repeats):
        out = subprocess.run(cmd, capture_output=True, text=True, check=True, cwd=ROOT).stdout
        result = json.loads(out)
        if best is None or result["seconds"] < best["seconds"]:
            best = result
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--mesh", default=str(DEFAULT_MESH))
    ap.add_argument("--iterations", type=int, default=20)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument(
        "--ours-cmd",
        default=str(ROOT / "target" / "release" / "meshsmooth") + " bench {file} --filter {filter} --iterations {iterations} --json",
    )
    args = ap.parse_args()
    points, faces = load_ply(args.mesh)
    n, its = len(points), args.iterations
    print(f"mesh {pathlib.Path(args.mesh).name}: {n} vertices, {len(faces)} triangles; {its} iterations; "
          f"{os.cpu_count()} CPUs; best of {args.repeats}", file=sys.stderr)

    rows = {f: [] for f in FILTERS}
    for peers in (trimesh_peers, vtk_peers, pymeshlab_peers, open3d_peers):
        try:
            for filt, name, seconds in peers(points, faces, its, args.repeats):
                rows[filt].append((name, seconds))
        except ImportError as e:
            print(f"skipped {peers.__name__}: {e}", file=sys.stderr)

    print(f"{'filter':<8} {'implementation':<44} {'seconds':>9} {'M vert-it/s':>12} {'vs fastest peer':>16}")
    for filt in FILTERS:
        peers = sorted(rows[filt], key=lambda r: r[1])
        fastest = peers[0][1] if peers else None
        for name, seconds in peers:
            print(f"{filt:<8} {name:<44} {seconds:>9.4f} {n * its / seconds / 1e6:>12.1f} {fastest / seconds:>15.2f}x")
        try:
            r = ours(args.ours_cmd, args.mesh, filt, its, args.repeats)
        except (OSError, subprocess.CalledProcessError, json.JSONDecodeError, IndexError) as e:
            print(f"{filt:<8} {'meshsmooth (unavailable: ' + type(e).__name__ + ')':<44}")
            continue
        label = f"meshsmooth ({r.get('backend', '?')})"
        ratio = f"{fastest / r['seconds']:>15.2f}x" if fastest else ""
        print(f"{filt:<8} {label:<44} {r['seconds']:>9.4f} {r['vertex_iterations_per_second'] / 1e6:>12.1f} {ratio}")


if __name__ == "__main__":
    main()
