"""Speed of `meshsmooth extract` (label map -> one closed surface per label) against VTK's label-map filters.

Printed, not asserted. Run with the peers' venv (nibabel, numpy, scipy, vtk >= 9.3; it lives outside the
repository, /work/peers/venv here), after `cargo build --release`:

    <venv>/bin/python tests/bench/extract_vs_vtk.py [--repeats 3] [--maps jhu,brain116,ct]
        [--backends Sequential,STDThread] [--work /tmp/meshsmooth-extract-bench] [--regenerate]

The tool is target/release/meshsmooth under the repository root (override with MESHSMOOTH_BIN); the data
is ../shared/data beside the repository (override with MESHSMOOTH_DATA).

Three label maps, side by side:
  jhu      labelmaps/JHU-WhiteMatter-labels-1mm.nii.gz as shipped: 182 x 218 x 182, 1 mm, 48 labels.
  brain116 a 116-parcel whole-brain atlas on the same grid and affine: the MNI152 grey+white mask
           (segmentations/seg_mni152_gm_plus_wm_p0.5_1mm_mask.nii.gz, a 1 mm grid offset by whole voxels
           from JHU's) cropped to the JHU grid, split by nearest of 116 seeded points (seed 116, five
           Lloyd steps so the parcels are of similar size). uint8.
  ct       CT-sized, 512 x 512 x 400: the abdominal phantom (labelmaps/case_phantom_shared.nii.gz,
           160 x 140 x 48) upsampled by nearest neighbour to that grid (the affine keeps the phantom's
           world extent and flips: 0.244 x 0.213 x 0.3 mm voxels), the liver split into two lobes and
           seven more organs drawn at full resolution into background voxels: 12 labels. uint8. The
           aorta and the vena cava run through the top and bottom slices, as in an abdominal scan.
The generated maps are written once (deterministic) as .nii.gz and .nii into --work (outside the
repository); --regenerate rewrites them.

What is timed, best of --repeats each:
  meshsmooth  `meshsmooth extract MAP -o WORK/out.glb --json`: wall time of the whole process (read,
              inflate, extract, normals, GLB write) and its JSON `seconds` (decode + extraction, no
              writing); peak RSS of the process (GNU /usr/bin/time). Also run on the uncompressed
              .nii, which shows what inflating the .nii.gz costs.
  VTK         each filter in a fresh worker process (this script, --vtk-worker), the SMP backend set
              first: the nibabel load (nib.load + the voxel array, inflating the .gz) timed apart, the
              numpy -> vtkImageData wrap (no copy) untimed, then only Update() of a new filter timed:
                vtkSurfaceNets3D, smoothing off, every label;
                vtkSurfaceNets3D, default smoothing (16 iterations of constrained smoothing);
                vtkDiscreteFlyingEdges3D, SetValue per label, normals and gradients off (its default
                computes normals; ours computes them only when writing, outside `seconds`).
              Peak RSS is the worker's over the filter runs (its high-water mark reset after loading): it
              includes the interpreter, VTK's libraries and the loaded volume (shown on the load row).
Triangles are printed as a sanity check (quads count as two). They differ by design: surface nets give
one shared surface (a wall between two labels once), discrete flying edges and meshsmooth one closed
surface per label (such a wall twice). Discrete flying edges leaves a surface open where it meets the
grid's edge (the CT map's vessels), meshsmooth closes it.

VTK runs under each of --backends: Sequential (the pip wheel's default: one thread) and STDThread (as
many threads as cores). On a loaded machine two threads need not beat one; the load average is printed.

Ratios are ours / VTK: `extract` = our JSON seconds over the filter's Update(); `end-to-end` = our whole
process over VTK's load + Update(). Below 1 means meshsmooth is faster.
"""
import argparse
import json
import os
import pathlib
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = pathlib.Path(os.environ.get("MESHSMOOTH_DATA", ROOT.parent / "shared" / "data"))
BIN = pathlib.Path(os.environ.get("MESHSMOOTH_BIN", ROOT / "target" / "release" / "meshsmooth"))
VENV = pathlib.Path(os.environ.get("PEERS_VENV", ROOT.parent / "peers" / "venv"))
JHU = DATA / "labelmaps" / "JHU-WhiteMatter-labels-1mm.nii.gz"
BRAIN_MASK = DATA / "segmentations" / "seg_mni152_gm_plus_wm_p0.5_1mm_mask.nii.gz"
PHANTOM = DATA / "labelmaps" / "case_phantom_shared.nii.gz"
MAPS = ["jhu", "brain116", "ct"]
VARIANTS = {
    "sn": "vtkSurfaceNets3D (no smoothing)",
    "sn_smooth": "vtkSurfaceNets3D (default smoothing)",
    "dfe": "vtkDiscreteFlyingEdges3D",
}
GENERATOR_VERSION = "v1"  # bump when a generated map changes

try:
    import numpy as np
    import nibabel as nib
except ImportError as e:
    sys.exit(f"extract_vs_vtk.py needs numpy, nibabel, scipy and vtk ({e}); run it with the peers' venv: "
             f"{VENV / 'bin' / 'python'} {pathlib.Path(__file__).relative_to(ROOT)}")


# ---------------------------------------------------------------------------------------------------
# The label maps


def brain116(path):
    """116 parcels of the MNI152 grey+white mask, cropped to the JHU grid, nearest of 116 seeds."""
    from scipy.spatial import cKDTree

    jhu = nib.load(JHU)
    mask_img = nib.load(BRAIN_MASK)
    # Both are 1 mm axis-aligned grids; the mask's voxel (i, j, k) + offset is JHU's voxel (i, j, k).
    to_mask = np.linalg.inv(mask_img.affine) @ jhu.affine
    offset = np.rint(to_mask[:3, 3]).astype(int)
    if not np.allclose(to_mask[:3, :3], np.eye(3)) or not np.allclose(to_mask[:3, 3], offset):
        sys.exit(f"{BRAIN_MASK.name} is not on a whole-voxel shift of the JHU grid")
    shape = jhu.shape
    mask = np.zeros(shape, bool)
    src = np.asanyarray(mask_img.dataobj) > 0
    lo = np.maximum(offset, 0)
    hi = np.minimum(offset + np.array(shape), src.shape)
    dst = lo - offset
    mask[dst[0]:dst[0] + hi[0] - lo[0], dst[1]:dst[1] + hi[1] - lo[1], dst[2]:dst[2] + hi[2] - lo[2]] = \
        src[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]
    points = np.argwhere(mask).astype(np.float64)
    rng = np.random.default_rng(116)
    seeds = points[rng.choice(len(points), 116, replace=False)]
    for _ in range(5):  # Lloyd steps: parcels of similar size, like an atlas's
        _, nearest = cKDTree(seeds).query(points)
        counts = np.bincount(nearest, minlength=116)
        sums = np.stack([np.bincount(nearest, weights=points[:, a], minlength=116) for a in range(3)], 1)
        seeds = np.where(counts[:, None] > 0, sums / np.maximum(counts, 1)[:, None], seeds)
    _, nearest = cKDTree(seeds).query(points)
    labels = np.zeros(shape, np.uint8)
    labels[tuple(points.astype(int).T)] = nearest + 1
    img = nib.Nifti1Image(labels, jhu.affine)
    img.set_qform(jhu.affine, code=2)
    img.set_sform(jhu.affine, code=2)
    return img


def _ellipsoid(c, r):
    c, r = np.asarray(c, float), np.asarray(r, float)
    return c - r, c + r, lambda p: (((p - c) / r) ** 2).sum(-1) <= 1


def _capsule(a, b, radius):
    a, b = np.asarray(a, float), np.asarray(b, float)
    ab = b - a

    def inside(p):
        t = np.clip(((p - a) @ ab) / (ab @ ab), 0, 1)
        return (((p - a) - t[..., None] * ab) ** 2).sum(-1) <= radius * radius

    return np.minimum(a, b) - radius, np.maximum(a, b) + radius, inside


# Extra organs of the CT-sized map, in the phantom's frame (mm, phantom = (i, j, k) * spacing; the
# phantom spans 124.8 x 109.2 x 120 mm). Drawn in this order into background voxels only.
CT_EXTRA = [
    (6, "left_kidney", _ellipsoid((24, 90, 45), (9, 14, 20))),
    (7, "spleen", _ellipsoid((22, 70, 100), (12, 18, 12))),
    (8, "aorta", _capsule((45, 100, 6), (45, 100, 114), 5.0)),
    (9, "inferior_vena_cava", _capsule((82, 96, 6), (82, 96, 114), 6.0)),
    (10, "gallbladder", _ellipsoid((85, 45, 30), (7, 7, 10))),
    (11, "stomach", _ellipsoid((55, 45, 100), (22, 16, 14))),
    (12, "pancreas", _capsule((40, 75, 25), (85, 70, 22), 5.0)),
]
CT_SHAPE = (512, 512, 400)
LEFT_LOBE_X_MM = 38.0  # liver voxels left of this plane (phantom x) become label 5


def ct(path):
    """The phantom upsampled by nearest neighbour to 512 x 512 x 400, plus organs: 12 labels."""
    src = nib.load(PHANTOM)
    a = np.asanyarray(src.dataobj)
    spacing = np.abs(np.diag(src.affine)[:3])
    scale = np.array(a.shape) / np.array(CT_SHAPE)  # source voxels per output voxel
    # Output voxel i's centre sits at source index (i + 0.5) * scale - 0.5: same world extent.
    idx = [np.minimum(np.floor((np.arange(n) + 0.5) * s).astype(int), m - 1)
           for n, s, m in zip(CT_SHAPE, scale, a.shape)]
    out = a[np.ix_(*idx)]
    out = np.asfortranarray(out)
    del a

    def phantom_mm(axis, lo, hi):
        """Output indices along `axis` whose centres lie in [lo, hi] phantom mm, and those centres."""
        centres = ((np.arange(CT_SHAPE[axis]) + 0.5) * scale[axis] - 0.5) * spacing[axis]
        keep = np.nonzero((centres >= lo) & (centres <= hi))[0]
        return keep, centres[keep]

    # Split the liver: its left lobe (phantom x < LEFT_LOBE_X_MM) becomes label 5.
    xs, _ = phantom_mm(0, -np.inf, LEFT_LOBE_X_MM)
    block = out[xs[0]:xs[-1] + 1]
    block[block == 1] = 5
    for label, _name, (lo, hi, inside) in CT_EXTRA:
        (i, ci), (j, cj), (k, ck) = (phantom_mm(ax, lo[ax], hi[ax]) for ax in range(3))
        p = np.stack(np.meshgrid(ci, cj, ck, indexing="ij"), -1)
        sub = out[i[0]:i[-1] + 1, j[0]:j[-1] + 1, k[0]:k[-1] + 1]
        sub[inside(p) & (sub == 0)] = label
    step = np.diag(np.append(scale, 1.0))
    step[:3, 3] = 0.5 * scale - 0.5
    affine = src.affine @ step
    img = nib.Nifti1Image(out, affine)
    img.set_qform(affine, code=1)
    img.set_sform(affine, code=1)
    return img


def prepare_maps(names, work, regenerate):
    """{name: (path .nii.gz, path .nii or None)} for the maps asked for, generated where needed."""
    work.mkdir(parents=True, exist_ok=True)
    maps = {}
    for name in names:
        if name == "jhu":
            plain = work / "jhu.nii"
            if regenerate or not plain.exists():
                img = nib.load(JHU)
                nib.save(nib.Nifti1Image(np.asanyarray(img.dataobj), img.affine, img.header), plain)
            maps[name] = (JHU, plain)
            continue
        gz = work / f"{name}_{GENERATOR_VERSION}.nii.gz"
        plain = work / f"{name}_{GENERATOR_VERSION}.nii"
        if regenerate or not gz.exists() or not plain.exists():
            t = time.perf_counter()
            img = {"brain116": brain116, "ct": ct}[name](gz)
            nib.save(img, gz)
            nib.save(img, plain)
            print(f"generated {gz} in {time.perf_counter() - t:.1f} s", file=sys.stderr)
        maps[name] = (gz, plain)
    return maps


def label_values(a):
    """The non-zero labels of a label array, without a full-size temporary (bincount widens to int64)."""
    if a.dtype in (np.uint8, np.uint16):
        counts = sum(np.bincount(a[..., k].ravel(order="K"), minlength=1 << (8 * a.itemsize)) for k in range(a.shape[2]))
        return [int(v) for v in np.nonzero(counts)[0] if v != 0]
    return [int(v) for v in np.unique(a) if v != 0]


def describe(path):
    img = nib.load(path)
    return img.shape, len(label_values(np.asanyarray(img.dataobj))), img.header.get_zooms()[:3]


# ---------------------------------------------------------------------------------------------------
# Running and measuring a process


TIME = pathlib.Path("/usr/bin/time")


def measured(cmd, cwd=None):
    """(wall seconds, peak RSS MB, stdout) of one run of `cmd`; stderr shown when it fails.

    Peak RSS comes from GNU time (`apt-get install time`), which forks the command from a small
    process: os.wait4 on a child of this interpreter reports the interpreter's own size whenever
    that is larger (Linux keeps the high-water mark across fork and exec). Without /usr/bin/time
    the RSS column is left empty.
    """
    with tempfile.TemporaryDirectory() as tmp:
        rss_file = pathlib.Path(tmp) / "rss"
        wrapped = [str(TIME), "-f", "%M", "-o", str(rss_file), *map(str, cmd)] if TIME.is_file() else list(map(str, cmd))
        t = time.perf_counter()
        p = subprocess.run(wrapped, capture_output=True, cwd=cwd)
        wall = time.perf_counter() - t
        if p.returncode != 0:
            raise RuntimeError(f"{' '.join(map(str, cmd))} exited {p.returncode}:\n{p.stderr.decode(errors='replace')}")
        rss = int(rss_file.read_text().split()[-1]) / 1024 if TIME.is_file() else None
        return wall, rss, p.stdout.decode()


def ours(path, out, repeats):
    best = None
    rss = 0.0
    for _ in range(repeats):
        wall, peak, stdout = measured([str(BIN), "extract", str(path), "-o", str(out), "--json"], cwd=ROOT)
        result = json.loads(stdout)
        rss = max(rss, peak) if peak is not None else None
        triangles = sum(s["triangles"] for s in result["structures"])
        if best is None or wall < best["wall"]:
            best = dict(wall=wall, triangles=triangles, structures=len(result["structures"]))
        best["seconds"] = min(best.get("seconds", float("inf")), result["seconds"])
    best["rss"] = rss
    return best


def vtk_worker(path, variant, backend, repeats):
    """In a fresh process: the nibabel load, then Update() of one filter; prints JSON."""
    from vtkmodules.util import numpy_support
    from vtkmodules.vtkCommonCore import vtkSMPTools
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkFiltersCore import vtkSurfaceNets3D
    from vtkmodules.vtkFiltersGeneral import vtkDiscreteFlyingEdges3D

    smp = vtkSMPTools()
    smp.SetBackend(backend)
    used_backend, threads = smp.GetBackend(), smp.GetEstimatedNumberOfThreads()

    load = float("inf")
    for _ in range(repeats):
        t = time.perf_counter()
        img = nib.load(path)
        arr = np.asanyarray(img.dataobj)
        load = min(load, time.perf_counter() - t)
    labels = label_values(arr)
    flat = arr.ravel(order="F")  # VTK's x-fastest layout: a view of nibabel's Fortran-ordered array
    image = vtkImageData()
    image.SetDimensions(*arr.shape)
    image.SetSpacing(*(float(z) for z in img.header.get_zooms()[:3]))
    scalars = numpy_support.numpy_to_vtk(flat, deep=False)
    scalars.SetName("labels")
    image.GetPointData().SetScalars(scalars)
    del img
    rss_loaded = _status_mb("VmRSS")
    # Peak RSS of the filters alone (on top of what is resident now): reset the high-water mark,
    # which the repeated loads pushed up (Linux >= 4.0; else the peak includes the loads).
    try:
        pathlib.Path("/proc/self/clear_refs").write_text("5")
    except OSError:
        pass

    def make():
        if variant in ("sn", "sn_smooth"):
            f = vtkSurfaceNets3D()
            f.SetNumberOfLabels(len(labels))
            for i, v in enumerate(labels):
                f.SetLabel(i, v)
            if variant == "sn":
                f.SmoothingOff()
        else:
            f = vtkDiscreteFlyingEdges3D()
            f.SetNumberOfContours(len(labels))
            for i, v in enumerate(labels):
                f.SetValue(i, v)
            f.ComputeNormalsOff()
            f.ComputeGradientsOff()
        f.SetInputData(image)
        return f

    best = float("inf")
    for _ in range(repeats):
        f = make()
        t = time.perf_counter()
        f.Update()
        best = min(best, time.perf_counter() - t)
        polys = f.GetOutput().GetPolys()
        triangles = polys.GetNumberOfConnectivityIds() - 2 * polys.GetNumberOfCells()
        points = f.GetOutput().GetNumberOfPoints()
        del f, polys
    print(json.dumps(dict(load=load, seconds=best, triangles=int(triangles), points=int(points),
                          labels=len(labels), backend=used_backend, threads=threads, rss_loaded=rss_loaded,
                          rss_filter=_status_mb("VmHWM"))))


def _status_mb(field):
    """A memory figure of this process from /proc/self/status, in MB (None where unavailable)."""
    try:
        for line in pathlib.Path("/proc/self/status").read_text().splitlines():
            if line.startswith(field + ":"):
                return int(line.split()[1]) / 1024
    except OSError:
        pass
    return None


def vtk_run(path, variant, backend, repeats):
    cmd = [sys.executable, __file__, "--vtk-worker", str(path), variant, backend, "--repeats", str(repeats)]
    _, rss, stdout = measured(cmd)
    result = json.loads(stdout.strip().splitlines()[-1])
    result["rss"] = result["rss_filter"] if result["rss_filter"] is not None else rss
    return result


# ---------------------------------------------------------------------------------------------------


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--maps", default=",".join(MAPS), help="comma-separated, of " + ", ".join(MAPS))
    ap.add_argument("--backends", default="Sequential,STDThread",
                    help="vtkSMPTools backends to time VTK under (Sequential is the wheel's default)")
    ap.add_argument("--work", type=pathlib.Path, default=pathlib.Path(tempfile.gettempdir()) / "meshsmooth-extract-bench")
    ap.add_argument("--regenerate", action="store_true", help="rewrite the generated label maps")
    ap.add_argument("--vtk-worker", nargs=3, metavar=("MAP", "VARIANT", "BACKEND"), help=argparse.SUPPRESS)
    args = ap.parse_args()

    if args.vtk_worker:
        path, variant, backend = args.vtk_worker
        vtk_worker(path, variant, backend, args.repeats)
        return

    try:
        import scipy  # noqa: F401
        import vtkmodules.vtkCommonCore as vcc
        from vtkmodules.vtkFiltersCore import vtkSurfaceNets3D  # noqa: F401
    except ImportError as e:
        sys.exit(f"needs scipy and vtk >= 9.3 ({e}); run with {VENV / 'bin' / 'python'}")
    if not BIN.is_file():
        sys.exit(f"{BIN} not found: run `cargo build --release` first (or set MESHSMOOTH_BIN)")
    for f in (JHU, BRAIN_MASK, PHANTOM):
        if not f.is_file():
            sys.exit(f"{f} not found (set MESHSMOOTH_DATA to the shared data folder)")
    names = [m for m in args.maps.split(",") if m]
    if unknown := set(names) - set(MAPS):
        sys.exit(f"unknown map(s) {', '.join(sorted(unknown))}; known: {', '.join(MAPS)}")
    backends = [b for b in args.backends.split(",") if b]

    smp = vcc.vtkSMPTools()
    default_backend, default_threads = smp.GetBackend(), smp.GetEstimatedNumberOfThreads()
    print(f"VTK {vcc.vtkVersion.GetVTKVersion()}: vtkSMPTools default backend {default_backend} "
          f"({default_threads} thread(s)); this machine: {os.cpu_count()} CPU(s), "
          f"{len(os.sched_getaffinity(0))} usable, load average {os.getloadavg()[0]:.1f} at start; "
          f"best of {args.repeats}")

    if not TIME.is_file():
        print(f"note: {TIME} missing (apt-get install time): no peak RSS figures", file=sys.stderr)
    maps = prepare_maps(names, args.work, args.regenerate)
    rows = []
    for name in names:
        gz, plain = maps[name]
        shape, nlabels, zooms = describe(gz)
        voxels = int(np.prod(shape))
        print(f"{name}: {gz} {'x'.join(map(str, shape))} voxels of {'x'.join(f'{z:.3g}' for z in zooms)} mm, "
              f"{nlabels} labels", file=sys.stderr)
        glb = args.work / f"out_{name}.glb"
        r = ours(gz, glb, args.repeats)
        rows.append((name, nlabels, voxels, "meshsmooth extract (.nii.gz) wall", r["wall"], r["triangles"], r["rss"], None))
        rows.append((name, nlabels, voxels, "meshsmooth extract (.nii.gz) json seconds", r["seconds"], r["triangles"], None, None))
        ours_wall, ours_seconds = r["wall"], r["seconds"]
        if r["structures"] != nlabels:
            print(f"note: {name}: meshsmooth gave {r['structures']} structures for {nlabels} labels", file=sys.stderr)
        if plain is not None:
            p = ours(plain, glb, args.repeats)
            rows.append((name, nlabels, voxels, "meshsmooth extract (.nii) wall", p["wall"], p["triangles"], p["rss"], None))
            rows.append((name, nlabels, voxels, "meshsmooth extract (.nii) json seconds", p["seconds"], p["triangles"], None, None))
        load_row = None
        for backend in backends:
            for variant, label in VARIANTS.items():
                try:
                    v = vtk_run(gz, variant, backend, args.repeats)
                except (RuntimeError, json.JSONDecodeError, IndexError) as e:
                    print(f"{name}: {label} under {backend} failed: {e}", file=sys.stderr)
                    continue
                if load_row is None:
                    load_row = (name, nlabels, voxels, "nibabel load (.nii.gz -> numpy)", v["load"], None,
                                v["rss_loaded"], None)
                    rows.append(load_row)
                tool = f"{label} [{v['backend']} x{v['threads']}]"
                ratios = (ours_seconds / v["seconds"], ours_wall / (v["load"] + v["seconds"]))
                rows.append((name, nlabels, voxels, tool, v["seconds"], v["triangles"], v["rss"], ratios))

    print()
    print(f"{'map':<9} {'labels':>6} {'voxels':>11}  {'tool':<58} {'seconds':>8} {'triangles':>10} "
          f"{'peak RSS MB':>11}  {'ours/VTK extract':>16} {'end-to-end':>10}")
    last = None
    for name, nlabels, voxels, tool, seconds, triangles, rss, ratios in rows:
        if last is not None and name != last:
            print()
        last = name
        tri = f"{triangles:>10,}" if triangles is not None else f"{'':>10}"
        mb = f"{rss:>11.0f}" if rss is not None else f"{'':>11}"
        rat = f"{ratios[0]:>15.2f}x {ratios[1]:>9.2f}x" if ratios else ""
        print(f"{name:<9} {nlabels:>6} {voxels:>11,}  {tool:<58} {seconds:>8.3f} {tri} {mb}  {rat}")
    print()
    print("ours/VTK extract = meshsmooth JSON seconds (decode + extraction) / filter Update(); end-to-end = "
          "meshsmooth wall (read .nii.gz .. GLB written) / (nibabel load + Update()). Below 1: meshsmooth faster.")
    print("VTK peak RSS: the worker's high-water mark over the filter runs (Python + VTK + the volume as loaded "
          "+ the filter's own), reset after loading; the nibabel load row: the worker's RSS once loaded.")


if __name__ == "__main__":
    main()
