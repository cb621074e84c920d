// End-to-end tests of the viewer (`?mode=viewer`): a student opens a case glTF, shows, hides and
// isolates its structures in the panel by mouse, cuts them with the clipping plane, looks from
// the standard sides, slides back to the segmentation and has a structure named under the
// pointer; the editing controls are absent, their shortcuts do nothing.
//
//   E2E_MODE=webgpu|cpu node --test tests/e2e/viewer.test.mjs   (tests/e2e/run.sh runs both)
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import { join } from "node:path";

import * as cli from "./lib/cli.mjs";
import { E2E_OUT, meshPath } from "./lib/paths.mjs";
import { EVERY_RUN, appSuite, testIn } from "./lib/suite.mjs";

const { MODE, withApp } = appSuite({ beforeAll: () => cli.requireCli() });

const PHANTOM_NRRD = meshPath("labelmaps/case_phantom_shared.seg.nrrd");
const TIMEOUT = 240_000;

/**
 * The pixels of the 3D view that show a surface: unlike the background (read at the view's
 * top-right corner), away from the messages at its top and its tools at its bottom. Returns
 * their count and mean x (CSS pixels).
 */
function drawn(image, view) {
    const at = (x, y) => {
        const i = (Math.round(y) * image.width + Math.round(x)) * 4;
        return [image.rgba[i], image.rgba[i + 1], image.rgba[i + 2]];
    };
    const background = at(view.x + view.width - 4, view.y + 4);
    let count = 0;
    let sumX = 0;
    for (let y = Math.round(view.y + 60); y < Math.round(view.y + view.height - 40); y++) {
        for (let x = Math.round(view.x); x < Math.round(view.x + view.width); x++) {
            const c = at(x, y);
            if (c.some((v, k) => Math.abs(v - background[k]) > 24)) {
                count++;
                sumX += x;
            }
        }
    }
    return { count, meanX: count ? sumX / count : NaN };
}

/** Pixels of the view (away from its messages and tools) that differ between two images. */
function changedPixels(a, b, view) {
    let count = 0;
    for (let y = Math.round(view.y + 60); y < Math.round(view.y + view.height - 40); y++) {
        for (let x = Math.round(view.x); x < Math.round(view.x + view.width); x++) {
            const i = (y * a.width + x) * 4;
            if ([0, 1, 2].some((k) => Math.abs(a.rgba[i + k] - b.rgba[i + k]) > 16)) count++;
        }
    }
    return count;
}

/** Pixels of the view whose colour passes `test(r, g, b)`: their count and mean position. */
function pixelsWhere(image, view, test) {
    let [count, sumX, sumY] = [0, 0, 0];
    for (let y = Math.round(view.y + 60); y < Math.round(view.y + view.height - 40); y++) {
        for (let x = Math.round(view.x); x < Math.round(view.x + view.width); x++) {
            const i = (y * image.width + x) * 4;
            if (test(image.rgba[i], image.rgba[i + 1], image.rgba[i + 2])) {
                count++;
                sumX += x;
                sumY += y;
            }
        }
    }
    return { count, meanX: sumX / count, meanY: sumY / count };
}

testIn(EVERY_RUN, "V1 the viewer reads a case: its structures by mouse, the clipping plane, the standard views, no editing", { timeout: TIMEOUT }, async () => {
    const file = join(E2E_OUT, MODE, "V1-phantom-case.glb");
    await cli.cliJson("case", "build", PHANTOM_NRRD, "--search", "local", "-o", file, "--json");
    await withApp(async (app) => {
        const opened = await app.loadMesh(readFileSync(file), "V1-phantom-case.glb", "loadCase");
        assert.deepEqual(opened.structures.map((s) => s.name), ["liver", "portal_vein", "tumor", "right_kidney"]);
        let state = await app.stateWhen((s) => s.layout.structures.length === 4 && s.loading === null, "the case's four rows");
        assert.equal(state.mode, "viewer");
        assert.deepEqual(state.layout.graphs, [], "no quality graphs");
        const view = state.view;
        const rows = state.layout.structures;
        const centre = (r) => [r.x + r.width / 2, r.y + r.height / 2];
        const click = (r) => app.page.mouse.click(...centre(r));
        const visible = (s) => s.structures.structures.map((x) => x.visible);

        // Shortcuts that edit do nothing here: 1 would pick Laplace.
        const filter = state.filter;
        await app.page.mouse.click(view.x + view.width / 2, view.y + 20);
        await app.page.keyboard.press("1");
        assert.equal((await app.state()).filter, filter, "the structure's filter stays");

        const all = drawn(await app.screenshot("V1-viewer-case"), view);
        assert.ok(all.count > 5000, `the case is drawn: ${all.count} pixels`);

        // S shows the kidney alone: fewer pixels; again, all of them. The view keeps the whole
        // case's middle; the phantom's kidney lies medial to its liver (centroid's x 20 mm
        // against the liver's 64: RAS, so towards the patient's left of the case's middle).
        // From the front the patient's left is on the screen's right; from behind, on its left.
        await click(rows[3].solo);
        await app.stateWhen((s) => visible(s).join() === "false,false,false,true", "the kidney alone");
        await app.call("setView", { from: "A" });
        const front = await app.screenshotWhen("V1-kidney-from-the-front", (i) => drawn(i, view).count > 500, "the kidney");
        await app.call("setView", { from: "P" });
        const back = await app.screenshotWhen("V1-kidney-from-behind", (i) => drawn(i, view).count > 500, "the kidney");
        const [f, b] = [drawn(front, view), drawn(back, view)];
        const middle = view.x + view.width / 2;
        assert.ok(f.meanX > middle && b.meanX < middle, `the kidney right from the front (${f.meanX}), left from behind (${b.meanX}) of ${middle}`);
        assert.ok(f.count < all.count, `alone, less is drawn: ${f.count} of ${all.count}`);
        await click(rows[3].solo);
        await app.stateWhen((s) => visible(s).every((v) => v), "every structure shown again");
        // The box hides one.
        await click(rows[0].visible);
        await app.stateWhen((s) => visible(s).join() === "false,true,true,true", "the liver hidden");
        await click(rows[0].visible);
        await app.stateWhen((s) => visible(s).every((v) => v), "the liver shown again");

        // A sagittal plane through the middle cuts away the patient's right half (the screen's
        // left, from the front).
        await app.call("setView", { from: "A" });
        const whole = drawn(await app.screenshot("V1-case-from-the-front"), view);
        await app.call("setView", { clip: { axis: "sagittal", at: 0.5 } });
        assert.deepEqual((await app.state()).view.clip, { axis: "sagittal", at: 0.5, flip: false });
        const cut = drawn(await app.screenshotWhen("V1-clipped-sagittal", (i) => drawn(i, view).count < 0.8 * whole.count, "the cut"), view);
        assert.ok(cut.meanX > whole.meanX, `what is left lies on the screen's right (the patient's left): ${cut.meanX} vs ${whole.meanX}`);
        await app.call("setView", { clip: { axis: "sagittal", at: 0.5, flip: true } });
        const other = drawn(await app.screenshotWhen("V1-clipped-flipped", (i) => drawn(i, view).meanX < whole.meanX, "the other half"), view);
        assert.ok(other.count < 0.8 * whole.count, `flipped, the other half: ${other.count} of ${whole.count}`);
        await app.call("setView", { clip: null });
        await app.screenshotWhen("V1-unclipped", (i) => drawn(i, view).count > 0.95 * whole.count, "the whole case again");
        await assert.rejects(app.call("setView", { clip: { axis: "oblique" } }), /none of axial/);

        // The slide back to the segmentation shows its staircase; back again, the same picture.
        const smoothed = await app.screenshot("V1-smoothed");
        await app.call("setView", { toward_segmentation: 1 });
        assert.equal((await app.state()).view.toward_segmentation, 1);
        const moved = (i) => changedPixels(i, smoothed, view);
        await app.screenshotWhen("V1-toward-segmentation", (i) => moved(i) > 2000, "the segmentation's staircase");
        await app.call("setView", { toward_segmentation: 0 });
        await app.screenshotWhen("V1-smoothed-again", (i) => moved(i) < 50, "the smoothed surfaces again");

        // Through a transparent liver, the tumour (turned green) is named under the pointer, and a
        // click selects it.
        await app.call("setStructure", { index: 0, opacity: 0 });
        await app.call("setStructure", { index: 2, color: [0, 1, 0] });
        const green = (r, g, b) => g > 120 && g > r + 60 && g > b + 60;
        const image = await app.screenshotWhen("V1-tumour-through-the-liver", (i) => pixelsWhere(i, view, green).count > 200, "the green tumour");
        const tumour = pixelsWhere(image, view, green);
        await app.page.mouse.move(tumour.meanX, tumour.meanY);
        await app.stateWhen((s) => s.view.pointed === "tumor", "the tumour named under the pointer");
        await app.page.mouse.move(view.x + view.width - 10, view.y + 80);
        await app.stateWhen((s) => s.view.pointed === null, "nothing under the pointer");
        await app.page.mouse.click(tumour.meanX, tumour.meanY);
        await app.stateWhen((s) => s.structures.current === 2 && s.loading === null, "the tumour selected");
        await app.page.mouse.move(tumour.meanX, tumour.meanY + 1);
        await app.stateWhen((s) => s.view.pointed === "tumor", "the tumour named again");
        await app.screenshot("V1-tumour-named-and-selected");
    }, { query: "?mode=viewer" });
});
