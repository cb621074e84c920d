"""The whole-body CT case: `meshsmooth case build` natively, the page's Suggest all beside it, and
the suggestions' quality, in one run.

Printed, not asserted. Needs Python 3 and the release builds (`cargo build --release --example
whole_body` and `cargo build --release`); the page's part also needs the web build (`trunk build
--release`, dist/) and what the e2e tests need (bash .ci/install.sh):

    python3 tests/bench/whole_body_case.py [--threads 1,2] [--simplify 0.1] [--keep DIR]
        [--page-modes cpu,webgpu | --page-modes ''] [--quality jhu,phantom | --quality '']

The tool is release/meshsmooth under CARGO_TARGET_DIR or the repository's target/ (override with
MESHSMOOTH_BIN), the generator release/examples/whole_body beside it (MESHSMOOTH_WHOLE_BODY). The
label map is made afresh in a temporary folder (or --keep DIR, kept there): 512 x 512 x 400 voxels,
114 structures.

1. For each thread count (RAYON_NUM_THREADS), one run of the default `case build` (learned search,
   compressed case glTF with the original as morph target), and with the most threads one more
   with `--simplify`: the JSON's `open_seconds` (reading and extraction), `suggest_seconds` (every
   structure's suggestion, smoothing and measures), `checks_seconds` (the checks between
   structures before and after), `export_seconds` (writing the case glTF, simplification
   included), `seconds` (the whole command), the file's size, its triangles and the command's peak
   resident memory (the kernel's count for that process).
2. The quality of the default search: each structure's S against the full grid's minimum on the
   shared JHU atlas and abdominal phantom (tests/bench/suggest_quality.py's table).
3. The page's Suggest all on the same map in headless Chromium, in each of --page-modes (cpu: the
   CPU engine with WebGL2; webgpu: WebGPU on SwiftShader), with one and with two engine workers,
   against the faster of two runs of the same tool's `case build` on every core right after it (benchmark B9 of
   tests/e2e/speed.bench.mjs): seconds, the ratio to the CLI's Suggest all, the page's and the
   workers' memory, and how many structures got the CLI's parameters. A pool of N workers puts
   N + 1 threads on Suggest all: the view worker takes structures too while the view does not
   need it. The CLI's Suggest all on one thread is printed beside, for the per-thread speed.
"""

import argparse
import json
import os
import struct
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from suggest_all import BIN, DATA, MAPS, ROOT  # noqa: E402  (the same tool and data)
from suggest_quality import quality_table  # noqa: E402
GEN = os.environ.get(
    "MESHSMOOTH_WHOLE_BODY", os.path.join(os.path.dirname(BIN), "examples", "whole_body"))


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


def cli_table(folder, label_map, table, threads, simplify):
    runs = [(t, []) for t in threads] + [(max(threads), ["--simplify", simplify])]
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


def page_table(folder, modes):
    """Runs B9 in each mode and prints its figures; says why not when the page cannot run."""
    if not os.path.exists(os.path.join(ROOT, "dist", "index.html")):
        print("the page: dist/index.html is missing (trunk build --release)")
        return
    env = dict(os.environ, E2E_WHOLE_BODY=folder, MESHSMOOTH_CLI=BIN, E2E_MODES=" ".join(modes))
    done = subprocess.run(["bash", "tests/e2e/run.sh", "--bench", "--test-name-pattern=^B9 "],
                          cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    bench = os.path.join(ROOT, "target", "e2e", "bench.json")
    lines = []
    if os.path.exists(bench):
        with open(bench) as f:
            lines = [json.loads(l) for l in f if l.strip()]
    lines = [l for l in lines if l.get("bench") == "page-suggest-all" and l.get("file") == "whole_body.nii.gz"]
    if done.returncode != 0 or not lines:
        print(f"the page: tests/e2e/run.sh --bench failed ({done.returncode}); its last lines:")
        print("\n".join(done.stdout.splitlines()[-20:]))
    print(f"{'page':<7} {'workers':>7} {'page s':>7} {'CLI s':>6} {'ratio':>6} {'page MB':>8} "
          f"{'workers MB':>11} {'CLI params':>10}")
    for l in lines:
        cli = l["cli_suggest_all_cores_s"]
        runs = ", ".join(f"{r:.2f}" for r in l.get("cli_suggest_all_cores_runs_s", [cli]))
        print(f"(the CLI's Suggest all: {cli:.2f} s on {l['cores']} threads, the faster of {runs}; "
              f"{l['cli_suggest_one_thread_s']:.2f} s on one)")
        for k, (workers, seconds, memory) in enumerate([
                (1, l["page_one_worker_s"], l["memory_one_worker"]),
                (2, l["page_two_workers_s"], l["memory_two_workers"])]):
            print(f"{l.get('mode', '?'):<7} {workers:>7} {seconds:>7.2f} {cli:>6.2f} {seconds / cli:>6.2f} "
                  f"{memory['page_mb']:>8.0f} {'+'.join(f'{w:.0f}' for w in memory['workers_mb']):>11} "
                  f"{l['same_params_as_cli'][k]:>6}/{l['structures']}")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--threads", default="1,2")
    p.add_argument("--simplify", default="0.1")
    p.add_argument("--keep")
    p.add_argument("--page-modes", default="cpu,webgpu")
    p.add_argument("--quality", default="jhu,phantom")
    a = p.parse_args()
    with tempfile.TemporaryDirectory() as work:
        folder = os.path.abspath(a.keep or work)
        os.makedirs(folder, exist_ok=True)
        label_map = os.path.join(folder, "whole_body.nii.gz")
        if not os.path.exists(label_map):
            subprocess.run([GEN, folder], check=True, stdout=subprocess.DEVNULL)
        table = os.path.join(folder, "whole_body_labels.txt")
        cli_table(folder, label_map, table, [int(t) for t in a.threads.split(",")], a.simplify)
        if a.quality:
            print()
            maps = {k: tuple(os.path.join(DATA, r) for r in MAPS[k]) for k in a.quality.split(",")}
            quality_table(maps, ["grid", "learned"], 0.5)
        if a.page_modes:
            print()
            page_table(folder, a.page_modes.split(","))


if __name__ == "__main__":
    main()
