// End-to-end tests of the guidance features: suggestions, quality graphs and the gallery (the
// frame rate while they compute is a benchmark: speed.bench.mjs).
import assert from "node:assert/strict";
import { mkdtempSync, readFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";

import * as cli from "./lib/cli.mjs";
import { jsonDifferences, metricDifferences } from "./lib/compare.mjs";
import { ROOT, meshPath } from "./lib/paths.mjs";
import { CPU_RUN, EVERY_RUN, WEBGPU_RUN, appSuite, testIn } from "./lib/suite.mjs";

const { MODE, withApp } = appSuite({ beforeAll: () => cli.requireCli() });
const TUBE = join(ROOT, "tests/data/bent_tube_staircase.ply");
/** A small staircase vessel, opened in place of the page's sample case. */
const openTube = (app) => app.loadMesh(readFileSync(TUBE), "bent_tube_staircase.ply");
/** The background searches run the same Rust code on the CPU in both modes (wasm: one thread,
 * so f64 sums may differ in order from the native CLI's: 1e-9 relative allows that). */
const RTOL = 1e-9;
/** metrics() comes from the page's engine: on WebGPU its f32 WGSL (see app.test.mjs, METRIC_RTOL). */
const METRIC_RTOL = { cpu: 1e-9, webgpu: 1e-4 }[MODE];
const TIMEOUT = 10 * 60_000;

const state = (app) => app.page.evaluate(() => window.meshsmooth.state());

/** The page x of `value` in a graph strip of `state().layout.graphs`. */
function xOfValue(strip, value) {
    return strip.x + (strip.width * (value - strip.x0)) / (strip.x1 - strip.x0);
}

function assertClose(actual, expected, what) {
    const diffs = jsonDifferences(actual, expected, RTOL);
    assert.deepEqual(diffs, [], `${what}: app and CLI differ`);
}

testIn(EVERY_RUN, "G1 suggest() equals the CLI's suggest --json for the same mesh, filter and tau", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        await openTube(app);
        await app.call("setFilter", "laplace");
        for (const search of ["local", "grid"]) {
            const got = await app.call("suggest", { tau: 0.6, search });
            const want = await cli.cliJson("suggest", TUBE, "--filter", "laplace", "--tau", "0.6", "--search", search, "--json");
            assert.deepEqual(got.params, want.params, `${search}: parameters`);
            assert.equal(got.evaluations, want.evaluations, `${search}: evaluations`);
            assertClose(got.terms, want.terms, `${search}: terms`);
            assertClose(got.score, want.score, `${search}: score`);
            console.log(`suggest ${search}: ${JSON.stringify(got.params)} in ${got.seconds.toFixed(2)} s (CLI ${want.seconds.toFixed(2)} s)`);
        }
        assert.equal((await state(app)).tau, 0.6, "suggest() sets tau");
        // The suggestion is shown, not applied, until the user takes it (key A).
        const suggested = (await state(app)).guidance.suggestion.params;
        assert.notDeepEqual((await state(app)).params, suggested);
        // A click on the view gives the canvas the keyboard.
        const { view } = await state(app);
        await app.page.mouse.click(view.x + view.width / 2, view.y + view.height / 2);
        await app.page.keyboard.press("a");
        await app.page.waitForFunction((p) => JSON.stringify(window.meshsmooth.state().params) === JSON.stringify(p), suggested);
        const metrics = await app.call("metrics");
        // ...and the measures are those of the CLI smoothing with the suggested parameters.
        const given = Object.fromEntries(Object.entries(suggested).filter(([, v]) => v !== null));
        const out = join(mkdtempSync(join(tmpdir(), "meshsmooth-g1-")), "s.ply");
        const reference = await cli.smooth(TUBE, out, "laplace", given);
        // The CLI's score is for its default tau 0.5; the page's for the tau just set (0.6).
        const { score: _a, ...measured } = metrics;
        const { score: _b, ...expected } = reference.metrics;
        assert.deepEqual(metricDifferences(measured, expected, METRIC_RTOL).problems, []);
    });
});

testIn(WEBGPU_RUN, "G1b on WebGPU with ?guidance=gpu, suggest() runs on the GPU engine and equals the CLI's", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        await openTube(app);
        await app.call("setFilter", "laplace");
        for (const search of ["local", "grid"]) {
            const got = await app.call("suggest", { tau: 0.6, search });
            assert.equal((await state(app)).guidance.engine, "webgpu", "the background ran on the GPU");
            const want = await cli.cliJson("suggest", TUBE, "--filter", "laplace", "--tau", "0.6", "--search", search, "--json");
            assert.deepEqual(got.params, want.params, `${search}: parameters`);
            // f32 WGSL against the CLI's f64 sums, as metrics() on WebGPU.
            assert.deepEqual(jsonDifferences(got.terms, want.terms, 1e-4), [], `${search}: terms`);
            console.log(`GPU suggest ${search}: ${JSON.stringify(got.params)}, ${got.evaluations} sets in ${got.seconds.toFixed(2)} s (CLI on the CPU: ${want.evaluations} sets, ${want.seconds.toFixed(2)} s)`);
        }
    }, { query: "?guidance=gpu" });
});

testIn(WEBGPU_RUN, "G2 sweep() equals the CLI's sweep --json; a click in a graph sets the parameter", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        await openTube(app);
        const got = await app.call("sweep");
        // Around the parameters the page has (a surface opened keeps those the author was trying).
        const { filter, params } = await state(app);
        assert.equal(filter, "hc", "the sample's filter, kept");
        const around = ["alpha", "beta", "iterations"].flatMap((k) => [`--${k}`, String(params[k])]);
        const want = await cli.cliJson("sweep", TUBE, "--filter", filter, ...around, "--json");
        assert.deepEqual(got.current, want.current);
        assert.equal(got.curves.length, 3);
        for (const [k, curve] of got.curves.entries()) {
            assert.equal(curve.param, want.curves[k].param);
            assert.equal(curve.best, want.curves[k].best, `${curve.param}: lowest S`);
            assert.deepEqual(curve.samples.map((s) => s.value), want.curves[k].samples.map((s) => s.value));
            assertClose(curve.samples, want.curves[k].samples, `${curve.param} samples`);
        }
        // The graphs may finish between frames: the page draws them in its next.
        const before = await app.stateWhen((s) => s.layout.graphs.length > 0, "the graphs drawn");
        const shot = await app.screenshot("guidance-graphs");
        console.log(`graphs screenshot: ${shot.path}`);
        // A click in the iterations column's error strip, at another count than the current
        // one (from where the page says it drew the strip), sets the iterations to it.
        const target = before.params.iterations === 20 ? 30 : 20;
        const column = before.layout.graphs.find((c) => c.param === "iterations");
        assert.ok(column, `state().layout.graphs: ${JSON.stringify(before.layout.graphs)}`);
        assert.equal(column.strips.length, 4);
        const strip = column.strips[1];
        await app.page.mouse.click(xOfValue(strip, target), strip.y + strip.height / 2);
        await app.page.waitForFunction(
            (it) => window.meshsmooth.state().params.iterations !== it,
            before.params.iterations,
            { timeout: 10_000 },
        );
        const after = await state(app);
        assert.equal(after.params.alpha, before.params.alpha, "only the clicked parameter changes");
        assert.equal(after.params.iterations, target);
        await app.screenshotWhen(
            "guidance-graphs-after-click",
            () => true,
            "graphs",
        );
        // The graphs follow: new ones for the new value.
        const again = await app.call("sweep");
        assert.equal(again.current.iterations, after.params.iterations);
    });
});

testIn(WEBGPU_RUN, "G3 the gallery shows five results; a click on one takes its tau and parameters", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        await openTube(app);
        await app.call("setFilter", "laplace");
        const picks = await app.call("gallery");
        assert.deepEqual(picks.map((p) => p.tau), [0.1, 0.3, 0.5, 0.7, 0.9]);
        for (const p of picks) {
            const want = await cli.cliJson("suggest", TUBE, "--filter", "laplace", "--tau", String(p.tau), "--search", "local", "--json");
            assert.deepEqual(p.params, want.params, `tau ${p.tau}`);
        }
        // Pictures are drawn one per frame after the gallery is made.
        await app.page.waitForTimeout(1500);
        const shot = await app.screenshot("guidance-gallery");
        console.log(`gallery screenshot: ${shot.path}`);
        // Laplace shrinks: the cards' volume changes are signed, the terms hold their size.
        for (const p of picks) {
            assert.ok(p.volume_change <= 0, `tau ${p.tau}: volume change ${p.volume_change}`);
            assert.ok(Math.abs(Math.abs(p.volume_change) - p.terms.volume_change) < 1e-12, `tau ${p.tau}`);
        }
        // A click on each card, where the page says it drew it, takes that card's tau and
        // parameters; the first (tau 0.1) leaves this mesh unchanged (no iterations).
        const { layout } = await state(app);
        assert.equal(layout.gallery.length, picks.length, `state().layout.gallery: ${JSON.stringify(layout.gallery)}`);
        for (const k of [0, 2, 1]) {
            const card = layout.gallery[k];
            assert.ok(card.width > 50 && card.height > 50, `card ${k} is visible: ${JSON.stringify(card)}`);
            await app.page.mouse.click(card.x + card.width / 2, card.y + card.height / 2);
            await app.page.waitForFunction(
                (p) => JSON.stringify(window.meshsmooth.state().params) === JSON.stringify(p),
                picks[k].params,
                { timeout: 10_000 },
            );
            assert.equal((await state(app)).tau, picks[k].tau);
        }
    });
});

testIn(CPU_RUN, "G4 Suggest all takes the view worker too; a change of parameters meanwhile takes it back at once, and every structure still gets the CLI's suggestion", { timeout: TIMEOUT }, async () => {
    const atlas = meshPath("labelmaps/JHU-WhiteMatter-labels-1mm.nii.gz");
    await withApp(async (app) => {
        await app.loadMesh(readFileSync(atlas), "JHU-WhiteMatter-labels-1mm.nii.gz");
        await app.metrics();
        const running = app.call("suggestAll", { tau: 0.5, search: "learned" });
        running.catch(() => {});
        await app.stateWhen((s) => s.suggest_all?.work_done > 0, "some structures done");
        // The view's result while both workers do structures: the view worker is restarted for
        // it (should it be free at that moment, the next change finds it busy).
        let restarts = 0;
        for (let iterations = 11; iterations < 20 && restarts === 0; iterations += 1) {
            const started = Date.now();
            await app.setParams({ iterations });
            const metrics = await app.metrics();
            assert.ok(metrics.score >= 0, JSON.stringify(metrics));
            const s = await state(app);
            restarts = s.cpu_engine.restarts;
            console.log(`G4: the view's result ${((Date.now() - started) / 1000).toFixed(2)} s after the change (view worker restarts: ${restarts}; Suggest all ${s.suggest_all.done} of 48)`);
            if (s.suggest_all.done === 48) break;
        }
        assert.ok(restarts >= 1, "the view worker was taken back from a structure");
        const all = await running;
        assert.deepEqual([all.done, all.total, all.cancelled], [48, 48, false]);
        const out = join(mkdtempSync(join(tmpdir(), "meshsmooth-g4-")), "jhu-case.glb");
        const built = await cli.cliJson("case", "build", atlas, "--search", "learned", "-o", out, "--json");
        all.structures.forEach((s, i) => assert.deepEqual(s.params, built.structures[i].params, `structure ${i}: the CLI's suggestion`));
    });
});
