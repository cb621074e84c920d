"""The whole-body CT case natively: `meshsmooth case build` on the synthetic whole-body label map.

Printed, not asserted. Needs Python 3 and the release builds (`cargo build --release --example
whole_body` and `cargo build --release`):

    python3 tests/bench/whole_body_case.py [--threads 1,2] [--simplify 0.1] [--keep DIR]

The tool is target/release/meshsmooth under the repository root (override with MESHSMOOTH_BIN), the
generator target/release/examples/whole_body (MESHSMOOTH_WHOLE_BODY). The label map is made afresh
in a temporary folder (or --keep DIR, kept there): 512 x 512 x 400 voxels, 114 structures.

For each thread count (RAYON_NUM_THREADS), one run of the default `case build` (learned search,
compressed case glTF with the original as morph target), and with the most threads one more with
`--simplify`: the JSON's `open_seconds` (reading and extraction), `suggest_seconds` (every
structure's suggestion, smoothing and measures), `checks_seconds` (the checks between structures
before and after), `export_seconds` (writing the case glTF, simplification included), `seconds`
(the whole command), the file's size, its triangles and the command's peak resident memory (the
kernel's count for that process). The page's "Suggest all" is not measured here.
"""

import argparse
import json
import os
import struct
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BIN = os.environ.get("MESHSMOOTH_BIN", os.path.join(ROOT, "target", "release", "meshsmooth"))
GEN = os.environ.get(
    "MESHSMOOTH_WHOLE_BODY", os.path.join(ROOT, "target", "release", "examples", "whole_body"))


def run_with_peak(cmd, env):
    """The command's stdout and its peak resident memory in MB (its own rusage, from wait4)."""
    child = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    chunks = []
    while True:
        block = child.stdout.read(1 << 16)
        if not block:
            break
        chunks.append(block)
    _, status, usage = os.wait4(child.pid, 0)
    if status != 0:
        sys.exit(f"{' '.join(cmd)} failed with status {status}")
    return b"".join(chunks).decode(), usage.ru_maxrss / 1024.0


def triangles(glb):
    """Triangles in a case GLB, from its accessors' counts."""
    with open(glb, "rb") as f:
        data = f.read()
    length = struct.unpack("<I", data[12:16])[0]
    doc = json.loads(data[20:20 + length])
    return sum(doc["accessors"][p["indices"]]["count"] // 3
               for m in doc["meshes"] for p in m["primitives"])


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--threads", default="1,2")
    p.add_argument("--simplify", default="0.1")
    p.add_argument("--keep")
    a = p.parse_args()
    with tempfile.TemporaryDirectory() as work:
        folder = a.keep or work
        os.makedirs(folder, exist_ok=True)
        label_map = os.path.join(folder, "whole_body.nii.gz")
        if not os.path.exists(label_map):
            subprocess.run([GEN, folder], check=True, stdout=subprocess.DEVNULL)
        table = os.path.join(folder, "whole_body_labels.txt")
        threads = [int(t) for t in a.threads.split(",")]
        runs = [(t, []) for t in threads] + [(max(threads), ["--simplify", a.simplify])]
        print(f"{'threads':>7} {'options':<16} {'open s':>7} {'suggest s':>9} {'checks s':>8} "
              f"{'export s':>8} {'total s':>7} {'sets':>6} {'file MB':>8} {'triangles':>10} {'peak MB':>8}")
        for t, more in runs:
            out = os.path.join(folder, f"case_{t}{'_simplified' if more else ''}.glb")
            cmd = [BIN, "case", "build", label_map, "--colors", table, "-o", out, "--json"] + more
            text, peak = run_with_peak(cmd, dict(os.environ, RAYON_NUM_THREADS=str(t)))
            r = json.loads(text)
            print(f"{t:>7} {' '.join(more) or 'default':<16} {r['open_seconds']:>7.2f} "
                  f"{r['suggest_seconds']:>9.2f} {r['checks_seconds']:>8.2f} "
                  f"{r['export_seconds']:>8.2f} {r['seconds']:>7.2f} "
                  f"{r['evaluations']:>6} {r['bytes'] / 1e6:>8.2f} {triangles(out):>10} {peak:>8.0f}")


if __name__ == "__main__":
    main()
