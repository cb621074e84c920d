"""Load speed of meshsmooth against MeshLab (pymeshlab) on the large staircase benchmark mesh.

Needs a Python environment with pymeshlab and numpy (the project's peer-library venv), and a
release build of the command-line tool:

    cargo build --release
    <venv>/bin/python tests/bench/load_vs_meshlab.py [--repeat N]

The tool is found at target/release/meshsmooth under the repository root (override with the
MESHSMOOTH_BIN environment variable) and the test meshes at ../shared/data beside the repository.

The PLY is the 206,512-vertex `seg_mni152_gm_plus_wm_p0.5_1mm.ply`; a binary STL of the same
triangles is written to a temporary directory. Both are loaded by pymeshlab (best of N, STL with
its default vertex unification) and by `meshsmooth bench-load --json` (parse, which for STL
includes welding, plus topology; best of N). The issue's floors: our STL load + weld + topology
at least 3x faster than MeshLab's STL load, our PLY load + topology at least as fast as MeshLab's
PLY load. Exits with status 1 when a floor is missed.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pymeshlab

REPO = Path(__file__).resolve().parents[2]
DATA = REPO.parent / "shared" / "data"
MESH = DATA / "segmentations" / "seg_mni152_gm_plus_wm_p0.5_1mm.ply"
FLOORS = {"STL": 3.0, "PLY": 1.0}


def meshlab_load(path: Path, repeat: int) -> tuple[float, int]:
    """Best wall-clock seconds of pymeshlab loading `path`, and the vertex count it got."""
    best, vertices = float("inf"), 0
    for _ in range(repeat):
        ms = pymeshlab.MeshSet()
        start = time.perf_counter()
        ms.load_new_mesh(str(path))
        best = min(best, time.perf_counter() - start)
        vertices = ms.current_mesh().vertex_number()
    return best, vertices


def ours(binary: Path, path: Path, repeat: int) -> dict:
    """`meshsmooth bench-load --json` on `path`."""
    out = subprocess.run(
        [str(binary), "bench-load", str(path), "--repeat", str(repeat), "--json"],
        check=True,
        capture_output=True,
        text=True,
    )
    return json.loads(out.stdout)


def write_binary_stl(ply: Path, stl: Path) -> None:
    """The PLY's triangles as binary STL, coordinates unchanged (float32), normals computed."""
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(ply))
    mesh = ms.current_mesh()
    corners = mesh.vertex_matrix().astype(np.float32)[mesh.face_matrix()]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    lengths = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, lengths, out=np.zeros_like(normals), where=lengths > 0)
    records = np.zeros(len(corners), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    records["n"] = normals
    records["v"] = corners
    with open(stl, "wb") as f:
        f.write(b"meshsmooth load benchmark".ljust(80, b" "))
        f.write(np.uint32(len(records)).tobytes())
        f.write(records.tobytes())


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="runs per measurement (best is kept)")
    args = parser.parse_args()

    binary = Path(os.environ.get("MESHSMOOTH_BIN", REPO / "target" / "release" / "meshsmooth"))
    if not binary.is_file():
        print(f"no binary at {binary}: run `cargo build --release` first", file=sys.stderr)
        return 2
    if not MESH.is_file():
        print(f"no benchmark mesh at {MESH}", file=sys.stderr)
        return 2

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        stl = Path(tmp) / (MESH.stem + ".stl")
        write_binary_stl(MESH, stl)
        for label, path in [("PLY", MESH), ("STL", stl)]:
            meshlab_s, meshlab_v = meshlab_load(path, args.repeat)
            r = ours(binary, path, args.repeat)
            rows.append((label, meshlab_s, meshlab_v, r))

    print(f"{MESH.name}, best of {args.repeat}")
    print(
        f"{'format':6} {'MeshLab load':>13} {'our parse':>10} {'our topology':>13} "
        f"{'our total':>10} {'speed-up':>9} {'floor':>6}  vertices (MeshLab / ours)"
    )
    missed = []
    for label, meshlab_s, meshlab_v, r in rows:
        ratio = meshlab_s / r["total_seconds"]
        floor = FLOORS[label]
        ok = ratio >= floor
        if not ok:
            missed.append(label)
        print(
            f"{label:6} {meshlab_s * 1e3:10.1f} ms {r['parse_seconds'] * 1e3:7.1f} ms "
            f"{r['topology_seconds'] * 1e3:10.1f} ms {r['total_seconds'] * 1e3:7.1f} ms "
            f"{ratio:8.1f}x {floor:4.0f}x{'' if ok else ' MISSED'}  {meshlab_v} / {r['vertices']}"
        )
    if missed:
        print(f"floor missed for: {', '.join(missed)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
