"""Speed of "Suggest all" natively: `meshsmooth case build` on a whole atlas, with 1 and 2 threads.

Printed, not asserted. Needs only Python 3 and the release build (`cargo build --release`):

    python3 tests/bench/suggest_all.py [--repeats 2] [--maps jhu,phantom] [--searches grid,local]
        [--threads 1,2]

The tool is release/meshsmooth under CARGO_TARGET_DIR or the repository's target/ (override with MESHSMOOTH_BIN); the data
is ../shared/data beside the repository (override with MESHSMOOTH_DATA).

For each label map, search and thread count (RAYON_NUM_THREADS), best of --repeats: the JSON's
`suggest_seconds` (every structure's suggestion and its smoothing and measures, the part the page's
"Suggest all" does), `seconds` (the whole command: reading, extraction, checks, writing the GLB) and the
parameter sets measured. The last column is the speed-up of the most threads over one.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TARGET = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
BIN = os.environ.get("MESHSMOOTH_BIN", os.path.join(TARGET, "release", "meshsmooth"))
DATA = os.environ.get("MESHSMOOTH_DATA", os.path.join(ROOT, "..", "shared", "data"))

MAPS = {
    "jhu": ("labelmaps/JHU-WhiteMatter-labels-1mm.nii.gz", "labelmaps/JHU-WhiteMatter-labels-1mm.nii.txt"),
    "phantom": ("labelmaps/case_phantom_shared.nii.gz", "labelmaps/case_phantom_shared_labels.txt"),
}


def run(label_map, table, search, threads, out):
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    cmd = [BIN, "case", "build", label_map, "--colors", table, "--search", search, "-o", out, "--json"]
    done = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed: {done.stderr}")
    return json.loads(done.stdout)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=2)
    p.add_argument("--maps", default="jhu,phantom")
    p.add_argument("--searches", default="grid,local")
    p.add_argument("--threads", default="1,2")
    a = p.parse_args()
    threads = [int(t) for t in a.threads.split(",")]
    print(f"{'map':<8} {'search':<6} {'structures':>10} {'vertices':>9} {'sets':>7} "
          + " ".join(f"{f'suggest {t}t s':>12} {f'total {t}t s':>11}" for t in threads)
          + f" {'speed-up':>8}")
    with tempfile.TemporaryDirectory() as work:
        out = os.path.join(work, "case.glb")
        for key in a.maps.split(","):
            label_map, table = (os.path.join(DATA, rel) for rel in MAPS[key])
            for search in a.searches.split(","):
                cells, suggest = [], {}
                for t in threads:
                    runs = [run(label_map, table, search, t, out) for _ in range(a.repeats)]
                    best = min(runs, key=lambda r: r["suggest_seconds"])
                    suggest[t] = best["suggest_seconds"]
                    total = min(r["seconds"] for r in runs)
                    cells.append(f"{suggest[t]:>12.2f} {total:>11.2f}")
                vertices = sum(s["vertices"] for s in best["structures"])
                ratio = suggest[threads[0]] / suggest[threads[-1]]
                print(f"{key:<8} {search:<6} {len(best['structures']):>10} {vertices:>9} "
                      f"{best['evaluations']:>7} " + " ".join(cells) + f" {ratio:>8.2f}")


if __name__ == "__main__":
    main()
