// End-to-end tests of the built web app (dist/) in headless Chromium, in one mode per run:
//
//   E2E_MODE=webgpu|cpu node --test tests/e2e/app.test.mjs   (tests/e2e/run.sh runs both)
//
// `webgpu`: WebGPU on SwiftShader, the app smooths on its GPU engine. `cpu`: no WebGPU, eframe
// draws with WebGL2 and the app smooths with its CPU engine. The native CLI is the reference for
// every number. Screenshots go to target/e2e/<mode>/.
import { after } from "node:test";
import assert from "node:assert/strict";
import { appendFileSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";

import { MODES } from "./lib/browser.mjs";
import * as cli from "./lib/cli.mjs";
import { jsonDifferences, metricDifferences, relativeDifference } from "./lib/compare.mjs";
import { gltfValidator } from "./lib/deps.mjs";
import { colourAt, colourHistogram, flatBoxes } from "./lib/png.mjs";
import { E2E_OUT, ROOT, meshPath } from "./lib/paths.mjs";
import { CPU_RUN, EVERY_RUN, WEBGPU_RUN, appSuite, testIn } from "./lib/suite.mjs";

const tmp = mkdtempSync(join(tmpdir(), "meshsmooth-e2e-"));
after(() => rmSync(tmp, { recursive: true, force: true }));

// The start itself is under test here: pages are handed over before their API is up.
const { MODE, OUT, withApp } = appSuite({ beforeAll: () => cli.requireCli(), waitForApi: false });

/** The bundled sample case (web/sample/abdomen_phantom.glb) as the page opens it: its first
 * structure is the model. */
const SAMPLE = {
    name: "abdomen_phantom.glb: liver",
    vertices: 22644,
    faces: 45292,
    structures: ["liver", "portal_vein", "tumor", "right_kidney"],
    lesson: JSON.parse(readFileSync(join(ROOT, "web/sample/abdomen_phantom_lesson.json"), "utf8")),
};
const TORUS = meshPath("synthetic/synthetic_torus_R24_r8.ply");
const SCALP = meshPath("real/fsaverage_head_scalp_mne.ply");
const BRAIN = meshPath("segmentations/seg_mni152_gm_plus_wm_p0.5_1mm.ply");

/** The page must be up within this many seconds (it takes about 2 s on SwiftShader). */
const START_LIMIT_S = 20;

/**
 * Tolerances of the app's measures against the native CLI's (relative; see compare.mjs).
 * cpu: the wasm build runs the same Rust code on the same f32 positions; only the order of f64
 * sums may differ (rayon splits them natively, wasm runs one thread). Measured on the scalp,
 * all four filters: at most 2.2e-16 (one ulp of curvature0). 1e-9 keeps a wide margin and still
 * catches any real divergence (a changed parameter moves the measures by 1e-3 or more).
 * webgpu: smoothing runs as WGSL in f32. Natively on lavapipe the GPU engine's positions were
 * bit-identical to the CPU's for these cases (and HC 50, sinc 100), so the measures were equal;
 * but WGSL lets a GPU fuse multiply-adds and round division and square roots differently (a
 * few ulp per operation, ~1e-7 relative), which 100 iterations and the drifting reference of
 * the local error can grow. 1e-4 allows that on real GPUs while a wrong parameter (1e-3 and
 * more) still fails. Each run prints the differences it saw (metrics-vs-cli lines).
 */
const METRIC_RTOL = { cpu: 1e-9, webgpu: 1e-4 }[MODE];
/** info is computed from the parsed file, the same code natively and in wasm. */
const INFO_RTOL = 1e-9;
/**
 * The bounding box holds f32 coordinates. The CLI prints each as the shortest decimal of the f32
 * (-83.23214); the app's JSON widens it to f64 first (-83.23213958740234): the same f32, a
 * relative difference of ~1e-8 in the text. Compared as f32, exactly.
 */
const INFO_F32_KEYS = ["bbox_min", "bbox_max"];

/** Non-default parameters per filter (defaults and ranges: ../shared/docs/ALGORITHMS.md). */
const FILTER_CASES = {
    laplace: { lambda: 0.3, iterations: 7 },
    taubin: { lambda: 0.4, mu: -0.45, iterations: 12 },
    hc: { alpha: 0.2, beta: 0.6, iterations: 15, max_displacement: 0.8 },
    sinc: { passband: 0.05, iterations: 30 },
};

const API_TIMEOUT = 5 * 60_000;

/** Opens the app and loads `file` through the API. */
async function withLoaded(file, body) {
    return withApp(async (app) => {
        const name = file.split("/").pop();
        const info = await app.loadMesh(readFileSync(file), name);
        return body(app, info, name);
    });
}

/**
 * The app logs every mesh it opens ("opened NAME: N vertices, M faces") and every file it
 * cannot open ("Cannot open NAME: why") to the console (src/app). The tests that need no
 * embedding API use these lines as their evidence.
 */
const escape = (text) => text.replace(/[.*+?^${}()|[\]\\]/g, "\\$&");
const openedLog = (name, vertices) => new RegExp(`opened ${escape(name)}: ${vertices ?? "\\d+"} vertices`);
const refusedLog = (name) => new RegExp(`cannot open ${escape(name)}: `, "i");

const isRed = (image, i) => image.rgba[i] >= 180 && image.rgba[i + 1] <= 90 && image.rgba[i + 2] <= 90;

/** Pixels of an error colour (egui draws errors in red) below the top bar. */
function redPixels(image) {
    let count = 0;
    for (let i = image.width * 4 * 30; i < image.rgba.length; i += 4) {
        if (isRed(image, i)) count++;
    }
    return count;
}

// --- 1: start-up ---

testIn(EVERY_RUN, "1a the page starts with the bundled sample within seconds", { timeout: 120_000 }, async () => {
    await withApp(async (app) => {
        assert.ok(
            app.startSeconds <= START_LIMIT_S,
            `the app took ${app.startSeconds.toFixed(1)} s to start (limit ${START_LIMIT_S} s)`,
        );
        await app.waitForConsole(openedLog(SAMPLE.name, SAMPLE.vertices));
        await app.screenshot("01-start");
        // The browser is in the mode this run claims: a WebGPU adapter exactly in the webgpu run.
        const adapter = await app.page.evaluate(async () =>
            navigator.gpu ? (await navigator.gpu.requestAdapter()) !== null : false,
        );
        assert.equal(adapter, MODE === "webgpu", `navigator.gpu.requestAdapter() ${adapter ? "found" : "found no"} adapter in the ${MODE} run`);
        console.log(`e2e ${MODE}: started in ${app.startSeconds.toFixed(2)} s`);
    });
});

testIn(EVERY_RUN, "1b the API reports the sample and the engine backend", { timeout: 120_000 }, async () => {
    await withApp(async (app) => {
        const state = await app.state();
        assert.equal(state.model, SAMPLE.name, "state().model");
        assert.equal(state.vertices, SAMPLE.vertices, "state().vertices");
        assert.equal(state.faces, SAMPLE.faces, "state().faces");
        assert.equal(state.error, null, "state().error");
        assert.equal(typeof state.busy, "boolean", "state().busy");
        assert.equal(await app.backend(), MODES[MODE].backend, `backend() in the ${MODE} run`);
        // A whole case: every structure, and its lesson in the Lesson panel.
        assert.deepEqual(state.structures.structures.map((s) => s.name), SAMPLE.structures);
        assert.equal(state.tour.steps, SAMPLE.lesson.steps.length, "state().tour.steps");
        assert.ok(state.quiz !== null, "the sample has a quiz");
    });
});

testIn(EVERY_RUN, "1c the viewer opens the same sample case: its structures, tour, labels and quiz", { timeout: 120_000 }, async () => {
    await withApp(async (app) => {
        const texts = SAMPLE.lesson.labels.map((l) => l.text);
        const state = await app.stateWhen(
            (s) => s.structures?.structures.length === SAMPLE.structures.length && s.view.labels.length === texts.length,
            "the sample's structures and labels",
        );
        assert.equal(state.mode, "viewer");
        assert.equal(state.model, SAMPLE.name);
        assert.deepEqual(state.view.labels.map((l) => l.text).sort(), [...texts].sort());
        assert.equal(state.tour.steps, SAMPLE.lesson.steps.length);
        assert.ok(state.layout.lesson.start && state.layout.lesson.quiz, "the tour's and the quiz's buttons");
        await app.screenshot("01c-viewer-sample");
    }, { query: "?mode=viewer" });
});

testIn(EVERY_RUN, "1d the viewer names the sample's structures in the student's language", { timeout: 120_000 }, async () => {
    const names = JSON.parse(readFileSync(join(ROOT, "web/sample/abdomen_phantom_names.json"), "utf8"));
    for (const [lang, tag] of [["de", "de"], ["fr-CA,de", "fr"]]) {
        await withApp(async (app) => {
            const open = (s) => s.structures?.structures.length === SAMPLE.structures.length;
            const labelled = await app.stateWhen((s) => open(s) && s.view.labels.length === 4, "the sample and its labels");
            const want = SAMPLE.structures.map((n) => names[n][tag]);
            // The labels name their structures: in the reader's language too.
            assert.deepEqual(labelled.view.labels.map((l) => l.text).sort(), [...want].sort());
            const listed = () => app.page.locator("#case_structures li").allTextContents();
            // The list is written at the frame after the case opened.
            let items = await listed();
            for (let t = 0; t < 100 && !(items[0] ?? "").startsWith(want[0]); t++) {
                await new Promise((r) => setTimeout(r, 100));
                items = await listed();
            }
            assert.deepEqual(items.map((l) => l.split(",")[0]), want, `?lang=${lang}`);
            const label = await app.page.getAttribute("#meshsmooth_canvas", "aria-label");
            assert.match(label, new RegExp(`selected: ${want[0]}$`));
            // The API keeps the case's own names, with the others beside them.
            const state = await app.state();
            assert.deepEqual(state.structures.structures.map((s) => s.name), SAMPLE.structures);
            assert.equal(state.structures.structures[0].names[tag], want[0]);
            if (tag === "de") await app.screenshot("01d-viewer-sample-de");
        }, { query: `?mode=viewer&lang=${lang}` });
    }
});

// --- 2: privacy ---

testIn(WEBGPU_RUN, "2 every request the page makes goes to its own origin", { timeout: 120_000 }, async () => {
    await withApp(async (app) => {
        await app.waitForConsole(openedLog(SAMPLE.name));
        await app.page.waitForLoadState("networkidle");
        assert.ok(
            app.requests.some((url) => url.endsWith(".wasm")),
            `the page's requests were recorded from the first navigation (got ${app.requests.join(", ")})`,
        );
        assert.deepEqual(app.foreignRequests(), [], "requests outside the page's origin");
        console.log(`e2e ${MODE}: requests: ${app.requests.map((u) => new URL(u).pathname).join(" ")}`);
    });
    // A link that names a model elsewhere must not make the page fetch it.
    for (const model of ["http://example.invalid/scan.ply", "//example.invalid/scan.stl"]) {
        await withApp(
            async (app) => {
                await app.waitForConsole(openedLog(SAMPLE.name));
                await app.page.waitForLoadState("networkidle");
                assert.deepEqual(app.foreignRequests(), [], `requests outside the page's origin with ?model=${model}`);
            },
            { query: `?model=${encodeURIComponent(model)}` },
        );
    }
    // One of its own origin that is not there: index.html asked for it before the app started,
    // and the app names it with the server's answer.
    await withApp(
        async (app) => {
            const error = await app.page.waitForFunction(() => window.meshsmooth.state().error, null, { timeout: 60_000 });
            assert.match(await error.jsonValue(), /^Cannot open missing\.ply: .*the server answered 404/);
            assert.deepEqual(app.requests.filter((u) => new URL(u).pathname === "/missing.ply").length, 1, "asked for once");
        },
        { query: "?model=missing.ply" },
    );
});

// --- 3: the Open button and the file input ---

testIn(WEBGPU_RUN, "3 Open… opens the file chooser, and the chosen torus is loaded", { timeout: API_TIMEOUT }, async () => {
    await withApp(async (app) => {
        // Listen first: Playwright starts intercepting file choosers when the listener is added,
        // asynchronously; a click right after it sometimes opened a chooser nobody caught.
        const chooserOpened = app.page.waitForEvent("filechooser", { timeout: 30_000 });
        chooserOpened.catch(() => {}); // awaited below; a rejection before then is not unhandled
        // The button is drawn in the canvas: find it in a screenshot of the top bar (the first
        // flat-filled box from the left: the title and the hint are text, not boxes). The bar
        // ends above y = 25; below it, the Structures list's "Add files…" opens the chooser too.
        const topBarBoxes = (image) => flatBoxes(image, { y0: 0, y1: 25 });
        const image = await app.screenshotWhen("03-before-open", (i) => topBarBoxes(i).length > 0, "a button in the top bar");
        const button = topBarBoxes(image)[0];
        await app.page.mouse.click(button.x + button.width / 2, button.y + button.height / 2);
        const chooser = await chooserOpened.catch((e) => {
            throw new Error(
                `clicking the top bar's first button at (${button.x}, ${button.y}, ${button.width}x${button.height}) ` +
                    `opened no file chooser (${e.message}); see ${image.path}`,
            );
        });
        // Several files chosen together open as one case (the first opens, the others join it).
        assert.equal(chooser.isMultiple(), true, "the chooser takes several files");
        await chooser.setFiles(TORUS);
        const name = "synthetic_torus_R24_r8.ply";
        await app.waitForConsole(openedLog(name));
        await app.screenshot("03-torus-opened");
        await app.api();
        await app.page.waitForFunction((name) => window.meshsmooth.state().model === name, name, { timeout: 60_000 });
        const [state, expected] = await Promise.all([app.state(), cli.info(TORUS)]);
        assert.equal(state.error, null, "state().error");
        assert.equal(state.vertices, expected.vertices, "state().vertices");
        assert.equal(state.faces, expected.faces, "state().faces");
    });
});

// --- 4: loading through the API ---

testIn(WEBGPU_RUN, "4 loadMesh resolves with the CLI's info --json", { timeout: API_TIMEOUT }, async () => {
    await withApp(async (app) => {
        const [info, expected] = await Promise.all([
            app.loadMesh(readFileSync(SCALP), "fsaverage_head_scalp_mne.ply"),
            cli.info(SCALP),
        ]);
        const differences = jsonDifferences(info, expected, INFO_RTOL, { f32Keys: INFO_F32_KEYS });
        assert.deepEqual(differences, [], `loadMesh's info differs from \`meshsmooth info --json\`:\n${differences.join("\n")}`);
        const state = await app.state();
        assert.equal(state.model, "fsaverage_head_scalp_mne.ply", "state().model");
        assert.equal(state.vertices, expected.vertices, "state().vertices");
        assert.equal(state.faces, expected.faces, "state().faces");
        assert.equal(state.error, null, "state().error");
        await app.screenshot("04-scalp-loaded");
    });
});

// --- 5: smoothing and measures against the CLI ---

for (const [filter, params] of Object.entries(FILTER_CASES)) {
    testIn(EVERY_RUN, `5 ${filter}: metrics() equals the CLI's smooth --json for ${JSON.stringify(params)}`, { timeout: API_TIMEOUT }, async (t) => {
        const reference = cli.smooth(SCALP, join(tmp, `scalp-${filter}.ply`), filter, params);
        await withLoaded(SCALP, async (app) => {
            await app.setFilter(filter);
            await app.setParams(params);
            const metrics = await app.metrics();
            const state = await app.state();
            assert.equal(state.filter, filter, "state().filter");
            // The numbers must come from this mode's engine (the GPU engine falls back to the
            // CPU engine on an error: that would pass the comparison but test the wrong path).
            assert.equal(state.backend, MODE, "state().backend: the engine that computed metrics()");
            for (const [key, value] of Object.entries(params)) {
                // The engine may keep a parameter as f32: 0.3 reads back as 0.30000001192...
                assert.ok(
                    typeof state.params[key] === "number" && relativeDifference(state.params[key], value) <= 1e-6,
                    `state().params.${key} is ${JSON.stringify(state.params[key])}, expected ${value}`,
                );
            }
            const expected = (await reference).metrics;
            const { problems, differences } = metricDifferences(metrics, expected, METRIC_RTOL);
            const worst = Math.max(...Object.values(differences));
            t.diagnostic(`largest relative difference ${worst.toExponential(2)} (tolerance ${METRIC_RTOL})`);
            console.log(JSON.stringify({ e2e: "metrics-vs-cli", mode: MODE, filter, params, relative_differences: differences }));
            assert.deepEqual(problems, [], `metrics() differs from the CLI's (${MODE}):\n${problems.join("\n")}`);
            if (filter === "hc") {
                await app.screenshot("05-scalp-smoothed-hc");
            }
        });
    });
}

testIn(WEBGPU_RUN, "5 setFilter and setParams refuse bad values with the engine's message", { timeout: API_TIMEOUT }, async () => {
    const rangeMessage = await cli.refusal("smooth", SCALP, "-o", join(tmp, "refused.ply"), "--iterations", "1000");
    await withApp(async (app) => {
        const unknown = await app.attempt("setFilter", "bilateral");
        assert.equal(unknown.ok, false, "setFilter('bilateral') was accepted");
        assert.ok(unknown.isError, `setFilter('bilateral') threw a non-Error: ${unknown.message}`);
        assert.match(unknown.message, /bilateral/, "the message names the unknown filter");

        const before = await app.state();
        const range = await app.attempt("setParams", { iterations: 1000 });
        assert.equal(range.ok, false, "setParams({iterations: 1000}) was accepted");
        assert.ok(range.isError, `setParams threw a non-Error: ${range.message}`);
        assert.ok(
            range.message.includes(rangeMessage),
            `setParams({iterations: 1000}) threw "${range.message}"; expected the engine's message "${rangeMessage}"`,
        );
        const afterRefusal = await app.state();
        assert.deepEqual(afterRefusal.params, before.params, "a refused value changed state().params");
    });
});

// --- 6: exports ---

testIn(EVERY_RUN, "6 every export format reads back with the CLI; the GLB is valid glTF", { timeout: API_TIMEOUT }, async (t) => {
    const expected = await cli.info(SCALP);
    await withLoaded(SCALP, async (app) => {
        await app.setFilter("hc");
        await app.metrics();
        for (const format of ["glb", "stl", "ply", "obj"]) {
            await t.test(format, async () => {
                const bytes = await app.exportMesh(format);
                assert.ok(bytes.length > 0, `exportMesh('${format}') is empty`);
                const file = join(OUT, `06-scalp-export.${format}`);
                writeFileSync(file, bytes);
                const info = await cli.info(file);
                // An STL stores each triangle's corners: the CLI welds them back, so the vertex
                // count equals the indexed mesh's again.
                assert.equal(info.vertices, expected.vertices, `vertices of the exported ${format} (${file})`);
                assert.equal(info.faces, expected.faces, `faces of the exported ${format} (${file})`);
                assert.equal(info.closed, expected.closed, `closed, exported ${format}`);
                if (format === "glb") {
                    const report = await gltfValidator.validateBytes(new Uint8Array(bytes), { uri: "export.glb", format: "glb" });
                    const errors = report.issues.messages.filter((m) => m.severity === 0);
                    assert.equal(
                        report.issues.numErrors,
                        0,
                        `glTF-Validator found errors in ${file}:\n${errors.map((m) => `${m.code} ${m.pointer ?? ""}: ${m.message}`).join("\n")}`,
                    );
                    t.diagnostic(`glTF-Validator: ${report.issues.numWarnings} warnings, ${report.issues.numInfos} infos`);
                }
            });
        }
    });
});

testIn(WEBGPU_RUN, "6 no export carries the input STL's header text (a patient name)", { timeout: API_TIMEOUT }, async (t) => {
    const stl = join(tmp, "jane.stl");
    await cli.cli("convert", TORUS, stl);
    const bytes = readFileSync(stl);
    bytes.fill(0x20, 0, 80);
    bytes.write("patient: Jane Doe, born 1970-01-01", 0, "latin1");
    const expected = await cli.info(TORUS);
    await withApp(async (app) => {
        const info = await app.loadMesh(bytes, "scan.stl");
        assert.equal(info.vertices, expected.vertices, "the STL's corners are welded on load");
        for (const format of ["stl", "glb", "ply", "obj"]) {
            await t.test(format, async () => {
                const exported = await app.exportMesh(format);
                writeFileSync(join(OUT, `06-jane-export.${format}`), exported);
                assert.equal(exported.includes("Jane Doe"), false, `the exported ${format} contains "Jane Doe"`);
                if (format === "stl") {
                    const header = exported.subarray(0, 80).toString("latin1");
                    assert.equal(/patient/i.test(header), false, `the STL header was copied: "${header.trim()}"`);
                }
            });
        }
    });
});

// --- 7: a file that cannot be read ---

const BROKEN = Buffer.from("solid\x00\x01\x02\x03\x04", "latin1"); // 10 bytes: no STL

testIn(WEBGPU_RUN, "7a a bad file dropped on the page is reported on screen and the sample stays", { timeout: 120_000 }, async () => {
    await withApp(async (app) => {
        await app.waitForConsole(openedLog(SAMPLE.name));
        const before = await app.screenshot("07-before-drop");
        const redBefore = redPixels(before);
        await app.dropFile(BROKEN, "broken.stl");
        const warning = await app.waitForConsole(refusedLog("broken.stl"));
        assert.equal(
            app.console.some((line) => openedLog("broken.stl").test(line.text)),
            false,
            "the app claims to have opened broken.stl",
        );
        const shown = await app.screenshotWhen(
            "07-drop-error",
            (image) => redPixels(image) > redBefore + 200,
            "the error text in red",
        );
        console.log(`e2e ${MODE}: drop reported: ${warning.text}; red pixels ${redBefore} -> ${redPixels(shown)}`);
    });
});

testIn(WEBGPU_RUN, "7b after a bad drop state() names the file and keeps the model; loadMesh of garbage rejects", { timeout: API_TIMEOUT }, async () => {
    const brokenFile = join(tmp, "broken.stl");
    writeFileSync(brokenFile, BROKEN);
    const garbage = Buffer.from("hello, this is not a mesh\n");
    const garbageFile = join(tmp, "garbage.ply");
    writeFileSync(garbageFile, garbage);
    // The CLI prefixes its message with the path it was given; the engine's reason follows.
    const brokenReason = (await cli.refusal("info", brokenFile)).replace(`${brokenFile}: `, "");
    const garbageReason = (await cli.refusal("info", garbageFile)).replace(`${garbageFile}: `, "");

    await withApp(async (app) => {
        await app.api();
        await app.dropFile(BROKEN, "broken.stl");
        await app.page.waitForFunction(() => window.meshsmooth.state().error !== null, null, { timeout: 60_000 });
        const state = await app.state();
        assert.match(state.error, /broken\.stl/, "state().error names the file");
        assert.ok(state.error.includes(brokenReason), `state().error "${state.error}" lacks the engine's reason "${brokenReason}"`);
        assert.equal(state.model, SAMPLE.name, "the previous model stays");
        assert.equal(state.vertices, SAMPLE.vertices, "the previous model's vertices stay");

        const result = await app.attemptLoad(garbage, "garbage.ply");
        assert.equal(result.ok, false, "loadMesh of garbage resolved");
        assert.ok(result.isError, `loadMesh rejected with a non-Error: ${result.message}`);
        assert.ok(
            result.message.includes(garbageReason),
            `loadMesh rejected with "${result.message}"; expected the engine's message "${garbageReason}"`,
        );
        assert.equal((await app.state()).model, SAMPLE.name, "the previous model stays after a rejected loadMesh");
    });
});

// --- 8: the 3D view ---

/**
 * Whether the 3D view (between the side panels: 25 % to 70 % of the width, below the top bar,
 * left of the legend) shows something: at least 5 % of its pixels differ from its most common
 * colour (the background) and it has many colours (shading or colour-coding). A mesh need not
 * cover the very centre (the bent tube's bend leaves it empty).
 */
function middleShowsSomething(image) {
    const box = {
        x0: Math.round(image.width * 0.25),
        x1: Math.round(image.width * 0.6),
        y0: Math.round(image.height * 0.1),
        y1: Math.round(image.height * 0.9),
    };
    const histogram = colourHistogram(image, box);
    const total = (box.x1 - box.x0) * (box.y1 - box.y0);
    return histogram.length >= 32 && 1 - histogram[0][1] / total >= 0.05;
}

testIn(EVERY_RUN, "8 the 3D view draws the mesh: the sample at start, the scalp smoothed and colour-coded", { timeout: API_TIMEOUT }, async () => {
    await withApp(async (app) => {
        await app.screenshotWhen("08-view-sample", middleShowsSomething, "the sample mesh in the middle of the page", 30_000);
        await app.loadMesh(readFileSync(SCALP), "fsaverage_head_scalp_mne.ply");
        await app.setFilter("hc");
        await app.setParams(FILTER_CASES.hc);
        await app.metrics();
        const image = await app.screenshotWhen("08-view-scalp-hc", middleShowsSomething, "the smoothed scalp in the middle of the page", 30_000);
        // The colour legend has a strip of its own right of the view, where no framing or
        // turn of the model reaches: the top of its bar (viridis yellow) lies past the view's
        // right edge.
        const { view } = await app.state();
        const scale = image.width / (await app.page.evaluate(() => innerWidth));
        const right = Math.ceil((view.x + view.width) * scale);
        let yellowBeyond = 0;
        for (let y = Math.floor(view.y * scale); y < Math.min(image.height, (view.y + view.height) * scale); y++) {
            for (let x = right; x < image.width; x++) {
                const c = colourAt(image, x, y);
                const [r, g, b] = [c >> 16, (c >> 8) & 0xff, c & 0xff];
                yellowBeyond += r > 220 && g > 200 && b < 90 ? 1 : 0;
            }
        }
        assert.ok(yellowBeyond >= 30, `the legend's bar right of the view (x >= ${right}): ${yellowBeyond} yellow pixels`);
    });
});

// --- 10: a large mesh opens in a worker ---

testIn(CPU_RUN, "10 the 206k-vertex mesh opens in a worker: the page keeps drawing, state() shows the stages, the old model stays meanwhile (stage times printed)", { timeout: API_TIMEOUT }, async () => {
    await withApp(async (app) => {
        await app.api();
        const before = (await app.state()).model;
        const name = "seg_mni152_gm_plus_wm_p0.5_1mm.ply";
        const run = await app.page.evaluate(
            async ([base64, name]) => {
                const text = atob(base64);
                const bytes = new Uint8Array(text.length);
                for (let i = 0; i < text.length; i++) {
                    bytes[i] = text.charCodeAt(i);
                }
                // What state() says at every animation frame while a worker opens the mesh.
                const seen = [];
                // Animation frame times: while opening, and for a while after (the new model
                // goes to the GPU and is smoothed then).
                const frames = [];
                let running = true;
                const look = (t) => {
                    frames.push(t);
                    const s = window.meshsmooth.state();
                    if (s.loading) seen.push({ stage: s.loading.stage, doing: s.loading.doing, model: s.model });
                    if (running) requestAnimationFrame(look);
                };
                requestAnimationFrame(look);
                const start = performance.now();
                const info = await window.meshsmooth.loadMesh(bytes, name);
                const opened = performance.now();
                const seconds = (opened - start) / 1000;
                const after = window.meshsmooth.state();
                await new Promise((resolve) => setTimeout(resolve, 3000));
                running = false;
                const gaps = (from, to) => {
                    const t = frames.filter((f) => f >= from && f <= to);
                    return t.slice(1).map((f, i) => f - t[i]);
                };
                return { info, seen, seconds, after, gaps: [gaps(start, opened), gaps(opened, opened + 3000)] };
            },
            [readFileSync(BRAIN).toString("base64"), name],
        );
        assert.equal(run.info.vertices, 206512);
        assert.equal(run.after.model, name);
        assert.equal(run.after.loading, null, "state().loading clears once the mesh is open");
        // The page drew on while the worker opened the mesh, telling how far it got.
        assert.ok(run.seen.length >= 3, `only ${run.seen.length} frames while the mesh opened`);
        const stages = [...new Set(run.seen.map((s) => s.stage))];
        assert.deepEqual(stages, [...stages].sort((a, b) => a - b), "stages go forward");
        assert.ok(run.seen.some((s) => s.doing !== "waiting for a worker"), `no stage shown: ${JSON.stringify(stages)}`);
        for (const s of run.seen) {
            assert.equal(s.model, before, "the previous model stays open while the new one opens");
            assert.ok(s.doing.length > 0);
        }
        const stageMs = run.after.open_stages;
        const perStage = Object.fromEntries(stageMs.map((s) => [s.doing, s.ms]));
        assert.deepEqual(
            Object.keys(perStage),
            ["reading the file", "building the topology", "checking the mesh", "measuring the original"],
            `every stage is timed: ${JSON.stringify(stageMs)}`,
        );
        const line = {
            bench: "open-large-mesh",
            mode: MODE,
            backend: await app.backend(),
            mesh: name,
            seconds: run.seconds,
            stage_ms: Object.fromEntries(Object.entries(perStage).map(([k, v]) => [k, Math.round(v)])),
            frames_seen: run.seen.length,
            longest_frame_ms_opening: Math.round(Math.max(0, ...run.gaps[0])),
            longest_frame_ms_after: Math.round(Math.max(0, ...run.gaps[1])),
            stages_seen_between_frames: run.seen.map((s) => s.doing).filter((d, i, a) => a.indexOf(d) === i),
        };
        console.log(JSON.stringify(line));
        appendFileSync(join(E2E_OUT, "bench.json"), JSON.stringify(line) + "\n");
        // The view follows: the new mesh drawn and colour-coded once measured, and no error
        // text (red) over it.
        await app.metrics();
        const image = await app.screenshotWhen("10-brain-opened", middleShowsSomething, "the opened mesh in the middle of the page", 60_000);
        assert.ok(redPixels(image) < 50, `red (error) text over the view after opening: ${redPixels(image)} red pixels`);
    });
});
