// End-to-end test of embedding: the example case platform (web/examples/platform/), served from
// a second origin, embeds the authoring page and the viewer from the app's origin and drives
// them by their postMessage protocol. A segmentation handed to the authoring page comes back as
// a case glTF and opens in the viewer; a page from a third origin is ignored by both.
//
//   E2E_MODE=webgpu|cpu node --test tests/e2e/platform.test.mjs   (tests/e2e/run.sh runs both)
import { after } from "node:test";
import assert from "node:assert/strict";
import { mkdtempSync, readFileSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";

import { launchBrowser, modeFromEnv } from "./lib/browser.mjs";
import * as cli from "./lib/cli.mjs";
import { DIST, ROOT, meshPath, outputDir } from "./lib/paths.mjs";
import { decodePng, assertNotBlank } from "./lib/png.mjs";
import { serveDirectory } from "./lib/server.mjs";
import { EVERY_RUN, testIn } from "./lib/suite.mjs";

const MODE = modeFromEnv();
const OUT = outputDir(MODE);
const PHANTOM_NRRD = meshPath("labelmaps/case_phantom_shared.seg.nrrd");
const TIMEOUT = 300_000;

const closing = [];
after(async () => {
    for (const close of closing.reverse()) await close();
});

/** The origin of a URL, or null for local ones (data:, about:). */
function originOf(url) {
    const parsed = new URL(url);
    if (parsed.protocol === "blob:") return new URL(parsed.pathname).origin;
    return parsed.protocol.startsWith("http") ? parsed.origin : null;
}

testIn(EVERY_RUN, "P1 a platform on another origin authors a case in the embedded page and shows it in the embedded viewer; a third origin is ignored", { timeout: TIMEOUT }, async () => {
    const app = await serveDirectory(DIST);
    const platform = await serveDirectory(join(ROOT, "web/examples/platform"));
    const thirdDir = mkdtempSync(join(tmpdir(), "meshsmooth-third-"));
    // A page of a third site inside the platform: it posts calls at both meshsmooth pages.
    writeFileSync(join(thirdDir, "index.html"), "<!DOCTYPE html><title>third</title><p>another site</p>");
    const third = await serveDirectory(thirdDir);
    const browser = await launchBrowser(MODE);
    closing.push(() => app.close(), () => platform.close(), () => third.close(), () => browser.close());

    const context = await browser.newContext({ viewport: { width: 1600, height: 900 }, deviceScaleFactor: 1 });
    const page = await context.newPage();
    const requests = [];
    const consoleLines = [];
    const errors = [];
    page.on("request", (r) => requests.push({ url: r.url(), frame: r.frame().url(), navigation: r.isNavigationRequest() }));
    page.on("console", (m) => consoleLines.push(m.text()));
    page.on("pageerror", (e) => errors.push(String(e)));

    await page.goto(`${platform.url}?app=${encodeURIComponent(app.url)}`);
    /** Waits for a line of the platform's log matching `pattern`, among those from `since` on. */
    const logged = async (pattern, what, since = 0) => {
        const wanted = [pattern.source, since];
        await page.waitForFunction(([s, from]) => window.platform?.log.slice(from).some((l) => new RegExp(s).test(l)), wanted, { timeout: 120_000 })
            .catch(async () => {
                throw new Error(`${what}: not logged; the platform's log: ${JSON.stringify(await page.evaluate(() => window.platform?.log))}`);
            });
    };
    await logged(/^authoring page ready \((webgpu|cpu)\)$/, "the authoring page answers");
    await logged(/^viewer ready/, "the viewer answers");

    // The segmentation goes to the authoring page; its structures come back in the event.
    await page.setInputFiles("#segmentation", PHANTOM_NRRD);
    await logged(/^authoring page opened case_phantom_shared\.seg\.nrrd: 4 structures$/, "the segmentation opened");
    const call = (pane, name, ...args) => page.evaluate(([p, n, a]) => window.platform[p].call(n, ...a), [pane, name, args]);

    // Calls by message answer as the API does, and a change is announced.
    const state = await call("author", "state");
    assert.equal(state.mode, "author");
    assert.equal(state.shortcuts, false, "?shortcuts=off: the embedding page keeps the keys");
    const lines = () => page.evaluate(() => window.platform.log.length);
    let since = await lines();
    await call("author", "setStructure", { index: 3, visible: false });
    await logged(/^case changed: 3 of 4 structures shown$/, "the hidden kidney announced", since);
    since = await lines();
    await call("author", "setStructure", { index: 3, visible: true });
    await logged(/^case changed: 4 of 4 structures shown$/, "the kidney shown again", since);
    await assert.rejects(call("author", "setParams", { iterations: -1 }), /iterations/);
    await assert.rejects(call("author", "noSuchCall"), /no call 'noSuchCall' here: loadMesh/);
    await assert.rejects(call("viewer", "exportCase", "glb"), /no call 'exportCase' here/, "the viewer exports nothing");
    const refused = /not its name, group, description or names/;
    await assert.rejects(call("viewer", "setStructure", { index: 0, name: "x" }), refused);
    await assert.rejects(call("viewer", "setStructure", { index: 0, names: { de: "x" } }), refused);

    // Published: the case glTF the authoring page exported opens in the viewer, with what the
    // author wrote about a structure.
    const about = "The tumour: 2 cm, segment VIII, next to the portal vein.";
    await call("author", "setStructure", { index: 2, description: about });
    await page.click("#publish");
    await logged(/^received the case: \d+ bytes$/, "the exported case");
    await logged(/^viewer shows 4 structures$/, "the case in the viewer");
    const shown = await call("viewer", "structures");
    assert.deepEqual(shown.structures.map((s) => s.name), ["liver", "portal_vein", "tumor", "right_kidney"]);
    assert.equal(shown.structures[2].description, about);
    const authored = await call("author", "structures");
    assert.deepEqual(shown.structures.map((s) => s.color), authored.structures.map((s) => s.color), "the colours travel with the case");
    const received = await page.evaluate(() => Array.from(window.platform.published.subarray(0, 4)));
    assert.deepEqual(received, [0x67, 0x6c, 0x54, 0x46], "the platform holds a GLB");
    await page.evaluate(() => new Promise((r) => setTimeout(r, 1000)));
    const png = await page.screenshot();
    writeFileSync(join(OUT, "P1-platform.png"), png);
    assertNotBlank(decodePng(png), "P1-platform.png");

    // A third site's frame inside the platform posts at both pages: neither acts nor answers.
    await page.evaluate((src) => {
        const frame = document.createElement("iframe");
        frame.id = "third";
        frame.src = src;
        document.body.append(frame);
        return new Promise((r) => frame.addEventListener("load", r, { once: true }));
    }, third.url);
    const thirdFrame = page.frames().find((f) => f.url().startsWith(third.origin));
    const replies = await thirdFrame.evaluate(() => {
        const heard = [];
        window.addEventListener("message", (e) => heard.push(e.data));
        for (const target of [parent.frames[0], parent.frames[1]]) {
            target.postMessage({ meshsmooth: "call", id: 1, call: "setStructure", args: [{ index: 0, visible: false }] }, "*");
            target.postMessage({ meshsmooth: "call", id: 2, call: "structures", args: [] }, "*");
        }
        return new Promise((r) => setTimeout(() => r(heard), 2000));
    });
    assert.deepEqual(replies, [], "no answer reaches the third site");
    const ignored = consoleLines.filter((l) => l.includes(`ignored a meshsmooth call from ${third.origin}`));
    assert.equal(ignored.length, 4, `both pages note the calls they ignored: ${ignored.join(" | ")}`);
    for (const pane of ["author", "viewer"]) {
        const after = await call(pane, "structures");
        assert.equal(after.structures[0].visible, true, `the ${pane}'s liver stays shown`);
    }

    // A case with a tour: the platform steps the student through it from its own buttons and
    // hears each step shown, with the xAPI statement to record.
    const lessonCase = join(OUT, "P1-lesson-case.glb");
    await cli.cliJson("case", "build", PHANTOM_NRRD, "--search", "local", "--lesson", join(ROOT, "tests/data/phantom_lesson.json"), "-o", lessonCase, "--json");
    await page.evaluate((b) => window.platform.viewer.call("loadCase", new Uint8Array(b), "lesson.glb"), Array.from(readFileSync(lessonCase)));
    since = await lines();
    await call("viewer", "showStep", 1);
    await logged(/^student at step 2 of 3: The tumour inside the liver$/, "the step shown, heard", since);
    const [statement] = await page.evaluate(() => window.platform.statements);
    assert.equal(statement.verb.id, "http://adlnet.gov/expapi/verbs/experienced");
    assert.equal(statement.object.definition.name["en-US"], "The tumour inside the liver");
    assert.match(statement.object.id, /#step-2$/);

    // The platform starts the quiz from its own button; the student answers in the viewer (the
    // liver clicked for every "Find it", the first name for every "Name it") and the platform
    // hears each answer and the score, each with its xAPI statement.
    const viewerState = async (test, what) => {
        for (let tries = 0; tries < 300; tries++) {
            const s = await call("viewer", "state");
            if (test(s)) return s;
            await new Promise((r) => setTimeout(r, 100));
        }
        throw new Error(`the viewer: ${what} not reached`);
    };
    const frame = await page.locator("#viewer").boundingBox();
    const tap = (x, y) => page.mouse.click(frame.x + x, frame.y + y);
    await call("viewer", "showStep", 0);
    const front = JSON.parse(readFileSync(join(ROOT, "tests/data/phantom_lesson.json"), "utf8")).steps[0].camera;
    const arrived = (s) => Math.abs(s.view.camera.distance - front.distance) < 1e-3 && Math.abs(s.view.camera.yaw - front.yaw) < 1e-3;
    const atFront = await viewerState((s) => s.tour.step === 0 && arrived(s) && s.view.labels.length === 2, "the first step's view with its labels");
    const liver = atFront.view.labels.find((l) => l.text === "Liver");
    since = await lines();
    await call("viewer", "startQuiz");
    for (let q = 0; q < 8; q++) {
        const s = await viewerState((s) => s.quiz.question === q && !s.layout.lesson["next-question"], `question ${q + 1} drawn`);
        if (s.quiz.mode === "find-it") await tap(liver.x, liver.y);
        else await tap(s.layout.lesson["choice-0"].x + 10, s.layout.lesson["choice-0"].y + 8);
        const answered = await viewerState((s) => s.quiz.answer !== null && s.layout.lesson["next-question"], `question ${q + 1} answered`);
        const next = answered.layout.lesson["next-question"];
        await tap(next.x + next.width / 2, next.y + next.height / 2);
    }
    await logged(/^student finished the quiz: \d of 8, (passed|not passed)$/, "the score heard", since);
    const heard = (await page.evaluate(() => window.platform.log)).slice(since);
    const answers = heard.filter((l) => l.startsWith("student answered "));
    assert.equal(answers.length, 8, `every answer heard: ${answers.join(" | ")}`);
    assert.ok(answers.some((l) => /^student answered find-it on liver: right in/.test(l)), "the liver found");
    const statements = (await page.evaluate(() => window.platform.statements)).filter((s) => s.verb.display["en-US"] !== "experienced");
    assert.deepEqual(statements.map((s) => s.verb.display["en-US"]).slice(0, 8), Array(8).fill("answered"));
    const final = statements[8];
    assert.match(final.verb.id, /\/(passed|failed)$/);
    assert.equal(final.result.score.max, 8);
    assert.equal(final.actor.name, "the signed-in student", "the platform adds the student");

    // Frames open only the three sites, and every other request stays within the origin of the
    // frame that made it.
    const sites = [app.origin, platform.origin, third.origin];
    const navigations = requests.filter((r) => r.navigation).map((r) => originOf(r.url));
    assert.ok(navigations.every((o) => sites.includes(o)), `frames opened: ${navigations.join(", ")}`);
    const foreign = requests.filter((r) => !r.navigation && originOf(r.url) !== null && originOf(r.url) !== originOf(r.frame));
    assert.deepEqual(foreign, [], "a frame requested something from another origin");
    assert.ok(app.served.every((line) => !line.includes("platform")), "the app's origin served only the app");
    assert.deepEqual(errors, [], "uncaught errors in the page");
});
