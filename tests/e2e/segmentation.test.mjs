// End-to-end tests of label maps in the page: a NIfTI or .seg.nrrd opens into named structures
// (the same the CLI's `extract` makes), one of them the model; a broken one is refused by name.
//
//   E2E_MODE=webgpu|cpu node --test tests/e2e/segmentation.test.mjs   (tests/e2e/run.sh runs both)
import assert from "node:assert/strict";
import { appendFileSync, mkdirSync, readFileSync, writeFileSync } from "node:fs";
import { gunzipSync, gzipSync } from "node:zlib";
import { dirname, join } from "node:path";

import * as cli from "./lib/cli.mjs";
import { metricDifferences } from "./lib/compare.mjs";
import { E2E_OUT, meshPath } from "./lib/paths.mjs";
import { gltfValidator } from "./lib/deps.mjs";
import { meshNodes } from "./lib/glb.mjs";
import { EVERY_RUN, WEBGPU_RUN, appSuite, testIn } from "./lib/suite.mjs";

const { MODE, withApp } = appSuite({ beforeAll: () => cli.requireCli() });

const JHU = meshPath("labelmaps/JHU-WhiteMatter-labels-1mm.nii.gz");
const PHANTOM_NRRD = meshPath("labelmaps/case_phantom_shared.seg.nrrd");
const PHANTOM_NIFTI = meshPath("labelmaps/case_phantom_shared.nii.gz");
const TIMEOUT = 240_000;

/** `meshsmooth extract FILE --json` into a folder of PLYs (`file` of each names its PLY). */
async function extracted(file) {
    return (await cli.cliJson("extract", file, "-o", join(E2E_OUT, `extract-${MODE}/`), "--json")).structures;
}

/** Tolerance of the page's measures against the CLI's, as in app.test.mjs. */
const METRIC_RTOL = { cpu: 1e-9, webgpu: 1e-4 }[MODE];

/** The page's structure list against the CLI's: labels, names, colours and counts. */
function assertSameStructures(page, native) {
    assert.equal(page.length, native.length);
    page.forEach((s, i) => {
        const n = native[i];
        assert.deepEqual([s.label, s.name, s.voxels, s.vertices, s.triangles], [n.label, n.name, n.voxels, n.vertices, n.triangles], `structure ${i}`);
        s.color.forEach((c, k) => assert.ok(Math.abs(c - n.color[k]) < 1e-6, `structure ${i} colour`));
        assert.ok(Math.abs(s.volume - n.volume) <= 1e-9 * Math.abs(n.volume), `structure ${i} volume ${s.volume} vs ${n.volume}`);
    });
}

testIn(WEBGPU_RUN, "S1 the JHU atlas opens into its 48 structures, as the CLI extracts them (time printed)", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        const name = "JHU-WhiteMatter-labels-1mm.nii.gz";
        const bytes = readFileSync(JHU);
        const run = await app.page.evaluate(
            async ([base64, name]) => {
                const text = atob(base64);
                const data = new Uint8Array(text.length);
                for (let i = 0; i < text.length; i++) data[i] = text.charCodeAt(i);
                const start = performance.now();
                const info = await window.meshsmooth.loadMesh(data, name);
                const seconds = (performance.now() - start) / 1000;
                return { info, seconds, structures: window.meshsmooth.structures(), state: window.meshsmooth.state() };
            },
            [bytes.toString("base64"), name],
        );
        const native = await extracted(JHU);
        assert.equal(run.structures.file, name);
        assert.equal(run.structures.current, 0);
        assertSameStructures(run.structures.structures, native);
        assert.equal(run.info.vertices, native[0].vertices);
        assert.equal(run.info.closed, true);
        assert.equal(run.info.boundary_edges, 0);
        assert.equal(run.info.nonmanifold_edges, 0);
        assert.equal(run.state.model, `${name}: label 1`);
        const stages = run.state.open_stages.map((s) => s.doing);
        assert.equal(stages[0], "reading the label map");
        assert.equal(stages[1], "extracting the structures");
        const stageMs = Object.fromEntries(run.state.open_stages.slice(0, 2).map((s) => [s.doing, Math.round(s.ms)]));
        const line = { bench: "open-label-map", mode: MODE, backend: await app.backend(), file: name, structures: 48, seconds: run.seconds, stage_ms: stageMs };
        console.log(JSON.stringify(line));
        appendFileSync(join(E2E_OUT, "bench.json"), JSON.stringify(line) + "\n");
        await app.metrics();
        await app.screenshot("S1-jhu-first-structure");

        // 48 structures: the list offers a filter; typing keeps the rows whose name holds it
        // (without a colour table they are "label 1" to "label 48": "label 4" keeps 4, 40-48).
        const centre = (r) => [r.x + r.width / 2, r.y + r.height / 2];
        let state = await app.stateWhen((s) => s.layout.structures.length === 48 && s.layout.structure_filter, "every row and the filter field");
        await app.page.mouse.click(...centre(state.layout.structure_filter));
        await app.page.keyboard.type("LABEL 4");
        const wanted = run.structures.structures.flatMap((s, i) => (s.name.toLowerCase().includes("label 4") ? [i] : []));
        assert.equal(wanted.length, 10);
        state = await app.stateWhen((s) => s.layout.structures.length === wanted.length, "only the rows of label 4 and 40-48");
        assert.deepEqual(state.layout.structures.map((r) => r.index), wanted);
        await app.screenshot("S1-jhu-list-filtered");
        await app.page.keyboard.press("Control+A");
        await app.page.keyboard.press("Backspace");
        await app.stateWhen((s) => s.layout.structures.length === 48, "every row again");

        // Suggest all on the 48 structures tells how far it is by the work done, which the
        // list's bar shows with the time left.
        const running = app.call("suggestAll", { tau: 0.5, search: "learned" });
        running.catch(() => {});
        state = await app.stateWhen((s) => s.suggest_all && s.suggest_all.work_done > 0, "some of the work done");
        const part = state.suggest_all;
        assert.ok(part.work_done < 1 && part.done > 0 && part.done < part.total, JSON.stringify([part.work_done, part.done]));
        // The session keeps when it started, so the API's estimate is the bar's.
        assert.ok(typeof part.seconds_left === "number" && part.seconds_left > 0, JSON.stringify(part.seconds_left));
        await app.screenshot("S1-jhu-suggest-all-time-left");
        const all = await running;
        assert.deepEqual([all.done, all.total, all.work_done, all.seconds_left], [48, 48, null, null]);
    });
});

testIn(EVERY_RUN, "S2 the phantom's .seg.nrrd names its structures; picking one makes it the model with its voxel size", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        await app.loadMesh(readFileSync(PHANTOM_NRRD), "case_phantom_shared.seg.nrrd");
        const list = await app.call("structures");
        const native = await extracted(PHANTOM_NRRD);
        assertSameStructures(list.structures, native);
        assert.deepEqual(list.structures.map((s) => s.name), ["liver", "portal_vein", "tumor", "right_kidney"]);
        const info = await app.call("selectStructure", 2);
        assert.equal(info.vertices, list.structures[2].vertices);
        const state = await app.state();
        assert.equal(state.model, "case_phantom_shared.seg.nrrd: tumor");
        assert.equal(state.structures.current, 2);
        // It smooths by default within Gibson's bound: half its voxel diagonal.
        const diagonal = Math.hypot(...list.structures[2].voxel_size);
        assert.ok(Math.abs(state.params.max_displacement - diagonal / 2) < 1e-6, `bound ${state.params.max_displacement} mm, voxel diagonal ${diagonal} mm`);
        // The structure is the model: smoothed, it measures as the CLI measures the same
        // surface (the PLY that extract wrote) smoothed the same way, bound included.
        const params = { lambda: 0.5, mu: -0.53, iterations: 10, max_displacement: state.params.max_displacement };
        await app.setFilter("taubin");
        await app.setParams(params);
        const metrics = await app.metrics();
        const reference = await cli.smooth(native[2].file, join(E2E_OUT, `tumor-${MODE}.ply`), "taubin", params);
        const { problems } = metricDifferences(metrics, reference.metrics, METRIC_RTOL);
        assert.deepEqual(problems, [], `metrics() of the tumour differ from the CLI's:\n${problems.join("\n")}`);
        const refused = await app.attempt("selectStructure", 9);
        assert.equal(refused.ok, false);
        assert.match(refused.message, /structure 9 does not exist/);
        await app.screenshot("S2-phantom-tumor");
    });
});

testIn(WEBGPU_RUN, "S3 a broken label map is refused by name and the open structure stays", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        await app.loadMesh(readFileSync(PHANTOM_NIFTI), "case_phantom_shared.nii.gz");
        const whole = readFileSync(PHANTOM_NIFTI);
        const half = whole.subarray(0, whole.length >> 1);
        const result = await app.attemptLoad(half, "half.nii.gz");
        assert.equal(result.ok, false);
        assert.match(result.message, /half\.nii\.gz/);
        assert.match(result.message, /gzip|ends early|truncated/i);
        const state = await app.state();
        assert.equal(state.model, "case_phantom_shared.nii.gz: label 1");
        assert.equal(state.structures.structures.length, 4);
    });
});

/**
 * A CT-sized label map (512 x 512 x 400 voxels) made from the phantom by nearest-neighbour
 * upsampling, its structures split by side and height into about a dozen labels; written as
 * NIfTI-1 .nii.gz. Returns the gzip bytes.
 */
function ctSizedLabelMap() {
    const src = gunzipSync(readFileSync(PHANTOM_NIFTI));
    const h = Buffer.from(src.subarray(0, 348));
    const dim = [1, 2, 3].map((k) => h.readInt16LE(40 + 2 * k));
    assert.equal(h.readInt16LE(70), 2, "the phantom is uint8");
    assert.ok(h.readInt16LE(254) > 0, "the phantom has an sform");
    const offset = h.readFloatLE(108);
    const want = [512, 512, 400];
    const scale = dim.map((d, k) => d / want[k]);
    const out = Buffer.alloc(352 + want[0] * want[1] * want[2]);
    h.copy(out, 0);
    want.forEach((d, k) => out.writeInt16LE(d, 40 + 2 * (k + 1)));
    for (let k = 0; k < 3; k++) out.writeFloatLE(h.readFloatLE(80 + 4 * k) * scale[k], 80 + 4 * k);
    out.writeFloatLE(352, 108);
    out.writeInt16LE(0, 252); // qform off: the sform alone places the grid
    for (let r = 0; r < 3; r++) {
        const row = [0, 1, 2, 3].map((c) => h.readFloatLE(280 + 16 * r + 4 * c));
        let t = row[3];
        for (let c = 0; c < 3; c++) {
            // New voxel i sits at old index (i + 0.5) * s - 0.5.
            t += row[c] * (0.5 * scale[c] - 0.5);
            out.writeFloatLE(row[c] * scale[c], 280 + 16 * r + 4 * c);
        }
        out.writeFloatLE(t, 280 + 16 * r + 12);
    }
    const voxels = src.subarray(offset);
    let at = 352;
    for (let k = 0; k < want[2]; k++) {
        const ks = Math.floor(k * scale[2]);
        for (let j = 0; j < want[1]; j++) {
            const js = Math.floor(j * scale[1]);
            const row = (ks * dim[1] + js) * dim[0];
            for (let i = 0; i < want[0]; i++) {
                const label = voxels[row + Math.floor(i * scale[0])];
                out[at++] = label === 0 ? 0 : label + 4 * ((i >= 256 ? 1 : 0) + (k >= 200 ? 2 : 0));
            }
        }
    }
    return gzipSync(out, { level: 1 });
}

testIn(WEBGPU_RUN, "S4 a CT-sized label map (512 x 512 x 400) opens natively and in the page (times and peak memory printed)", { timeout: 600_000 }, async () => {
    const bytes = ctSizedLabelMap();
    const file = join(E2E_OUT, `ct_sized_${MODE}.nii.gz`);
    writeFileSync(file, bytes);
    const native = await cli.cliJson("extract", file, "-o", join(E2E_OUT, `ct_sized_${MODE}.glb`), "--json");
    await withApp(async (app) => {
        const run = await app.page.evaluate(async (base64) => {
            const text = atob(base64);
            const data = new Uint8Array(text.length);
            for (let i = 0; i < text.length; i++) data[i] = text.charCodeAt(i);
            const before = window.meshsmooth.state().memory.page;
            const start = performance.now();
            await window.meshsmooth.loadMesh(data, "ct_sized.nii.gz");
            const seconds = (performance.now() - start) / 1000;
            const state = window.meshsmooth.state();
            return { seconds, before, state, structures: window.meshsmooth.structures() };
        }, bytes.toString("base64"));
        assertSameStructures(run.structures.structures, native.structures);
        const stageMs = Object.fromEntries(run.state.open_stages.slice(0, 2).map((s) => [s.doing, Math.round(s.ms)]));
        const line = {
            bench: "open-ct-sized-label-map",
            mode: MODE,
            voxels: 512 * 512 * 400,
            gzip_bytes: bytes.length,
            structures: native.structures.length,
            native_extract_seconds: native.seconds,
            native_peak_memory_mb: native.peak_memory_bytes === null ? null : Math.round(native.peak_memory_bytes / 1e6),
            page_open_seconds: run.seconds,
            page_stage_ms: stageMs,
            page_memory_mb_before: Math.round(run.before / 1e6),
            page_memory_mb_peak: Math.round(run.state.memory.page / 1e6),
        };
        console.log(JSON.stringify(line));
        appendFileSync(join(E2E_OUT, "bench.json"), JSON.stringify(line) + "\n");
    });
});

testIn(WEBGPU_RUN, "S5 a label map dropped on the page opens as its structures", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        await app.dropFile(readFileSync(PHANTOM_NRRD), "case_phantom_shared.seg.nrrd");
        const deadline = Date.now() + 60_000;
        let state = await app.state();
        while (!(state.structures?.file === "case_phantom_shared.seg.nrrd" && state.loading === null) && Date.now() < deadline) {
            await new Promise((resolve) => setTimeout(resolve, 200));
            state = await app.state();
        }
        assert.ok(state.structures, "the dropped label map opened as structures");
        assert.equal(state.model, "case_phantom_shared.seg.nrrd: liver");
        assert.deepEqual(state.structures.structures.map((s) => s.name), ["liver", "portal_vein", "tumor", "right_kidney"]);
        await app.screenshot("S5-dropped-seg-nrrd");
    });
});

/**
 * Strongly green pixels in the 3D view (`view`: its rectangle from state()), left of its colour
 * legend: the tumour once it is coloured pure green (the list's swatch is outside the view).
 */
function greenPixels(image, view) {
    return viewPixels(image, view, (r, g, b) => g > 90 && g > r + 60 && g > b + 60);
}

/** Pixels of the 3D view left of its legend whose colour `(r, g, b)` passes `test`. */
function viewPixels(image, view, test) {
    let count = 0;
    for (let y = Math.round(view.y); y < Math.round(view.y + view.height); y++) {
        for (let x = Math.round(view.x); x < Math.round(view.x + 0.7 * view.width); x++) {
            const i = (y * image.width + x) * 4;
            if (test(image.rgba[i], image.rgba[i + 1], image.rgba[i + 2])) count++;
        }
    }
    return count;
}

/** The checks' marks: magenta, unlike any structure of the phantom. */
const magenta = (r, g, b) => r > 120 && b > 110 && g + 70 < Math.min(r, b);

testIn(EVERY_RUN, "S6 every structure is drawn in its colour: opacity, hiding, solo and names; each keeps its own smoothing", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        await app.loadMesh(readFileSync(PHANTOM_NRRD), "case_phantom_shared.seg.nrrd");
        const looks = (list) => list.structures.map((s) => [s.name, s.opacity, s.visible]);
        let list = await app.call("structures");
        assert.deepEqual(looks(list), [["liver", 1, true], ["portal_vein", 1, true], ["tumor", 1, true], ["right_kidney", 1, true]]);
        await app.screenshot("S6-phantom-all-structures");
        // Work on the kidney; the tumour, inside the liver, turns pure green.
        await app.call("selectStructure", 3);
        await app.call("setStructure", { index: 2, color: [0, 1, 0] });
        await app.metrics();
        const { view } = await app.state();
        const hidden = greenPixels(await app.screenshot("S6-tumour-green-inside-the-liver"), view);
        // The liver made translucent shows the tumour inside it.
        await app.call("setStructure", { index: 0, opacity: 0.3 });
        await app.metrics();
        const seen = greenPixels(await app.screenshot("S6-liver-translucent-tumour-seen"), view);
        assert.ok(seen > hidden + 200, `the tumour shows through the translucent liver: ${hidden} -> ${seen} green pixels`);
        await app.call("setStructure", { index: 2, visible: false });
        await app.metrics();
        const gone = greenPixels(await app.screenshot("S6-tumour-hidden"), view);
        assert.ok(gone < 50, `the hidden tumour is not drawn: ${gone} green pixels (${seen} shown)`);
        await app.call("setStructure", { index: 1, name: "portal vein", group: "Vessels" });
        const refused = await app.attempt("setStructure", { index: 0, opacity: 2 });
        assert.equal(refused.ok, false);
        assert.match(refused.message, /opacity/);
        list = await app.call("structures");
        assert.deepEqual(looks(list), [["liver", 0.30000001192092896, true], ["portal vein", 1, true], ["tumor", 1, false], ["right_kidney", 1, true]]);
        assert.deepEqual(list.structures[2].color, [0, 1, 0]);
        assert.deepEqual(list.structures.map((s) => s.group), [null, "Vessels", null, null]);
        // Solo: the portal vein alone (the model, the kidney, not drawn); again, all of them.
        await app.call("soloStructure", 1);
        list = await app.call("structures");
        assert.deepEqual(list.structures.map((s) => s.visible), [false, true, false, false]);
        await app.metrics();
        await app.screenshot("S6-portal-vein-alone");
        await app.call("soloStructure", 1);
        list = await app.call("structures");
        assert.deepEqual(list.structures.map((s) => s.visible), [true, true, true, true]);
        await app.call("setStructure", { index: 2, visible: false });

        // The kidney smoothed; then the liver: the kidney keeps its smoothing and measures.
        await app.setFilter("taubin");
        await app.setParams({ iterations: 12 });
        const kidney = await app.metrics();
        await app.call("selectStructure", 0);
        await app.setFilter("laplace");
        await app.setParams({ iterations: 4 });
        const liver = await app.metrics();
        // The liver is the model now, drawn at its own opacity: the tumour shows through it.
        const behindModel = greenPixels(await app.screenshot("S6-liver-model-tumour-hidden"), view);
        await app.call("setStructure", { index: 2, visible: true });
        await app.metrics();
        const throughModel = greenPixels(await app.screenshot("S6-liver-model-translucent-tumour-seen"), view);
        assert.ok(throughModel > behindModel + 200, `the tumour shows through the translucent model: ${behindModel} -> ${throughModel} green pixels`);
        await app.call("setStructure", { index: 2, visible: false });
        list = await app.call("structures");
        assert.deepEqual(list.structures[3].metrics, kidney, "the kidney keeps its measures");
        assert.deepEqual(list.structures[0].metrics, liver);
        assert.equal(list.structures[1].metrics, null, "never smoothed");
        assert.equal(list.structures[2].metrics, null, "never smoothed");
        // Back to the kidney: its filter and parameters return, and its result with them. A
        // pointer moves: no worker opens it and nothing is smoothed again.
        const openings = (await app.state()).cpu_engine.openings;
        await app.call("selectStructure", 3);
        const state = await app.state();
        assert.equal(state.structures.current, 3);
        assert.equal(state.cpu_engine.openings, openings, "selecting asked the workers to open nothing");
        assert.equal(state.loading, null);
        assert.equal(state.busy, false, "its result is there at once");
        assert.equal(state.filter, "taubin");
        assert.equal(state.params.iterations, 12);
        assert.deepEqual(await app.metrics(), kidney);
        await app.screenshot("S6-kidney-again-liver-smoothed-translucent");

        // The case as arranged, exported: valid glTF, and the CLI reads back every structure
        // with its name, look, parameters and measures.
        await app.call("setCase", { title: "Abdomen", description: "Liver, portal vein, tumour, kidney" });
        const bytes = Buffer.from(await app.call("exportCase", "glb"));
        const file = join(E2E_OUT, MODE, "S6-case.glb");
        writeFileSync(file, bytes);
        const report = await gltfValidator.validateBytes(new Uint8Array(bytes), { uri: "S6-case.glb", format: "glb" });
        const issues = report.issues.messages.filter((m) => m.severity <= 1).map((m) => `${m.code} ${m.pointer ?? ""}: ${m.message}`);
        assert.deepEqual(issues, [], "the page's case GLB has no validator errors or warnings");
        const back = await cli.cliJson("case", "info", file, "--json");
        assert.equal(back.title, "Abdomen");
        assert.deepEqual(back.structures.map((s) => s.group), [null, "Vessels", null, null]);
        assert.deepEqual(back.structures.map((s) => [s.name, s.visible, s.smoothed, s.filter]), [
            ["liver", true, true, "laplace"],
            ["portal vein", true, false, "hc"],
            ["tumor", false, false, "hc"],
            ["right_kidney", true, true, "taubin"],
        ]);
        assert.ok(Math.abs(back.structures[0].color[3] - 0.3) < 1e-6, "the liver's opacity");
        assert.deepEqual(back.structures[2].color.slice(0, 3), [0, 1, 0]);
        const { problems } = metricDifferences(back.structures[3].metrics, kidney, 1e-9);
        assert.deepEqual(problems, [], `the kidney's record: ${problems.join("; ")}`);
        assert.equal(back.structures[3].params.iterations, 12);
    });
});

testIn(EVERY_RUN, "S7 Suggest all gives every structure the CLI's case build suggestion, one structure per worker; the checks agree", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        await app.loadMesh(readFileSync(PHANTOM_NRRD), "case_phantom_shared.seg.nrrd");
        const start = Date.now();
        const all = await app.call("suggestAll", { tau: 0.5, search: "local" });
        const seconds = (Date.now() - start) / 1000;
        assert.deepEqual([all.done, all.total, all.cancelled], [4, 4, false]);
        const file = join(E2E_OUT, MODE, "S7-cli-case.glb");
        const cliStart = Date.now();
        const built = await cli.cliJson("case", "build", PHANTOM_NRRD, "--search", "local", "-o", file, "--json");
        const cliSeconds = (Date.now() - cliStart) / 1000;
        const native = (await cli.cliJson("case", "info", file, "--json")).structures;
        // Every structure, the model's too, starts as the CLI's do: its filter, with the bound
        // at half its voxel diagonal.
        for (const i of [0, 1, 2, 3]) {
            assert.deepEqual(all.structures[i].params, native[i].params, `${native[i].name}'s suggestion`);
            const { problems } = metricDifferences(all.structures[i].metrics, native[i].metrics, 1e-9);
            assert.deepEqual(problems, [], `${native[i].name}'s measures: ${problems.join("; ")}`);
        }
        const state = await app.state();
        assert.deepEqual(state.params, all.structures[0].params, "the model takes its suggestion");
        // Its result follows its new parameters.
        await app.metrics();
        const list = await app.call("structures");
        assert.ok(list.structures.every((s) => s.metrics !== null), "every structure smoothed");
        // The checks between the structures say what the CLI's say of its case.
        const checks = await app.call("checkStructures");
        assert.equal(checks.current, true);
        assert.deepEqual([checks.left_inside, checks.new_crossings, checks.flagged], [[], [], []]);
        assert.match(checks.text, /tumor lies inside liver/);
        const flags = (p) => [p.a, p.b, p.a_inside_b, p.b_inside_a, p.crosses];
        assert.deepEqual(checks.pairs.map(flags), built.checks.pairs.map(flags));
        const within = { cpu: 1e-9, webgpu: 1e-3 }[MODE];
        checks.pairs.forEach((p, i) => {
            for (const key of ["a_outside_b_mm", "b_outside_a_mm", "overlap_depth_mm"]) {
                const [x, y] = [p[key], built.checks.pairs[i][key]];
                assert.ok(x === y || Math.abs(x - y) <= within, `${p.a}/${p.b} ${key}: ${x} vs the CLI's ${y}`);
            }
        });
        const view = (await app.state()).view;
        const unmarked = viewPixels(await app.screenshot("S7-phantom-suggested-all"), view, magenta);
        assert.ok(unmarked < 50, `no warning, no marks: ${unmarked} magenta pixels`);
        // The liver shrunk by heavy smoothing: the checks warn, and the list flags both.
        await app.setFilter("laplace");
        await app.setParams({ lambda: 0.9, iterations: 50, max_displacement: null });
        await app.metrics();
        const warned = await app.call("checkStructures");
        assert.deepEqual(warned.left_inside, [["tumor", "liver"]]);
        assert.ok(warned.flagged.includes(0) && warned.flagged.includes(2), `flagged ${warned.flagged}`);
        // The view marks where, over everything.
        assert.ok(warned.marked_vertices[2] > 0, `the tumour's vertices out of the liver: ${warned.marked_vertices}`);
        const marked = (image) => viewPixels(image, view, magenta) > unmarked + 300;
        await app.screenshotWhen("S7-liver-shrunk-checks-warn", marked, "the checks' marks");
        // Hiding the kidney leaves the surfaces as checked, and the marks; smoothing anew does not.
        await app.call("setStructure", { index: 3, visible: false });
        assert.equal((await app.state()).checks.current, true);
        await app.screenshotWhen("S7-marks-kidney-hidden", marked, "the marks with the kidney hidden");
        await app.setParams({ iterations: 5 });
        await app.metrics();
        assert.equal((await app.state()).checks.current, false);
        const gone = (image) => viewPixels(image, view, magenta) < unmarked + 50;
        await app.screenshotWhen("S7-liver-changed-marks-gone", gone, "the marks gone");
        const line = { bench: "page-suggest-all", mode: MODE, file: "case_phantom_shared.seg.nrrd", structures: 4, search: "local", page_s: seconds, cli_s: cliSeconds, workers: state.cpu_engine.workers };
        console.log(JSON.stringify(line));
        appendFileSync(join(E2E_OUT, "bench.json"), JSON.stringify(line) + "\n");
    });
});

/** The largest difference between two lists of numbers (Infinity when their lengths differ). */
/**
 * How far apart two point sets (flat x, y, z arrays) are: the farthest any point of one lies
 * from its nearest in the other, both ways; Infinity when the counts differ or a point has no
 * other within `reach`. Exports may number the same vertices differently.
 */
function farthestApart(a, b, reach) {
    if (a.length !== b.length) return Infinity;
    const key = (x, y, z) => `${Math.floor(x / reach)},${Math.floor(y / reach)},${Math.floor(z / reach)}`;
    const oneWay = (from, to) => {
        const cells = new Map();
        for (let i = 0; i < to.length; i += 3) {
            const k = key(to[i], to[i + 1], to[i + 2]);
            if (!cells.has(k)) cells.set(k, []);
            cells.get(k).push(i);
        }
        let worst = 0;
        for (let i = 0; i < from.length; i += 3) {
            const [x, y, z] = [from[i], from[i + 1], from[i + 2]];
            let nearest = Infinity;
            for (const dx of [-reach, 0, reach]) for (const dy of [-reach, 0, reach]) for (const dz of [-reach, 0, reach]) {
                for (const j of cells.get(key(x + dx, y + dy, z + dz)) ?? []) {
                    nearest = Math.min(nearest, Math.hypot(x - to[j], y - to[j + 1], z - to[j + 2]));
                }
            }
            worst = Math.max(worst, nearest);
        }
        return worst;
    };
    return Math.max(oneWay(a, b), oneWay(b, a));
}

testIn(EVERY_RUN, "S8 a case GLB exported by the page reopens as the same case and exports the same again (within the stated quantization)", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        await app.loadMesh(readFileSync(PHANTOM_NRRD), "case_phantom_shared.seg.nrrd");
        await app.call("setCase", { title: "Abdomen", description: "Round trip" });
        await app.call("setStructure", { index: 1, group: "Vessels" });
        await app.call("setStructure", { index: 0, opacity: 0.4 });
        await app.metrics();
        await app.call("selectStructure", 3);
        await app.setFilter("taubin");
        await app.setParams({ iterations: 9 });
        await app.metrics();
        const first = Buffer.from(await app.call("exportCase", "glb"));
        writeFileSync(join(E2E_OUT, MODE, "S8-first.glb"), first);

        const reopened = await app.loadMesh(first, "S8-first.glb", "loadCase");
        assert.equal(reopened.file, "S8-first.glb");
        assert.equal(reopened.current, 0);
        assert.deepEqual([reopened.title, reopened.description], ["Abdomen", "Round trip"]);
        assert.deepEqual(reopened.structures.map((s) => [s.name, s.group, s.opacity]), [
            ["liver", null, 0.4000000059604645],
            ["portal_vein", "Vessels", 1],
            ["tumor", null, 1],
            ["right_kidney", null, 1],
        ]);
        const state = await app.state();
        assert.equal(state.model, "S8-first.glb: liver");
        assert.equal(state.filter, "hc", "the liver's own filter and parameters come back");
        assert.ok(state.params.max_displacement > 0, "with its bound");
        await app.metrics();
        await app.screenshot("S8-reopened-case");
        const second = Buffer.from(await app.call("exportCase", "glb"));
        writeFileSync(join(E2E_OUT, MODE, "S8-second.glb"), second);

        // The same records (names, looks, groups, filters, parameters) and the same surfaces.
        const [a, b] = await Promise.all(
            ["S8-first.glb", "S8-second.glb"].map((f) => cli.cliJson("case", "info", join(E2E_OUT, MODE, f), "--json")),
        );
        const record = (s) => [s.name, s.color, s.visible, s.group, s.source, s.filter, s.params, s.tau, s.smoothed];
        assert.deepEqual(b.structures.map(record), a.structures.map(record));
        assert.deepEqual([b.title, b.description], [a.title, a.description]);
        const [x, y] = [meshNodes(first), meshNodes(second)];
        assert.deepEqual(y.map((n) => n.name), x.map((n) => n.name));
        x.forEach((n, i) => {
            // Compressed files: each position within its record's stated quantization error, and
            // the second smoothing starts from the first file's quantized original. The codecs'
            // vertex order may differ between the two.
            const [p, q] = [n.quantization, y[i].quantization];
            const stated = Math.max(p?.max_error_mm ?? 0, q?.max_error_mm ?? 0);
            const diagonals = Math.max(p?.max_error_voxel_diagonals ?? 0, q?.max_error_voxel_diagonals ?? 0);
            assert.ok(stated > 0 && diagonals < 0.05, `${n.name}: quantized, stating ${stated} mm, ${diagonals} voxel diagonals`);
            const bound = 3 * stated + 1e-6;
            const moved = farthestApart(n.positions, y[i].positions, bound);
            assert.ok(moved <= bound, `${n.name}: surfaces differ by ${moved} mm (bound ${bound})`);
            assert.equal(n.targets.length, y[i].targets.length, `${n.name}: its original as a morph target`);
            const originals = (node, t) => node.positions.map((p, j) => p + t[j]);
            n.targets.forEach((t, k) => {
                const apart = farthestApart(originals(n, t), originals(y[i], y[i].targets[k]), bound);
                assert.ok(apart <= bound, `${n.name}: original differs by ${apart} mm`);
            });
        });
        assert.equal(x[3].targets.length, 1, "the kidney was smoothed: its staircase is the morph target");
    });
});

testIn(EVERY_RUN, "S9 files added to the case, and several dropped together, join it as structures", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        await app.loadMesh(readFileSync(PHANTOM_NRRD), "case_phantom_shared.seg.nrrd");
        const before = await app.state();
        const sphere = readFileSync(meshPath("synthetic/synthetic_sphere_r20.stl"));
        const list = await app.loadMesh(sphere, "synthetic_sphere_r20.stl", "addFile");
        assert.deepEqual(list.structures.map((s) => s.name), ["liver", "portal_vein", "tumor", "right_kidney", "synthetic sphere r20"]);
        assert.equal(list.structures[4].source, "synthetic_sphere_r20.stl");
        assert.equal(list.structures[4].label, null);
        const state = await app.state();
        assert.equal(state.model, before.model, "the model stays");
        assert.deepEqual(state.params, before.params);
        const refused = await app.attemptLoad(Buffer.from("solid nothing"), "broken.stl", "addFile");
        assert.equal(refused.ok, false);
        assert.match(refused.message, /broken\.stl/);
        assert.equal((await app.call("structures")).structures.length, 5, "the case stays as it was");
        await app.metrics();
        await app.screenshot("S9-phantom-and-added-sphere");

        // A large structure selected the first time: a worker builds its model, then it is the
        // model (the call resolves with it).
        const brain = readFileSync(meshPath("segmentations/seg_mni152_brainmask_2mm.ply"));
        await app.loadMesh(brain, "seg_mni152_brainmask_2mm.ply", "addFile");
        const openings = (await app.state()).cpu_engine.openings;
        const info = await app.call("selectStructure", 5);
        assert.equal(info.vertices, 32626);
        const built = await app.state();
        assert.equal(built.structures.current, 5);
        assert.equal(built.cpu_engine.openings, openings + 1, "a worker built its model");
        assert.equal(built.loading, null);
        await app.metrics();
        await app.screenshot("S9-large-structure-selected");
        await app.call("selectStructure", 0);
        assert.equal((await app.state()).cpu_engine.openings, openings + 1, "the liver's model was kept");

        // Dropped together: they open as one case, in order.
        const ellipsoid = readFileSync(meshPath("synthetic/synthetic_ellipsoid_30_20_12.ply"));
        await app.dropFiles([
            { bytes: sphere, name: "synthetic_sphere_r20.stl" },
            { bytes: ellipsoid, name: "synthetic_ellipsoid_30_20_12.ply" },
        ]);
        const deadline = Date.now() + 60_000;
        let dropped = await app.state();
        while (!(dropped.structures?.structures.length === 2 && dropped.loading === null) && Date.now() < deadline) {
            await new Promise((resolve) => setTimeout(resolve, 200));
            dropped = await app.state();
        }
        assert.equal(dropped.model, "synthetic_sphere_r20.stl");
        assert.deepEqual(dropped.structures.structures.map((s) => s.name), ["synthetic sphere r20", "synthetic ellipsoid 30 20 12"]);
        assert.notDeepEqual(dropped.structures.structures[0].color, dropped.structures.structures[1].color);
        await app.metrics();
        await app.screenshot("S9-two-meshes-dropped-as-one-case");
    });
});

/** Drops `files` together and waits until they are open as the case `file`. */
async function dropAsOneCase(app, files, file) {
    await app.dropFiles(files);
    return app.stateWhen((s) => s.structures?.file === file && s.loading === null && s.model !== null, `${file} to open`);
}

testIn(EVERY_RUN, "S9b a label map with its colour table, and four masks, dropped together open as the CLI opens them", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        // The table first, as a file manager may list it: it names the label map's labels.
        const table = meshPath("labelmaps/case_phantom_shared_labels.txt");
        let state = await dropAsOneCase(app, [
            { bytes: readFileSync(table), name: "case_phantom_shared_labels.txt" },
            { bytes: readFileSync(PHANTOM_NIFTI), name: "case_phantom_shared.nii.gz" },
        ], "case_phantom_shared.nii.gz");
        const named = await cli.cliJson("extract", PHANTOM_NIFTI, "--colors", table, "-o", join(E2E_OUT, `extract-table-${MODE}/`), "--json");
        assertSameStructures(state.structures.structures, named.structures);
        assert.ok(state.structures.structures.every((s) => !s.name.startsWith("label ")), "names from the table");
        assert.equal(state.model, `case_phantom_shared.nii.gz: ${named.structures[0].name}`);
        await app.metrics();
        await app.screenshot("S9b-label-map-named-by-its-table");

        // Four masks: one case of four structures, each named by its file, as `extract` of the four.
        const masks = ["sphere_r20_mask.nii.gz", "ellipsoid_30_20_12_mask.nii.gz", "torus_R24_r8_mask.nii.gz", "bent_tube_r3.5_mask.nii.gz"];
        const paths = masks.map((m) => meshPath(`synthetic/${m}`));
        state = await dropAsOneCase(app, masks.map((name, i) => ({ bytes: readFileSync(paths[i]), name })), "sphere_r20_mask.nii.gz and 3 more files");
        const native = await cli.cliJson("extract", ...paths, "-o", join(E2E_OUT, `extract-masks-${MODE}/`), "--json");
        assertSameStructures(state.structures.structures, native.structures);
        assert.deepEqual(state.structures.structures.map((s) => s.name), ["Sphere r20 mask", "Ellipsoid 30 20 12 mask", "Torus R24 r8 mask", "Bent tube r3.5 mask"]);
        assert.deepEqual(state.structures.structures.map((s) => s.source), masks);
        assert.equal(state.error, null);
        await app.metrics();
        await app.screenshot("S9b-four-masks-as-one-case");
    });
});

testIn(EVERY_RUN, "S9c a folder of masks dropped on the page opens as the CLI opens the folder, subfolders too; an empty one and an unreadable file are reported", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        // In the order of their paths, hidden files and a DICOMDIR not read: the same folder on
        // disk given to the CLI.
        const masks = ["bent_tube_r3.5_mask.nii.gz", "ellipsoid_30_20_12_mask.nii.gz", "sphere_r20_mask.nii.gz", "torus_R24_r8_mask.nii.gz"];
        const placed = ["bent_tube_r3.5_mask.nii.gz", "more/ellipsoid_30_20_12_mask.nii.gz", "sphere_r20_mask.nii.gz", "more/ring/torus_R24_r8_mask.nii.gz"];
        const paths = masks.map((m) => meshPath(`synthetic/${m}`));
        const shuffled = [2, 0, 3, 1].map((i) => ({ bytes: readFileSync(paths[i]), name: placed[i] }));
        const extras = [{ bytes: Buffer.from("Bud1"), name: ".DS_Store" }, { bytes: Buffer.from("an index"), name: "more/DICOMDIR" }];
        // Listed slowly, as a large export on a slow disk is: the page says how far the listing got.
        await app.dropFolder("masks", [...shuffled, ...extras], { batchMs: 500 });
        await new Promise((r) => setTimeout(r, 1200));
        await app.screenshot("S9c-folder-being-listed");
        let state = await app.stateWhen((s) => s.structures?.file === "masks/bent_tube_r3.5_mask.nii.gz and 3 more files" && s.loading === null && s.model !== null, "the folder to open");
        const onDisk = join(E2E_OUT, `folder-${MODE}`, "masks");
        for (const { bytes, name } of [...shuffled, ...extras]) {
            mkdirSync(dirname(join(onDisk, name)), { recursive: true });
            writeFileSync(join(onDisk, name), bytes);
        }
        const native = await cli.cliJson("extract", onDisk, "-o", join(E2E_OUT, `extract-folder-${MODE}/`), "--json");
        assertSameStructures(state.structures.structures, native.structures);
        assert.deepEqual(state.structures.structures.map((s) => s.source), [masks[0], masks[1], masks[3], masks[2]], "in the order of their paths");
        assert.equal(state.error, null, "the folder's own entry among the drop's files is not opened");
        await app.screenshot("S9c-folder-of-masks");

        // A folder with nothing to read in it or its subfolders: its name and why, and the case stays.
        await app.dropFolder("empty", [{ bytes: Buffer.from("Bud1"), name: ".DS_Store" }, { bytes: Buffer.from("Bud1"), name: "series/.DS_Store" }]);
        state = await app.stateWhen((s) => s.error !== null, "the empty folder's error");
        assert.match(state.error, /empty.*neither the folder nor its 1 subfolder\(s\) hold a file/);
        assert.equal(state.structures.structures.length, 4);

        // A file the browser cannot read is named by its path in the folder.
        await app.dropFolder("masks", [shuffled[0], { bytes: Buffer.from(""), name: "gone.nii.gz", fails: true }]);
        state = await app.stateWhen((s) => s.error?.includes("gone"), "the unreadable file's error");
        assert.match(state.error, /masks\/gone\.nii\.gz.*the browser could not read it/);
        assert.equal(state.structures.structures.length, 4);

        // A file dropped after them opens as before.
        state = await dropAsOneCase(app, [{ bytes: readFileSync(PHANTOM_NRRD), name: "case_phantom_shared.seg.nrrd" }], "case_phantom_shared.seg.nrrd");
        assert.equal(state.structures.structures.length, 4);
    });
});

testIn(WEBGPU_RUN, "S10 the Structures list by mouse and keyboard: select, show alone, hide, rename", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        await app.loadMesh(readFileSync(PHANTOM_NRRD), "case_phantom_shared.seg.nrrd");
        const centre = (r) => [r.x + r.width / 2, r.y + r.height / 2];
        const click = (r) => app.page.mouse.click(...centre(r));
        const visible = (s) => s.structures.structures.map((x) => x.visible);
        let state = await app.stateWhen((s) => s.layout.structures.length === 4, "the list's four rows");
        const rows = state.layout.structures;
        assert.deepEqual(rows.map((r) => r.index), [0, 1, 2, 3]);

        // Clicking a name makes that structure the model.
        await click(rows[2].name);
        state = await app.stateWhen((s) => s.structures.current === 2 && s.loading === null, "the tumour to open");
        assert.equal(state.model, "case_phantom_shared.seg.nrrd: tumor");
        // S shows one alone; again, all of them. The box hides one.
        await click(rows[1].solo);
        await app.stateWhen((s) => visible(s).join() === "false,true,false,false", "the portal vein alone");
        await click(rows[1].solo);
        await app.stateWhen((s) => visible(s).every((v) => v), "every structure shown again");
        await click(rows[3].visible);
        state = await app.stateWhen((s) => visible(s).join() === "true,true,true,false", "the kidney hidden");
        // The Name field renames the selected structure when it loses focus.
        await click(state.layout.structure_name);
        await app.page.keyboard.press("Control+A");
        await app.page.keyboard.type("tumour");
        await app.page.keyboard.press("Enter");
        state = await app.stateWhen((s) => s.structures.structures[2].name === "tumour", "the tumour renamed");
        assert.deepEqual(state.structures.structures.map((s) => s.name), ["liver", "portal_vein", "tumour", "right_kidney"]);
        await app.metrics();
        await app.screenshot("S10-list-driven-by-mouse");
    });
});
