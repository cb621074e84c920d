// End-to-end tests of the mouse interactions over the 3D view, in one mode per run (see
// app.test.mjs and run.sh): the window/level-style right drag that drives two smoothing
// parameters, and the weight brush (P, then a left drag) that locks vertices. Screenshots go to
// target/e2e/<mode>/.
//
//   bash tests/e2e/run.sh --test-name-pattern='^interact'
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";

import { brushOn, drag, frames, settled, viewCentre } from "./lib/input.mjs";
import { meshPath } from "./lib/paths.mjs";
import { EVERY_RUN, WEBGPU_RUN, appSuite, testIn } from "./lib/suite.mjs";

const { MODE, withApp } = appSuite();

const SPHERE = meshPath("synthetic/synthetic_sphere_r20.ply");

/** src/view/param_drag.rs: a parameter's whole range over this many points of travel. */
const POINTS_PER_RANGE = 400;

const API_TIMEOUT = 5 * 60_000;

testIn(WEBGPU_RUN, "interact 1 a right drag drives the filter's two parameters: right and up increase", { timeout: API_TIMEOUT }, async () => {
    await withApp(async (app) => {
        await app.setFilter("hc");
        await app.setParams({ alpha: 0.1, beta: 0.5, iterations: 10 });
        const before = await settled(app);
        const centre = await viewCentre(app);
        // HC's default pair: beta across, iterations up. 80 points right: +0.2 of beta's [0, 1];
        // 80 points up: +10 of [0, 50] iterations.
        await drag(app, "right", centre, { x: 80, y: -80 }, {
            during: async (app) => {
                await app.screenshot("interact-1-right-drag");
            },
        });
        const hc = await settled(app);
        assert.equal(hc.state.params.beta, 0.5 + 80 / POINTS_PER_RANGE);
        assert.equal(hc.state.params.iterations, 10 + (80 / POINTS_PER_RANGE) * 50);
        assert.equal(hc.state.params.alpha, 0.1, "alpha is not on either axis");
        assert.notEqual(hc.metrics.score, before.metrics.score, "the measures follow");
        console.log(`interact ${MODE}: HC right drag: ${JSON.stringify(before.state.params)} -> ${JSON.stringify(hc.state.params)}`);

        // Laplace: lambda across, iterations up; left and down decrease, clamped at 0.
        await app.setFilter("laplace");
        await app.setParams({ lambda: 0.5, iterations: 10 });
        await settled(app);
        await drag(app, "right", centre, { x: -40, y: 200 });
        const laplace = await settled(app);
        assert.equal(laplace.state.params.lambda, 0.4);
        assert.equal(laplace.state.params.iterations, 0);
        assert.equal(laplace.metrics.mean_error, 0, "0 iterations leave the mesh as it was");

        // Taubin: lambda stops short of -mu.
        await app.setFilter("taubin");
        await app.setParams({ lambda: 0.5, mu: -0.53, iterations: 10 });
        await settled(app);
        await drag(app, "right", centre, { x: 300, y: 0 });
        const taubin = await settled(app);
        assert.equal(taubin.state.params.lambda, 0.52);
        assert.ok(taubin.state.params.mu < -taubin.state.params.lambda);
    });
});

testIn(EVERY_RUN, "interact 2 a brush stroke locks the vertices under it: they stay, the measures change", { timeout: API_TIMEOUT }, async () => {
    await withApp(async (app) => {
        await app.loadMesh(readFileSync(SPHERE), "synthetic_sphere_r20.ply");
        await app.setFilter("laplace");
        await app.setParams({ lambda: 0.8, iterations: 30 });
        const free = await settled(app);
        assert.equal(free.state.weights, null, "nothing painted yet");

        // P turns the brush on (keys go to the canvas once it has been clicked).
        const centre = await viewCentre(app);
        await brushOn(app, centre);
        await frames(app);
        let state = await app.state();
        assert.equal(state.brush.on, true, "P turns the weight brush on");

        // A stroke across the middle of the sphere (r = 20 mm) with the 5 mm brush.
        const stroke = Math.min(240, centre.view.width / 3);
        await drag(app, "left", { x: centre.x - stroke / 2, y: centre.y }, { x: stroke, y: 0 }, { steps: 16 });
        const painted = await settled(app);
        const w = painted.state.weights;
        assert.ok(w && w.locked > 50, `the stroke locked vertices: ${JSON.stringify(w)}`);
        assert.equal(w.min, 0);
        assert.ok(w.painted < free.state.vertices / 2, `a stroke, not the whole sphere: ${JSON.stringify(w)}`);
        assert.notEqual(painted.metrics.mean_error, free.metrics.mean_error, "locked vertices change the result");
        assert.ok(painted.metrics.volume_change > free.metrics.volume_change, "less shrinkage with vertices locked");
        console.log(
            `interact ${MODE}: stroke locked ${w.locked} of ${painted.state.vertices} vertices (${w.painted} painted); ` +
                `volume change ${free.metrics.volume_change.toFixed(5)} -> ${painted.metrics.volume_change.toFixed(5)}, ` +
                `pick ${state.brush.pick_ms?.toFixed(2)} ms`,
        );
        // The view shows the weights: the locked blue of the weight colouring (33, 102, 172,
        // shaded) covers part of the view.
        await app.page.mouse.move(centre.x + stroke, centre.y - stroke / 2);
        const image = await app.screenshotWhen(
            "interact-2-brush-stroke",
            (image) => bluePixels(image) > 500,
            "the painted stroke in the weights colouring",
        );
        console.log(`interact ${MODE}: ${bluePixels(image)} blue pixels in ${image.path}`);

        // Clearing gives the unpainted result back exactly.
        await app.call("clearWeights");
        const cleared = await settled(app);
        assert.equal(cleared.state.weights, null);
        assert.deepEqual(cleared.metrics, free.metrics);
    });
});

/** Pixels close to the weight colouring's locked blue, lit anywhere from dim to bright. */
function bluePixels(image) {
    let count = 0;
    for (let i = 0; i < image.rgba.length; i += 4) {
        const [r, g, b] = [image.rgba[i], image.rgba[i + 1], image.rgba[i + 2]];
        if (b > 90 && b > r + 50 && b > g + 25) count++;
    }
    return count;
}
