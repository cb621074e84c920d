// End-to-end tests of the viewer (`?mode=viewer`): a student opens a case glTF, shows, hides and
// isolates its structures in the panel by mouse, cuts them with the clipping plane, looks from
// the standard sides, slides back to the segmentation and has a structure named under the
// pointer; the editing controls are absent, their shortcuts do nothing.
//
//   E2E_MODE=webgpu|cpu node --test tests/e2e/viewer.test.mjs   (tests/e2e/run.sh runs both)
import assert from "node:assert/strict";
import { readFileSync, readdirSync, writeFileSync } from "node:fs";
import { join } from "node:path";

import * as cli from "./lib/cli.mjs";
import { E2E_OUT, ROOT, meshPath } from "./lib/paths.mjs";
import { colourAt, decodePng } from "./lib/png.mjs";
import { changedPixels, drawn, roughnessAcross } from "./lib/view.mjs";
import { EVERY_RUN, WEBGPU_RUN, appSuite, testIn } from "./lib/suite.mjs";

const { MODE, OUT, withApp } = appSuite({ beforeAll: () => cli.requireCli() });

const PHANTOM_NRRD = meshPath("labelmaps/case_phantom_shared.seg.nrrd");
const TIMEOUT = 240_000;


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

/** The phantom's case glTF as the CLI builds it (once per run of this file). */
let phantomCase = null;
function phantomCaseBytes() {
    phantomCase ??= (async () => {
        const file = join(E2E_OUT, MODE, "phantom-case.glb");
        await cli.cliJson("case", "build", PHANTOM_NRRD, "--search", "local", "-o", file, "--json");
        return readFileSync(file);
    })();
    return phantomCase;
}

/** Page options that open the phantom's case from the page's own origin, as `?case=` does. */
async function viewingThePhantom(extra = "") {
    return { query: `?mode=viewer&case=cases/phantom.glb${extra}`, routes: { "cases/phantom.glb": await phantomCaseBytes() } };
}

/** Waits for the viewer to show the phantom's four structures. */
const phantomShown = (app) => app.stateWhen((s) => s.structures?.structures.length === 4 && s.loading === null && s.layout.structures.length === 4, "the phantom's four structures");

testIn(EVERY_RUN, "V1 the viewer reads a case: its structures by mouse, the clipping plane, the standard views, no editing", { timeout: TIMEOUT }, async () => {
    const bytes = await phantomCaseBytes();
    await withApp(async (app) => {
        const opened = await app.loadMesh(bytes, "V1-phantom-case.glb", "loadCase");
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

testIn(EVERY_RUN, "V2 a link restores the view; the view's picture; the case in words for screen readers", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        let state = await phantomShown(app);
        // Opened as it was, the link holds only the camera.
        const [page, cam] = state.view.link.split("&cam=");
        assert.equal(page, `${app.server.url}?mode=viewer&case=cases%2Fphantom.glb`);
        const { yaw, pitch, distance, target } = state.view.camera;
        cam.split(",").map(Number).forEach((v, k) => {
            const want = [yaw, pitch, distance, ...target][k];
            assert.ok(Math.abs(v - want) <= 1e-6 * Math.abs(want), `the link's camera ${cam} holds ${want}`);
        });
        const canvasLabel = () => app.page.getAttribute("#meshsmooth_canvas", "aria-label");
        const listed = () => app.page.locator("#case_structures li").allTextContents();
        assert.match(await canvasLabel(), /^3D view of .+: 4 structures, 4 shown; selected: liver$/);
        assert.deepEqual(await listed(), ["liver, shown, selected", "portal_vein, shown", "tumor, shown", "right_kidney, shown"]);

        // A view of the case: from the left, a little turned by the mouse, the liver see-through,
        // the kidney hidden, the tumour selected, cut axially.
        await app.call("setView", { from: "L", clip: { axis: "axial", at: 0.6 } });
        await app.call("setStructure", { index: 0, opacity: 0.4 });
        await app.call("setStructure", { index: 3, visible: false });
        await app.call("selectStructure", 2);
        const centre = [state.view.x + state.view.width / 2, state.view.y + state.view.height / 2];
        await app.page.mouse.move(...centre);
        await app.page.mouse.down();
        await app.page.mouse.move(centre[0] + 60, centre[1] + 25, { steps: 6 });
        await app.page.mouse.up();
        await app.page.mouse.move(state.view.x + 5, state.view.y + state.view.height - 60);
        state = await app.stateWhen((s) => s.structures.current === 2 && s.loading === null && !s.busy, "the tumour selected");
        const link = new URL(state.view.link);
        assert.deepEqual([...link.searchParams.keys()], ["mode", "case", "cam", "hide", "opacity", "select", "clip"]);
        assert.deepEqual(
            ["hide", "opacity", "select", "clip"].map((k) => link.searchParams.get(k)),
            ["3", "0:0.4", "2", "axial,0.6"],
        );
        assert.match(await canvasLabel(), /4 structures, 3 shown; selected: tumor$/);
        assert.deepEqual(await listed(), ["liver, shown, 40% opaque", "portal_vein, shown", "tumor, shown, selected", "right_kidney, hidden"]);
        const seen = await app.screenshot("V2-the-view-linked");

        // The view's picture: the view alone, its size, what the page shows there.
        const pngBytes = await app.callBytes("screenshot");
        writeFileSync(join(OUT, "V2-picture.png"), pngBytes);
        const png = decodePng(pngBytes);
        const view = state.view;
        assert.deepEqual([png.width, png.height], [Math.round(view.width), Math.round(view.height)], "the picture is the view's size");
        // The mean colour of the view's middle (80 x 80 pixels), in the picture and on the page.
        const middle = (image, x0, y0) => {
            const sum = [0, 0, 0];
            for (let y = -40; y < 40; y++) {
                for (let x = -40; x < 40; x++) {
                    const c = colourAt(image, x0 + Math.round(view.width / 2) + x, y0 + Math.round(view.height / 2) + y);
                    [c >> 16, (c >> 8) & 255, c & 255].forEach((v, k) => (sum[k] += v / 6400));
                }
            }
            return sum.map(Math.round);
        };
        const [inPicture, onPage] = [middle(png, 0, 0), middle(seen, Math.round(view.x), Math.round(view.y))];
        assert.ok(inPicture.every((v, k) => Math.abs(v - onPage[k]) <= 12), `the picture's middle ${inPicture} is the page's ${onPage}`);

        // The link opens the case as it was shown, in a page of its own.
        await withApp(async (linked) => {
            const restored = await linked.stateWhen((s) => s.structures?.structures.length === 4 && s.structures.current === 2 && s.loading === null && !s.busy, "the linked view");
            const looks = (s) => s.structures.structures.map((x) => [x.visible, x.opacity]);
            assert.deepEqual(looks(restored), looks(state));
            assert.deepEqual(restored.view.clip, state.view.clip);
            for (const key of ["yaw", "pitch", "distance"]) {
                assert.ok(Math.abs(restored.view.camera[key] - state.view.camera[key]) <= 1e-5 * Math.abs(state.view.camera[key]) + 1e-6, `camera ${key}: ${restored.view.camera[key]} vs ${state.view.camera[key]}`);
            }
            assert.equal(restored.view.link, state.view.link, "the same link again");
            await linked.page.mouse.move(view.x + 5, view.y + view.height - 60);
            const again = await linked.screenshotWhen("V2-the-view-restored", (i) => changedPixels(i, seen, view) < 0.01 * view.width * view.height, "the same picture as the linked page's");
            console.log(`viewer ${MODE}: a linked view differs in ${changedPixels(again, seen, view)} pixels`);
        }, await viewingThePhantom(link.search.replace(/^\?mode=viewer&case=[^&]*/, "")));
    }, await viewingThePhantom());

    // A link that does not read says so, and the case opens as it is.
    await withApp(async (app) => {
        const state = await app.stateWhen((s) => s.error !== null, "the broken link reported");
        assert.match(state.error, /the link's cam=1,2: six numbers/);
    }, await viewingThePhantom("&cam=1,2"));
});

testIn(WEBGPU_RUN, "V3 on a phone: the case under the view, one finger orbits, two pan and pinch, a tap hides a structure", { timeout: TIMEOUT }, async () => {
    const phone = { viewport: { width: 390, height: 844 }, isMobile: true, hasTouch: true, deviceScaleFactor: 1 };
    await withApp(async (app) => {
        const state = await phantomShown(app);
        const { view } = state;
        assert.ok(view.width >= 380, `the view takes the phone's width: ${view.width}`);
        const rows = state.layout.structures;
        assert.ok(rows.every((r) => r.name.y > view.y + view.height), "the structures are listed under the view");
        const first = drawn(await app.screenshot("V3-phone-case"), view);
        assert.ok(first.count > 3000, `the case is drawn: ${first.count} pixels`);

        const cdp = await app.context.newCDPSession(app.page);
        const touch = (type, points) => cdp.send("Input.dispatchTouchEvent", { type, touchPoints: points.map(([x, y], id) => ({ x, y, id })) });
        /** Moves fingers from `from` to `to` ([[x, y], ...]) in steps, then lifts them. */
        const gesture = async (from, to) => {
            await touch("touchStart", from);
            for (let k = 1; k <= 8; k++) {
                await touch("touchMove", from.map(([x, y], i) => [x + ((to[i][0] - x) * k) / 8, y + ((to[i][1] - y) * k) / 8]));
                await app.page.evaluate(() => new Promise((r) => requestAnimationFrame(r)));
            }
            await touch("touchEnd", []);
        };
        const camera = async () => (await app.state()).view.camera;
        const [cx, cy] = [view.x + view.width / 2, view.y + view.height / 2];

        const before = await camera();
        await gesture([[cx - 60, cy]], [[cx + 60, cy]]);
        const orbited = await camera();
        assert.ok(Math.abs(orbited.yaw - before.yaw) > 0.3, `one finger orbits: yaw ${before.yaw} -> ${orbited.yaw}`);

        await gesture([[cx - 40, cy], [cx + 40, cy]], [[cx - 120, cy], [cx + 120, cy]]);
        const pinched = await camera();
        assert.ok(pinched.distance < 0.7 * orbited.distance, `spreading two fingers zooms in: ${orbited.distance} -> ${pinched.distance}`);
        assert.ok(Math.abs(pinched.yaw - orbited.yaw) < 0.05, `and does not orbit: yaw ${orbited.yaw} -> ${pinched.yaw}`);

        await gesture([[cx - 40, cy], [cx + 40, cy]], [[cx - 40, cy + 100], [cx + 40, cy + 100]]);
        const panned = await camera();
        const moved = Math.hypot(...panned.target.map((t, k) => t - pinched.target[k]));
        assert.ok(moved > 0.05 * pinched.distance, `two fingers moving together pan: the target moved ${moved}`);
        assert.ok(Math.abs(panned.yaw - pinched.yaw) < 0.05, `and do not orbit: yaw ${pinched.yaw} -> ${panned.yaw}`);
        await app.screenshot("V3-phone-moved");

        await app.page.touchscreen.tap(rows[3].visible.x + rows[3].visible.width / 2, rows[3].visible.y + rows[3].visible.height / 2);
        await app.stateWhen((s) => s.structures.structures[3].visible === false, "the kidney hidden by a tap");
        await app.screenshot("V3-phone-kidney-hidden");
    }, { ...(await viewingThePhantom()), device: phone });
});

/** The phantom's case with its synthetic CT (tests/data/make_phantom_ct.py), as the CLI builds it. */
async function phantomWithImage() {
    const file = join(E2E_OUT, MODE, "phantom-case-ct.glb");
    const ct = join(ROOT, "tests/data/phantom_ct.nii.gz");
    await cli.cliJson("case", "build", PHANTOM_NRRD, "--image", ct, "--search", "local", "-o", file, "--json");
    return readFileSync(file);
}

/** The CT's grey levels on screen (soft-tissue window): liver 60 HU, the rest of the phantom. */
const LIVER_GREY = Math.round(((60 + 160) / 400) * 255);
const neutral = (r, g, b) => Math.abs(r - g) <= 3 && Math.abs(g - b) <= 3;
const liverGrey = (r, g, b) => neutral(r, g, b) && Math.abs(g - LIVER_GREY) <= 8;
/** The liver's colour (221, 130, 101), unlit: its cut outline. */
const liverOutline = (r, g, b) => Math.abs(r - 221) <= 24 && Math.abs(g - 130) <= 24 && Math.abs(b - 101) <= 24;

testIn(EVERY_RUN, "V4 the clipping plane shows the case's CT slice, the liver's cut outline on its edges", { timeout: TIMEOUT }, async () => {
    const bytes = await phantomWithImage();
    await withApp(async (app) => {
        const opened = await app.loadMesh(bytes, "V4-phantom-ct.glb", "loadCase");
        assert.deepEqual(opened.image, { source: "phantom_ct.nii.gz", dims: [160, 140, 48], preset: "ct-soft-tissue", window: { center: 40, width: 400 } });
        const { view } = await app.stateWhen((s) => s.layout.structures.length === 4 && s.loading === null, "the case's four rows");
        await app.call("setView", { from: "S" });
        const uncut = await app.screenshot("V4-from-above");
        assert.ok(pixelsWhere(uncut, view, liverGrey).count < 50, "no slice without the plane");
        // The plane through the middle of a slice of the CT: between two slices the image is
        // interpolated, and where a boundary runs oblique to them (the vein) the grey changes
        // over several voxels of the plane, though within one in 3D.
        const planeAt = async (at, before = null) => {
            await app.call("setView", { from: "S", clip: { axis: "axial", at } });
            const drawn = (s) => Math.abs(s.view.clip?.at - at) < 1e-6 && s.view.clip_plane[2] === 1 && s.view.clip_plane[3] !== before;
            return (await app.stateWhen(drawn, `the plane at ${at}`)).view.clip_plane[3];
        };
        const low = await planeAt(0);
        const high = await planeAt(1, low);
        const centre = -40 + 2.5 * Math.round(((low + high) / 2 + 40) / 2.5);
        const middle = await planeAt((centre - low) / (high - low), high);
        assert.ok(Math.abs(middle - centre) < 0.01, `the plane lies at z = ${middle} mm, a slice's centre ${centre}`);
        const image = await app.screenshotWhen("V4-axial-slice", (i) => pixelsWhere(i, view, liverGrey).count > 2000, "the CT's liver on the slice");
        const outline = pixelsWhere(image, view, liverOutline);
        assert.ok(outline.count > 100, `the liver's outline is drawn: ${outline.count} pixels`);
        // Each outline pixel lies on an intensity edge of the slice: within about one voxel
        // (R pixels), its grey levels span at least EDGE (the liver's grey against the
        // background's, the vein's or the tumour's, blurred where a boundary runs oblique to
        // the 2.5 mm slices). The slice and the cut coincide.
        const at = (x, y) => {
            const i = (y * image.width + x) * 4;
            return [image.rgba[i], image.rgba[i + 1], image.rgba[i + 2]];
        };
        const [R, EDGE] = [4, 40];
        let [onEdge, all] = [0, 0];
        for (let y = Math.round(view.y + 60); y < Math.round(view.y + view.height - 40); y++) {
            for (let x = Math.round(view.x); x < Math.round(view.x + view.width); x++) {
                if (!liverOutline(...at(x, y))) continue;
                all++;
                let [low, high] = [255, 0];
                for (let dy = -R; dy <= R; dy++) {
                    for (let dx = -R; dx <= R; dx++) {
                        const c = at(x + dx, y + dy);
                        if (!neutral(...c)) continue;
                        low = Math.min(low, c[1]);
                        high = Math.max(high, c[1]);
                    }
                }
                if (high - low >= EDGE) onEdge++;
            }
        }
        console.log(JSON.stringify({ e2e: "slice-outline", mode: MODE, outline_pixels: all, on_an_edge: onEdge }));
        assert.ok(onEdge >= 0.95 * all, `${onEdge} of ${all} outline pixels lie within ${R} pixels of an edge of the CT's slice`);
        // A sagittal plane, seen from the side it cuts away (the patient's right).
        await app.call("setView", { from: "R", clip: { axis: "sagittal", at: 0.6 } });
        await app.screenshotWhen("V4-sagittal-slice", (i) => pixelsWhere(i, view, liverGrey).count > 500, "the liver on a sagittal slice");
        // The three planes together, through the scene's middle; they replace the clip.
        await app.call("setView", { from: "A", planes: { axial: 0.75 } });
        let state = await app.stateWhen((s) => s.view.planes !== null, "the three planes");
        assert.deepEqual(state.view.planes, { sagittal: 0.5, coronal: 0.5, axial: 0.75 });
        assert.equal(state.view.clip, null, "no clip with the planes");
        // They cut nothing: the liver hides its own grey on the coronal plane until hidden.
        await app.screenshot("V4-three-planes");
        const liverRow = state.layout.structures[0];
        await app.page.mouse.click(liverRow.visible.x + liverRow.visible.width / 2, liverRow.visible.y + liverRow.visible.height / 2);
        await app.stateWhen((s) => s.structures.structures[0].visible === false, "the liver hidden");
        await app.screenshotWhen("V4-three-planes-liver-hidden", (i) => pixelsWhere(i, view, liverGrey).count > 2000, "the liver's grey on the coronal plane");
        await app.call("setView", { clip: { axis: "axial" } });
        state = await app.stateWhen((s) => s.view.clip !== null, "a clip again");
        assert.equal(state.view.planes, null, "a clip replaces the planes");
        await assert.rejects(app.call("setView", { planes: { oblique: 0.5 } }), /unknown planes key oblique/);
    }, { query: "?mode=viewer" });
});

testIn(EVERY_RUN, "V9 a link carries the image's three planes, and opens the case showing them; their sliders move them", { timeout: TIMEOUT }, async () => {
    const routes = { "cases/ct.glb": await phantomWithImage() };
    const shown = (app) => app.stateWhen((s) => s.structures?.structures.length === 4 && s.loading === null && s.layout.structures.length === 4, "the case's four rows");
    let link, seen, view;
    await withApp(async (app) => {
        const before = (await shown(app)).view.camera;
        await app.call("setView", { from: "A", planes: { sagittal: 0.25, axial: 0.75 } });
        // The planes are asked at once; the camera turns in the next frame.
        const turned = (c) => c !== null && (c.yaw !== before.yaw || c.pitch !== before.pitch);
        const state = await app.stateWhen((s) => s.view.planes !== null && turned(s.view.camera) && !s.busy, "the three planes, from the front");
        link = new URL(state.view.link);
        assert.equal(link.searchParams.get("planes"), "0.25,0.5,0.75");
        assert.equal(link.searchParams.get("clip"), null, "no clip beside the planes");
        view = state.view;
        await app.page.mouse.move(view.x + 5, view.y + view.height - 60);
        seen = await app.screenshot("V9-planes");
    }, { query: "?mode=viewer&case=cases/ct.glb", routes });
    await withApp(async (app) => {
        const state = await shown(app);
        assert.deepEqual(state.view.planes, { sagittal: 0.25, coronal: 0.5, axial: 0.75 });
        assert.equal(state.view.clip, null);
        await app.page.mouse.move(view.x + 5, view.y + view.height - 60);
        await app.screenshotWhen("V9-linked-planes", (i) => changedPixels(i, seen, view) < 0.01 * view.width * view.height, "the same picture as the linking page's");
        // The student looks from above and moves the axial plane down with its slider: the
        // picture and the link follow.
        const before = state.view.camera;
        await app.call("setView", { from: "S" });
        await app.stateWhen((s) => s.view.camera.pitch !== before.pitch && !s.busy, "the view from above");
        await app.page.mouse.move(view.x + 5, view.y + view.height - 60);
        const above = await app.screenshot("V9-planes-from-above");
        const [sagittal, , axial] = state.layout.planes;
        assert.ok(sagittal.x < axial.x, JSON.stringify(state.layout.planes));
        await app.page.mouse.click(axial.x + 0.15 * axial.width, axial.y + axial.height / 2);
        const moved = await app.stateWhen((s) => s.view.planes?.axial < 0.3, "the axial plane moved down");
        assert.deepEqual([moved.view.planes.sagittal, moved.view.planes.coronal], [0.25, 0.5], "the others stay");
        assert.match(new URL(moved.view.link).searchParams.get("planes"), /^0\.25,0\.5,(0|0\.[0-2]\d*)$/);
        await app.page.mouse.move(view.x + 5, view.y + view.height - 60);
        await app.screenshotWhen("V9-axial-plane-moved", (i) => changedPixels(i, above, view) > 0.01 * view.width * view.height, "the lower axial slice");
    }, { query: `?mode=viewer&case=cases/ct.glb${link.search.replace(/^\?mode=viewer&case=[^&]*/, "")}`, routes });
});

testIn(EVERY_RUN, "V10 a tour step records the image's three planes, and the viewer shows them at that step", { timeout: TIMEOUT }, async () => {
    const withImage = await phantomWithImage();
    let exported;
    await withApp(async (app) => {
        await app.loadMesh(withImage, "phantom-case-ct.glb", "loadCase");
        await app.stateWhen((s) => s.loading === null && s.view.camera, "the case open and framed");
        await app.call("setView", { planes: { sagittal: 0.3, axial: 0.2 } });
        await app.stateWhen((s) => s.view.planes !== null, "the three planes");
        assert.equal(await app.call("recordStep", { title: "Low slices" }), 1);
        const { steps } = await app.call("lesson");
        assert.deepEqual(steps[0].planes, { sagittal: Math.fround(0.3), coronal: 0.5, axial: Math.fround(0.2) });
        assert.equal(steps[0].clip, null);
        exported = Buffer.from(await app.call("exportCase", "glb"));
    });
    await withApp(async (app) => {
        await app.stateWhen((s) => s.structures?.structures.length === 4 && s.loading === null && s.tour?.steps === 1, "the case and its tour");
        await app.call("setView", { clip: { axis: "coronal", at: 0.4 } });
        await app.stateWhen((s) => s.view.clip !== null, "a clip of the student's");
        await app.call("showStep", 0);
        const at = await app.stateWhen((s) => s.tour.step === 0 && s.view.planes !== null, "the step's planes");
        assert.deepEqual(at.view.planes, { sagittal: Math.fround(0.3), coronal: 0.5, axial: Math.fround(0.2) });
        assert.equal(at.view.clip, null, "the step's planes replace the student's clip");
    }, { query: "?mode=viewer&case=cases/toured.glb", routes: { "cases/toured.glb": exported } });
});

testIn(EVERY_RUN, "V5 the author adds the CT under the page's case, the case glTF carries it, the viewer shows its slice", { timeout: TIMEOUT }, async () => {
    const ct = readFileSync(join(ROOT, "tests/data/phantom_ct.nii.gz"));
    const bone = { source: "phantom_ct.nii.gz", dims: [160, 140, 48], preset: "ct-bone", window: { center: 400, width: 1800 } };
    /** The liver (60 HU) in the bone window, unlit. */
    const boneLiver = (r, g, b) => neutral(r, g, b) && Math.abs(g - Math.round(((60 - 400 + 900) / 1800) * 255)) <= 6;
    let exported;
    await withApp(async (app) => {
        await app.loadMesh(readFileSync(PHANTOM_NRRD), "case_phantom_shared.seg.nrrd", "loadCase");
        const unknown = await app.attemptLoad(ct, "phantom_ct.nii.gz", "addImage", "soft");
        assert.match(unknown.message, /preset must be one of ct-soft-tissue, ct-bone/);
        const stl = await app.attemptLoad(ct, "phantom_ct.stl", "addImage");
        assert.match(stl.message, /cannot tell the image format of 'phantom_ct\.stl': use one of \.nii \.nii\.gz \.nrrd \.mgz \.mgh/);
        const jhu = await app.attemptLoad(readFileSync(join(ROOT, "tests/data/jhu_labels.mgz")), "jhu_labels.mgz", "addImage");
        assert.match(jhu.message, /Cannot open the image jhu_labels\.mgz: the image, on another voxel grid \(1\.000 x 1\.000 x 1\.000 mm voxels; the segmentation's 0\.780 x 0\.780 x 2\.500 mm\), does not cover the segmentation: its structures reach [0-9.]+ mm beyond the image$/);
        const added = await app.loadMesh(ct, "phantom_ct.nii.gz", "addImage", "ct-bone");
        assert.deepEqual(added.image, bone);
        const { view } = await app.stateWhen((s) => s.loading === null && s.layout.structures.length === 4, "the case open, the image read");
        await app.call("setView", { from: "S", clip: { axis: "axial", at: 0.5 } });
        await app.screenshotWhen("V5-author-bone-window", (i) => pixelsWhere(i, view, boneLiver).count > 2000, "the CT's liver on the author's slice");
        exported = Buffer.from(await app.call("exportCase", "glb"));
        await app.call("removeImage");
        assert.equal((await app.call("structures")).image, null, "removed");
    });
    await withApp(async (app) => {
        const opened = await app.loadMesh(exported, "V5-author-case.glb", "loadCase");
        assert.deepEqual(opened.image, bone, "the author's image, carried in the case glTF");
        const { view } = await app.stateWhen((s) => s.layout.structures.length === 4 && s.loading === null, "the case's four rows");
        await app.call("setView", { from: "S", clip: { axis: "axial", at: 0.5 } });
        await app.screenshotWhen("V5-viewer-bone-window", (i) => pixelsWhere(i, view, boneLiver).count > 2000, "the CT's liver on the viewer's slice");
    }, { query: "?mode=viewer" });
});

testIn(EVERY_RUN, "V8 a DICOM CT series, its slices given together, goes under the case as case build --image FOLDER adds it", { timeout: TIMEOUT }, async () => {
    const folder = join(ROOT, "tests/data/dicom_series/phantom_ct");
    // Not in slice order: the slices are placed by their positions.
    const names = readdirSync(folder).sort().reverse();
    const native = (await cli.cliJson("case", "build", PHANTOM_NRRD, "--image", folder, "--search", "local", "-o", join(E2E_OUT, MODE, "V8-series-case.glb"), "--json")).image;
    assert.deepEqual(native.dims, [160, 140, 24]);
    await withApp(async (app) => {
        await app.loadMesh(readFileSync(PHANTOM_NRRD), "case_phantom_shared.seg.nrrd", "loadCase");
        const addSeries = (files, names) =>
            app.page.evaluate(async ([files, names]) => {
                const slices = files.map((b64) => Uint8Array.from(atob(b64), (c) => c.charCodeAt(0)));
                try {
                    return { ok: true, value: await window.meshsmooth.addImage(slices, names, "ct-soft-tissue") };
                } catch (e) {
                    return { ok: false, message: e instanceof Error ? e.message : String(e) };
                }
            }, [files, names]);
        const files = names.map((n) => readFileSync(join(folder, n)).toString("base64"));
        const uneven = await addSeries(files, names.slice(1));
        assert.match(uneven.message, /addImage\(bytes, names\): a series needs as many names as slices/);
        const gapped = await addSeries(files.filter((_, i) => i !== 7), names.filter((_, i) => i !== 7));
        assert.match(gapped.message, /Cannot open the image DICOM series \(23 slices\): the slices are not evenly spaced: CT\d{4}\.dcm and CT\d{4}\.dcm lie 5\.000 mm apart/);
        const added = await addSeries(files, names);
        assert.ok(added.ok, added.message);
        assert.deepEqual(added.value.image, { source: "DICOM series (24 slices)", dims: native.dims, preset: native.preset, window: native.window });
        const { view } = await app.stateWhen((s) => s.loading === null && s.layout.structures.length === 4, "the case open, the series read");
        // The structures span slices 11 to 32, the series 0 to 23: a plane through slice 18.
        await app.call("setView", { from: "S", clip: { axis: "axial", at: 0.35 } });
        await app.screenshotWhen("V8-series-slice", (i) => pixelsWhere(i, view, liverGrey).count > 2000, "the series' liver on the slice");
    });
});

testIn(EVERY_RUN, "V6 a glTF meshsmooth did not smooth is shown as the file holds it, with no smoothing record", { timeout: TIMEOUT }, async () => {
    const file = join(E2E_OUT, MODE, "V6-converted.glb");
    await cli.cli("convert", meshPath("synthetic/synthetic_ellipsoid_30_20_12.ply"), file);
    const bytes = readFileSync(file);
    await withApp(async (app) => {
        const read = (s) => s.structures?.structures.length === 1 && s.loading === null && s.layout.structures.length === 1;
        const state = await app.stateWhen(read, "the converted surface");
        const [s] = state.structures.structures;
        assert.equal(s.shown_as_read, true, "no smoothing record");
        // Nothing is computed for it: a while later it is still unmeasured and nothing runs.
        await app.page.waitForTimeout(1500);
        const later = await app.state();
        assert.equal(later.busy, false, "nothing to compute");
        assert.equal(later.structures.structures[0].metrics, null, "no measures made up");
        const shot = await app.screenshot("V6-as-read");
        assert.ok(drawn(shot, later.view).count > 2000, "the surface is drawn");
    }, { query: "?mode=viewer&case=cases/converted.glb", routes: { "cases/converted.glb": bytes } });
});

testIn(EVERY_RUN, "V7 a cut shows each closed structure solid, its cut face filled in its colour; a translucent one shows its outline", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        let s = await phantomShown(app);
        const view = s.view;
        const cut = { from: "S", clip: { axis: "axial", at: 0.6, flip: false } };
        await app.call("setView", cut);
        await app.stateWhen((s) => s.view.clip?.axis === "axial", "the axial cut");
        const face = (image) => roughnessAcross(image, view);
        const flat = (i) => face(i).pairs > 3000 && face(i).step < 4;
        const solid = face(await app.screenshotWhen("V7-axial-cut-solid", flat, "the liver's cut face, flat"));
        assert.equal(solid.holes, 0, "no background inside the cut's outline");
        // The same cut through a liver barely translucent: hollow, its inside's relief shows.
        await app.call("setStructure", { index: 0, opacity: 0.97 });
        const hollow = face(await app.screenshotWhen("V7-axial-cut-translucent", (i) => face(i).step > 2 * solid.step, "the liver hollow"));
        console.log(`viewer ${MODE}: colour steps across the cut face: solid ${solid.step.toFixed(2)}, hollow ${hollow.step.toFixed(2)}`);
        await app.call("setStructure", { index: 0, opacity: 1 });
        await app.call("setView", { from: "R", clip: { axis: "sagittal", at: 0.5, flip: false } });
        const side = face(await app.screenshotWhen("V7-sagittal-cut-solid", (i) => face(i).pairs > 3000 && face(i).step < 4, "the sagittal cut face, flat"));
        assert.equal(side.holes, 0, "no background inside the sagittal cut");
    }, await viewingThePhantom());
});
