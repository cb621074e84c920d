// End-to-end tests of the LMS packages (`meshsmooth case package`): a test LMS page built on
// scorm-again (its Scorm12API or Scorm2004API as window.API / window.API_1484_11) frames the
// unzipped package from its own origin; the student takes the tour and the quiz by clicks and
// taps; the data model the LMS keeps is read back, and a relaunch with it resumes.
//
//   E2E_MODE=cpu node --test tests/e2e/lms.test.mjs   (tests/e2e/run.sh runs it in the cpu run)
import { after } from "node:test";
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { copyFileSync, mkdirSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";

import { launchBrowser, modeFromEnv } from "./lib/browser.mjs";
import * as cli from "./lib/cli.mjs";
import { ROOT, VIEWER_DIST, meshPath, outputDir } from "./lib/paths.mjs";
import { serveDirectory } from "./lib/server.mjs";
import { pressLessonControl } from "./lib/input.mjs";
import { LESSON_FILE, phantomPackage, phantomShown, press, stateWhen, takeQuiz, viewerOf } from "./lib/packaged.mjs";
import { CPU_RUN, appSuite, testIn } from "./lib/suite.mjs";

const MODE = modeFromEnv();
const OUT = outputDir(MODE);
const { withApp } = appSuite({ beforeAll: () => cli.requireCli() });
const TIMEOUT = 240_000;
const tmp = mkdtempSync(join(tmpdir(), "meshsmooth-lms-"));
after(() => rmSync(tmp, { recursive: true, force: true }));

const lessonFile = LESSON_FILE;
const lesson = JSON.parse(readFileSync(lessonFile, "utf8"));
const SCORM_AGAIN = join(ROOT, "web/node_modules/scorm-again/dist");

/** Each format's folder (the test LMS page beside the unzipped package), built once per run. */
const built = {};

/** The SCORM package of the phantom with its lesson, unzipped into `<tmp>/<format>/package/`. */
async function builtPackage(format) {
    const root = join(tmp, format);
    mkdirSync(root, { recursive: true });
    await phantomPackage(format, join(OUT, `phantom-${format}.zip`), join(root, "package"));
    const script = format === "scorm12" ? "scorm12.min.js" : "scorm2004.min.js";
    copyFileSync(join(SCORM_AGAIN, script), join(root, script));
    writeFileSync(join(root, "lms.html"), lmsPage(format, script));
    return root;
}

/**
 * The test LMS: `launch(kept)` makes a fresh API (loaded with what the LMS kept of the last
 * attempt) and frames the package; `leave()` takes the frame away, as a platform does when the
 * student goes elsewhere; `kept()` is the data model as the LMS holds it.
 */
function lmsPage(format, script) {
    const [global, make, commit] = format === "scorm12" ? ["API", "Scorm12API", "LMSCommit"] : ["API_1484_11", "Scorm2004API", "Commit"];
    return `<!DOCTYPE html><html><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1"><title>Test LMS</title>
<link rel="icon" href="data:,"><script src="${script}"></script>
<style>html, body { margin: 0; height: 100%; } iframe { border: 0; width: 100%; height: 100%; display: block; }</style>
</head><body><script>
window.commits = 0;
window.launch = (kept) => {
    const api = new ${make}({ lmsCommitUrl: false, autocommit: false, logLevel: 4 });
    if (kept) api.loadFromJSON(kept);
    api.on("${commit}", () => { window.commits += 1; });
    window.${global} = api;
    const frame = document.createElement("iframe");
    frame.src = "package/index.html";
    document.body.append(frame);
};
window.leave = () => document.querySelector("iframe")?.remove();
window.kept = () => window.${global}.renderCMIToJSONObject().cmi;
</script></body></html>`;
}

/** What the LMS keeps for the next launch, as an LMS relaunches a suspended attempt. */
function relaunchData(format, cmi) {
    const kept = structuredClone(cmi);
    const core = format === "scorm12" ? kept.core : kept;
    core.entry = core.exit === "suspend" ? "resume" : "";
    delete core.exit;
    delete core.session_time;
    return kept;
}

const interactionsOf = (cmi) => Object.values(cmi.interactions ?? {}).filter((i) => i && typeof i === "object" && i.id);

/**
 * One student's attempt in `format`: two tour steps, leave, relaunch (back at the second step),
 * the last step, the quiz (right and wrong in each mode), leave; returns what the LMS kept and
 * the answers given.
 */
async function attempt(format, { device = null, namedRight = 1 } = {}) {
    built[format] ??= builtPackage(format);
    // As many LMSs serve a package's files: the wasm as a plain download.
    const server = await serveDirectory(await built[format], 0, { types: { ".wasm": "application/octet-stream" } });
    const browser = await launchBrowser(MODE);
    const requests = [];
    try {
        const context = await browser.newContext(device ?? { viewport: { width: 1280, height: 800 } });
        const page = await context.newPage();
        page.on("request", (r) => requests.push(r.url()));
        const errors = [];
        page.on("pageerror", (e) => errors.push(String(e)));
        const tap = Boolean(device?.hasTouch);
        await page.goto(`${server.url}lms.html`);
        await page.evaluate(() => window.launch(null));
        let viewer = await viewerOf(page);
        await phantomShown(viewer);
        await press(page, viewer, "start", tap);
        await stateWhen(viewer, (s) => s.tour?.step === 0, "step 1");
        await press(page, viewer, "next", tap);
        await stateWhen(viewer, (s) => s.tour?.step === 1, "step 2");
        await page.screenshot({ path: join(OUT, `lms-${format}${tap ? "-phone" : ""}-tour.png`) });
        await page.evaluate(() => window.leave());
        const left = await page.evaluate(() => window.kept());

        await page.evaluate((kept) => window.launch(kept), relaunchData(format, left));
        viewer = await viewerOf(page);
        await phantomShown(viewer);
        await stateWhen(viewer, (s) => s.tour?.step === 1, "the relaunch resumed at step 2");
        await press(page, viewer, "next", tap);
        await stateWhen(viewer, (s) => s.tour?.step === 2, "step 3, the last");
        await press(page, viewer, "leave", tap);
        await stateWhen(viewer, (s) => s.tour.step === null && !s.layout.lesson?.leave, "the tour left, drawn");
        const answers = await takeQuiz(page, viewer, namedRight, tap);
        await page.screenshot({ path: join(OUT, `lms-${format}${tap ? "-phone" : ""}-score.png`) });
        await page.evaluate(() => window.leave());
        const kept = await page.evaluate(() => window.kept());
        const commits = await page.evaluate(() => window.commits);
        const outside = requests.filter((url) => !/^(data|blob):/.test(url) && !url.startsWith(server.url));
        assert.deepEqual(outside, [], "requests outside the LMS's origin");
        assert.deepEqual(errors, [], "uncaught errors");
        await context.close();
        return { left, kept, answers, commits };
    } finally {
        await browser.close();
        await server.close();
    }
}

/** The checks both versions share: one interaction per answer, with its result and response. */
function checkInteractions(format, kept, answers) {
    const interactions = interactionsOf(kept);
    assert.equal(interactions.length, answers.length, "one interaction per answer");
    const [right, wrong] = format === "scorm12" ? ["correct", "wrong"] : ["correct", "incorrect"];
    for (const [i, a] of answers.entries()) {
        const it = interactions[i];
        assert.equal(it.result, a.right ? right : wrong, `${JSON.stringify(it)} for ${JSON.stringify(a)}`);
        assert.match(it.id, new RegExp(a.mode), it.id);
        const response = format === "scorm12" ? it.student_response : it.learner_response;
        assert.ok(response, `a response in ${JSON.stringify(it)}`);
    }
    for (const mode of ["find-it", "name-it"]) {
        const of = answers.filter((a) => a.mode === mode);
        assert.ok(of.some((a) => a.right) && of.some((a) => !a.right), `${mode}: a right and a wrong answer`);
    }
}

testIn(CPU_RUN, "P1 SCORM 1.2: the tour and quiz by clicks reach the LMS: location, suspend data, interactions, score, failed; a relaunch resumes", { timeout: TIMEOUT }, async () => {
    const { left, kept, answers, commits } = await attempt("scorm12");
    assert.equal(left.core.lesson_location, "2", "the step left, counted from 1");
    assert.equal(left.core.exit, "suspend");
    assert.ok(left.suspend_data.length > 0 && left.suspend_data.length <= 4096, left.suspend_data);
    assert.equal(left.core.lesson_status, "incomplete");
    checkInteractions("scorm12", kept, answers);
    const right = answers.filter((a) => a.right).length;
    assert.equal(right, 2, "the liver found once, one name right");
    assert.equal(Number(kept.core.score.raw), (100 * right) / answers.length);
    assert.equal(kept.core.score.min, "0");
    assert.equal(kept.core.score.max, "100");
    assert.equal(kept.core.lesson_status, "failed", `${right} of ${answers.length} is under the pass mark of ${lesson.quiz.pass_mark}`);
    assert.ok(commits >= 3, `committed along the way (${commits})`);
});

testIn(CPU_RUN, "P2 SCORM 2004: progress, interactions, the scaled score passed at the pass mark, completed; a relaunch resumes", { timeout: TIMEOUT }, async () => {
    const { left, kept, answers } = await attempt("scorm2004", { namedRight: 3 });
    assert.equal(left.location, "2");
    assert.equal(left.exit, "suspend");
    assert.ok(Number(left.progress_measure) > 0 && Number(left.progress_measure) < 1, `progress ${left.progress_measure}`);
    assert.equal(left.completion_status, "incomplete");
    checkInteractions("scorm2004", kept, answers);
    const right = answers.filter((a) => a.right).length;
    assert.equal(right, 4, "the liver found once, three names right");
    assert.equal(Number(kept.score.scaled), right / answers.length);
    assert.equal(Number(kept.score.raw), (100 * right) / answers.length);
    assert.equal(kept.success_status, "passed", `${right} of ${answers.length} reaches the pass mark of ${lesson.quiz.pass_mark}`);
    assert.equal(kept.completion_status, "completed");
});

testIn(CPU_RUN, "P3 SCORM 1.2 on a phone held upright: the same attempt by taps", { timeout: TIMEOUT }, async () => {
    const phone = { viewport: { width: 390, height: 844 }, isMobile: true, hasTouch: true, deviceScaleFactor: 1 };
    const { left, kept, answers } = await attempt("scorm12", { device: phone });
    assert.equal(left.core.lesson_location, "2");
    checkInteractions("scorm12", kept, answers);
    assert.equal(kept.core.lesson_status, "failed");
});

testIn(CPU_RUN, "P4 a package opened on its own plays the lesson and says once that nothing is recorded", { timeout: TIMEOUT }, async () => {
    built.scorm12 ??= builtPackage("scorm12");
    const server = await serveDirectory(await built.scorm12);
    const browser = await launchBrowser(MODE);
    try {
        const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
        const errors = [];
        page.on("pageerror", (e) => errors.push(String(e)));
        await page.goto(`${server.url}package/index.html`);
        const viewer = await viewerOf(page);
        await phantomShown(viewer);
        const notice = page.locator("#notice");
        await notice.waitFor({ state: "visible" });
        assert.match(await notice.innerText(), /outside a learning platform: your progress and answers are not recorded/i);
        // The labels and a cut, as the viewer shows them anywhere.
        let s = await stateWhen(viewer, (s) => s.view.labels.length === 2, "the case's two labels");
        assert.deepEqual(s.view.labels.map((l) => l.text).sort(), ["Liver", "Tumour"]);
        await viewer.frame.evaluate(() => window.meshsmooth.setView({ clip: { axis: "axial", at: 0.5, flip: false } }));
        s = await stateWhen(viewer, (s) => s.view.clip?.axis === "axial", "the cut");
        await page.screenshot({ path: join(OUT, "lms-outside-cut.png") });
        await viewer.frame.evaluate(() => window.meshsmooth.setView({ clip: null }));
        await press(page, viewer, "start");
        await stateWhen(viewer, (s) => s.tour?.step === 0, "the tour plays without an LMS");
        await page.screenshot({ path: join(OUT, "lms-outside.png") });
        await page.locator("#notice-close").click();
        await notice.waitFor({ state: "hidden" });
        // The structure shown is smoothed and measured in the viewer as in the app.
        s = await stateWhen(viewer, (s) => !s.busy, "the shown structure's smoothing");
        assert.equal(s.error, null, "the viewer shows no error");
        // The student's build: the viewer's calls only, and a case glTF the one file it reads.
        const calls = await viewer.frame.evaluate(() => Object.keys(window.meshsmooth));
        for (const author of ["loadMesh", "addImage", "suggestAll", "setParams", "exportCase", "exportLms"]) {
            assert.ok(!calls.includes(author), `the packaged viewer has no ${author}: ${calls.join(", ")}`);
        }
        const refused = await viewer.frame.evaluate(async () => {
            try {
                await window.meshsmooth.loadCase(new Uint8Array([1, 2, 3]), "abdomen.nii.gz");
                return "opened";
            } catch (e) {
                return String(e?.message ?? e);
            }
        });
        assert.match(refused, /abdomen\.nii\.gz\b.*the viewer opens case glTF files \(\.glb, \.gltf\) only/);
        // The case it had stays open.
        await phantomShown(viewer);
        assert.deepEqual(errors, [], "uncaught errors");
    } finally {
        await browser.close();
        await server.close();
    }
});

testIn(CPU_RUN, "P5 the Lesson panel's Export for LMS saves the package the CLI writes for the same case", { timeout: TIMEOUT }, async () => {
    const caseFile = join(OUT, "lms-lesson-case.glb");
    const map = meshPath("labelmaps/case_phantom_shared.seg.nrrd");
    await cli.cliJson("case", "build", map, "--search", "local", "--lesson", lessonFile, "--title", "Abdominal phantom", "-o", caseFile, "--json");
    const routes = { "cases/lesson.glb": readFileSync(caseFile) };
    await withApp(async (app) => {
        await app.stateWhen((s) => s.loading === null && s.structures?.structures.length === 4 && s.layout.lesson?.["lesson-tab"], "the case open");
        const click = (key) => pressLessonControl(app, key);
        await click("lesson-tab");
        const saved = app.page.waitForEvent("download", { timeout: 60_000 });
        await click("lms-scorm2004");
        const download = await saved;
        assert.equal(download.suggestedFilename(), "Abdominal_phantom_scorm2004.zip");
        const zip = join(OUT, "lms-page-scorm2004.zip");
        await download.saveAs(zip);
        const fromPage = readFileSync(zip);
        const called = Buffer.from(await app.page.evaluate(async () => Array.from(await window.meshsmooth.exportLms("scorm2004"))));
        assert.ok(called.equals(fromPage), "exportLms() gives the button's package");

        // The CLI, given the page's case glTF and the page's build as the viewer.
        const unzipped = join(tmp, "page-package");
        execFileSync("python3", ["-m", "zipfile", "-e", zip, unzipped]);
        const fromCli = join(OUT, "lms-cli-scorm2004.zip");
        await cli.cliJson("case", "package", join(unzipped, "case.glb"), "--format", "scorm2004", "--viewer", VIEWER_DIST, "-o", fromCli, "--json");
        assert.ok(readFileSync(fromCli).equals(fromPage), "the page's package is the CLI's, byte for byte");
        assert.match(readFileSync(join(unzipped, "imsmanifest.xml"), "utf8"), /<imsss:minNormalizedMeasure>0\.5<\/imsss:minNormalizedMeasure>/);
    }, { query: "?case=cases/lesson.glb", routes });
});
