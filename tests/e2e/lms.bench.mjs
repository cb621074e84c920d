// Benchmarks of the LMS packages: what a student downloads (the package's viewer wasm, raw and
// gzipped, against the authoring app's; the packages of the phantom case and of the whole-body
// map simplified at 0.1 voxel diagonals) and the packaged viewer's first frame on a phone held
// upright in CPU mode. Figures printed and added to target/e2e/bench.json.
//
//   E2E_MODES=cpu bash tests/e2e/run.sh --bench --test-name-pattern='^LB'
import assert from "node:assert/strict";
import { appendFileSync, mkdtempSync, readFileSync, readdirSync, rmSync, statSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { after } from "node:test";
import { gzipSync } from "node:zlib";

import { launchBrowser, modeFromEnv } from "./lib/browser.mjs";
import * as cli from "./lib/cli.mjs";
import { DIST, E2E_OUT, VIEWER_DIST } from "./lib/paths.mjs";
import { phantomPackage, stateWhen, viewerOf } from "./lib/packaged.mjs";
import { serveDirectory } from "./lib/server.mjs";
import { CPU_RUN, testIn } from "./lib/suite.mjs";

const MODE = modeFromEnv();
const tmp = mkdtempSync(join(tmpdir(), "meshsmooth-lms-bench-"));
after(() => rmSync(tmp, { recursive: true, force: true }));

function emit(line) {
    console.log(JSON.stringify(line));
    appendFileSync(join(E2E_OUT, "bench.json"), JSON.stringify(line) + "\n");
}

/** The .wasm file in `folder`: its bytes raw and gzipped (level 9, as a server would send it). */
function wasmSizes(folder) {
    const name = readdirSync(folder).find((f) => f.endsWith(".wasm"));
    const bytes = readFileSync(join(folder, name));
    return { raw: bytes.length, gzipped: gzipSync(bytes, { level: 9 }).length };
}

testIn(CPU_RUN, "LB1 what a student downloads: the package's viewer wasm against the app's, the phantom's packages and the whole-body map's, simplified", { timeout: 20 * 60_000 }, async () => {
    const sizes = {};
    for (const format of ["scorm12", "scorm2004", "cmi5"]) {
        const zip = join(tmp, `phantom-${format}.zip`);
        const started = performance.now();
        await phantomPackage(format, zip, join(tmp, format));
        sizes[format] = { bytes: statSync(zip).size, seconds: (performance.now() - started) / 1000 };
    }
    const viewer = wasmSizes(join(tmp, "scorm12", "viewer"));
    const app = wasmSizes(DIST);
    emit({
        bench: "lms-package", case: "case_phantom_shared.seg.nrrd with its lesson",
        viewer_wasm_bytes: viewer.raw, viewer_wasm_gzipped: viewer.gzipped,
        app_wasm_bytes: app.raw, app_wasm_gzipped: app.gzipped,
        package_bytes: Object.fromEntries(Object.entries(sizes).map(([f, s]) => [f, s.bytes])),
        package_seconds: Object.fromEntries(Object.entries(sizes).map(([f, s]) => [f, Number(s.seconds.toFixed(2))])),
    });

    const dir = process.env.E2E_WHOLE_BODY;
    assert.ok(dir, "E2E_WHOLE_BODY names no folder: run tests/e2e/run.sh --bench, which makes the whole-body map");
    const zip = join(tmp, "whole-body-scorm12.zip");
    const started = performance.now();
    const out = await cli.cliJson("case", "package", join(dir, "whole_body.nii.gz"), "--colors", join(dir, "whole_body_labels.txt"), "--simplify", "0.1", "--format", "scorm12", "--viewer", VIEWER_DIST, "-o", zip, "--json");
    emit({
        bench: "lms-package", case: "whole_body.nii.gz (114 structures), simplified at 0.1 voxel diagonals",
        structures: out.structures, case_bytes: out.case_bytes, package_bytes: out.bytes,
        seconds: Number(((performance.now() - started) / 1000).toFixed(1)),
    });
});

testIn(CPU_RUN, "LB2 the packaged viewer's first frame of the phantom on a phone held upright, CPU mode", { timeout: 10 * 60_000 }, async () => {
    const folder = join(tmp, "first-frame");
    await phantomPackage("scorm12", join(tmp, "first-frame.zip"), join(folder, "package"));
    const server = await serveDirectory(folder);
    const browser = await launchBrowser(MODE);
    try {
        const page = await browser.newPage({ viewport: { width: 390, height: 844 }, isMobile: true, hasTouch: true, deviceScaleFactor: 1 });
        await page.goto(`${server.url}package/index.html`);
        const started = await page.evaluate(() => performance.timeOrigin);
        const viewer = await viewerOf(page);
        // On the epoch's clock: the viewer's frame counts from its own navigation.
        const drawn = await viewer.frame.evaluate(() => new Promise((resolve) => {
            const look = () => {
                const s = window.meshsmooth.state();
                if (s.structures?.structures.length === 4 && s.loading === null) {
                    requestAnimationFrame(() => requestAnimationFrame(() => resolve(performance.timeOrigin + performance.now())));
                } else {
                    requestAnimationFrame(look);
                }
            };
            look();
        }));
        await stateWhen(viewer, (s) => s.view.width > 0, "the view");
        await page.screenshot({ path: join(E2E_OUT, MODE, "LB2-packaged-viewer-on-a-phone.png") });
        const downloaded = server.served.filter((line) => line.startsWith("GET")).length;
        emit({ bench: "lms-first-frame", case: "phantom (4 structures), SCORM 1.2 package opened on its own", viewport: "390x844", mode: MODE, first_frame_ms: Math.round(drawn - started), requests: downloaded });
    } finally {
        await browser.close();
        await server.close();
    }
});
