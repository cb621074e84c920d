"""How good and how fast each case search is: `meshsmooth case build` with every --search on a
label map, each structure's score S beside the full grid's minimum.

Printed, not asserted. Needs Python 3 and the release build (`cargo build --release`):

    python3 tests/bench/suggest_quality.py [--maps jhu,phantom] [--searches grid,local,learned]
        [--tau 0.5] [--map-file FILE --colors TABLE]

The first search is the reference (grid: the full grid's minimum). For each other search: the
seconds of the suggestions, the parameter sets measured, and each structure's S against the
reference's: the worst and mean excess in percent and how many structures lie within 1%.
`--per-structure` prints every structure's line too.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from suggest_all import BIN, DATA, MAPS  # noqa: E402  (the same tool, data and maps)


def build(label_map, table, search, tau, out):
    cmd = [BIN, "case", "build", label_map, "--search", search, "--tau", str(tau), "-o", out, "--json"]
    if table:
        cmd += ["--colors", table]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed: {done.stderr}")
    return json.loads(done.stdout)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--maps", default="jhu,phantom")
    p.add_argument("--searches", default="grid,local,learned")
    p.add_argument("--tau", type=float, default=0.5)
    p.add_argument("--map-file", help="another label map (named 'file' in the table)")
    p.add_argument("--colors", help="the colour table beside --map-file")
    p.add_argument("--per-structure", action="store_true")
    a = p.parse_args()
    maps = {k: tuple(os.path.join(DATA, r) for r in MAPS[k]) for k in a.maps.split(",") if k}
    if a.map_file:
        maps["file"] = (a.map_file, a.colors)
    quality_table(maps, a.searches.split(","), a.tau, a.per_structure)


def quality_table(maps, searches, tau, per_structure=False):
    """Prints, for each label map of `maps` (key: (map, colour table)), each search's time, sets
    and scores against the first search's."""
    print(f"{'map':<8} {'search':<8} {'structures':>10} {'vertices':>9} {'suggest s':>9} {'sets':>7} "
          f"{'worst %':>8} {'mean %':>7} {'within 1%':>9}")
    with tempfile.TemporaryDirectory() as work:
        out = os.path.join(work, "case.glb")
        for key, (label_map, table) in maps.items():
            runs = {s: build(label_map, table, s, tau, out) for s in searches}
            reference = {s["name"]: s["score"] for s in runs[searches[0]]["structures"]}
            for search in searches:
                r = runs[search]
                excess = []
                for s in r["structures"]:
                    ref = reference[s["name"]]
                    excess.append((100.0 * (s["score"] - ref) / abs(ref) if ref else 0.0, s))
                worst = max(e for e, _ in excess)
                mean = sum(e for e, _ in excess) / len(excess)
                within = sum(1 for e, _ in excess if e <= 1.0)
                vertices = sum(s["vertices"] for s in r["structures"])
                print(f"{key:<8} {search:<8} {len(excess):>10} {vertices:>9} {r['suggest_seconds']:>9.2f} "
                      f"{r['evaluations']:>7} {worst:>8.3f} {mean:>7.3f} {within:>5}/{len(excess):<3}")
                if per_structure and search != searches[0]:
                    for e, s in sorted(excess, key=lambda x: -x[0]):
                        print(f"    {s['name']:<40} {s['vertices']:>8} S {s['score']:.5f} "
                              f"vs {reference[s['name']]:.5f} ({e:+.3f}%) {s['params']}")


if __name__ == "__main__":
    main()
