// End-to-end on a case of real size: the synthetic whole-body CT label map (512 x 512 x 400
// voxels, 114 structures; tests/bench/whole_body.rs, made by tests/e2e/run.sh into the folder
// E2E_WHOLE_BODY names, never committed) opened in the page with its label table, suggested for
// a few structures, written compressed and simplified with its size and triangles shown before
// it is saved, and opened by the viewer at a phone's size.
//
//   E2E_MODE=webgpu|cpu E2E_WHOLE_BODY=DIR node --test tests/e2e/whole_body.test.mjs
import assert from "node:assert/strict";
import { existsSync, readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";

import * as cli from "./lib/cli.mjs";
import { meshNodes } from "./lib/glb.mjs";
import { EVERY_RUN, appSuite, testIn } from "./lib/suite.mjs";

const { MODE, OUT, withApp } = appSuite({ beforeAll: () => cli.requireCli() });
const TIMEOUT = 1_200_000;
const PHONE = { viewport: { width: 390, height: 844 }, deviceScaleFactor: 2, isMobile: true, hasTouch: true };

/** The share of the 3D view (CSS pixels in `view`) drawn unlike its background (its top-right corner). */
function drawnShare(image, view) {
    const scale = image.width / PHONE.viewport.width;
    const at = (x, y) => {
        const i = (Math.round(y * scale) * image.width + Math.round(x * scale)) * 4;
        return [image.rgba[i], image.rgba[i + 1], image.rgba[i + 2]];
    };
    const background = at(view.x + view.width - 4, view.y + 4);
    let [drawn, all] = [0, 0];
    for (let y = view.y + 60; y < view.y + view.height - 40; y += 2) {
        for (let x = view.x; x < view.x + view.width; x += 2) {
            const c = at(x, y);
            all += 1;
            if (c.some((v, k) => Math.abs(v - background[k]) > 24)) drawn += 1;
        }
    }
    return drawn / Math.max(all, 1);
}

function wholeBody() {
    const dir = process.env.E2E_WHOLE_BODY;
    assert.ok(dir && existsSync(join(dir, "whole_body.nii.gz")), `E2E_WHOLE_BODY (${dir}) holds no whole_body.nii.gz: run tests/e2e/run.sh, which makes it`);
    return { map: readFileSync(join(dir, "whole_body.nii.gz")), table: readFileSync(join(dir, "whole_body_labels.txt")) };
}

testIn(EVERY_RUN, "W1 a whole-body CT label map: opened, suggested in part, written simplified with its size shown, drawn by the viewer on a phone", { timeout: TIMEOUT }, async () => {
    const { map, table } = wholeBody();
    let written;
    await withApp(async (app) => {
        let started = Date.now();
        await app.dropFiles([
            { bytes: table, name: "whole_body_labels.txt" },
            { bytes: map, name: "whole_body.nii.gz" },
        ]);
        let state = await app.stateWhen((s) => s.structures?.file === "whole_body.nii.gz" && s.loading === null && s.model !== null, "the whole-body map to open");
        const opened = (Date.now() - started) / 1000;
        const structures = state.structures.structures;
        assert.equal(structures.length, 114);
        assert.ok(structures.every((s) => !s.name.startsWith("label ")), "named by the table");
        const vertices = structures.reduce((n, s) => n + s.vertices, 0);
        assert.ok(vertices > 2_000_000, `millions of vertices: ${vertices}`);

        // "Suggest all" on the three smallest structures only.
        const few = structures.map((s, i) => [s.vertices, i]).sort((a, b) => a[0] - b[0]).slice(0, 3).map(([, i]) => i);
        const report = await app.call("suggestAll", { tau: 0.5, search: "learned", structures: few });
        assert.deepEqual([report.done, report.total, report.cancelled], [3, 3, false]);
        few.forEach((i) => assert.ok(report.structures[i]?.params, `${structures[i].name} suggested`));
        assert.equal(report.structures.filter((s) => s !== null).length, 3, "only those");

        // Written a structure per frame, simplified; its size and triangles shown before saving.
        started = Date.now();
        const file = await app.call("writeCase", { simplify: 0.1 });
        const writing = (Date.now() - started) / 1000;
        console.log(`W1 ${MODE}: opened in ${opened.toFixed(1)} s, written in ${writing.toFixed(1)} s: ${(file.bytes / 1e6).toFixed(2)} MB, ${file.triangles} triangles`);
        state = await app.state();
        assert.deepEqual(state.case_export.written, file);
        // Most structures are left as extracted here (staircases simplify least).
        const triangles = structures.reduce((n, s) => n + s.triangles, 0);
        assert.ok(file.triangles < 0.6 * triangles, `simplified: ${file.triangles} of ${triangles} triangles`);
        assert.ok(file.bytes < 10_000_000, `within 10 MB: ${file.bytes} bytes`);
        await app.screenshot("W1-written-simplified-size-shown");
        written = await app.callBytes("exportCase", "glb", { simplify: 0.1 });
        assert.equal(written.length, file.bytes, "the file written is the one exported");
        writeFileSync(join(OUT, "W1-whole-body-simplified.glb"), written);
        const nodes = meshNodes(written);
        assert.equal(nodes.length, 114);
        assert.ok(nodes.every((n) => n.quantization?.max_error_voxel_diagonals < 0.05), "quantized within 0.05 voxel diagonals");

        // The memory of the page and of each worker, as the API reports it (each one's peak).
        const { memory, cpu_engine: engine } = await app.state();
        assert.equal(memory.workers.length, engine.workers + (engine.view_worker ? 1 : 0));
        assert.ok(memory.page > 0 && memory.workers.every((b) => b > 0), JSON.stringify(memory));
        const mb = (b) => (b / 1e6).toFixed(0);
        const sum = memory.page + memory.workers.reduce((a, b) => a + b, 0);
        console.log(`W1 ${MODE}: memory: page ${mb(memory.page)} MB, workers ${memory.workers.map(mb).join(", ")} MB; ${mb(sum)} MB in all`);
    });

    // The viewer on a phone held upright: every structure listed, the case drawn.
    await withApp(async (viewer) => {
        // Timed in the page from the moment its bytes are there (handing them over from the
        // test is not the page's time): loadCase resolved, the first frame with every structure
        // open begun, and the frame after it begun (the first one drawn).
        await viewer.api();
        await viewer.page.evaluate((base64) => {
            window.wholeBodyCase = Uint8Array.from(atob(base64), (c) => c.charCodeAt(0));
        }, Buffer.from(written).toString("base64"));
        const [opened, ms] = await viewer.page.evaluate(async () => {
            const started = performance.now();
            const opened = await window.meshsmooth.loadCase(window.wholeBodyCase, "whole_body_case.glb");
            const marks = [performance.now() - started];
            const frame = () => new Promise((resolve) => requestAnimationFrame(resolve));
            while (!(window.meshsmooth.state().loading === null && window.meshsmooth.state().structures?.structures.length === 114)) {
                await frame();
            }
            await frame();
            marks.push(performance.now() - started);
            await frame();
            marks.push(performance.now() - started);
            return [opened.structures.length, marks];
        });
        assert.equal(opened, 114);
        const { view, open_stages: stages } = await viewer.state();
        const image = await viewer.screenshotWhen("W1-viewer-phone", (i) => drawnShare(i, view) > 0.05, "the case drawn");
        const [resolved, first, drawn] = ms.map((m) => (m / 1000).toFixed(2));
        const reading = stages.map((s) => `${s.doing} ${(s.ms / 1000).toFixed(2)} s`).join(", ");
        console.log(`W1 ${MODE}: the viewer drew the case ${drawn} s after its bytes were in the page (loadCase resolved at ${resolved} s, its worker: ${reading}; first frame begun at ${first} s; ${(100 * drawnShare(image, view)).toFixed(0)}% of the view drawn)`);
    }, { query: "?mode=viewer", device: PHONE });
});
