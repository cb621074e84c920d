// End-to-end tests of a case's lesson: the viewer plays its tour (steps, captions, the camera's
// flight, labels) and its quiz ("Find it" by clicking in the view, "Name it" by picking a name,
// the score); the authoring page records steps and sets the lesson, which the case glTF carries.
//
//   E2E_MODE=webgpu|cpu node --test tests/e2e/lesson.test.mjs   (tests/e2e/run.sh runs both)
import assert from "node:assert/strict";
import { existsSync, readFileSync } from "node:fs";
import { join } from "node:path";

import * as cli from "./lib/cli.mjs";
import { E2E_OUT, ROOT, meshPath } from "./lib/paths.mjs";
import { EVERY_RUN, appSuite, testIn } from "./lib/suite.mjs";
import { drag, frames, pressLessonControl } from "./lib/input.mjs";
import { changedPixels, drawn } from "./lib/view.mjs";

const { MODE, withApp } = appSuite({ beforeAll: () => cli.requireCli() });

const PHANTOM_NRRD = meshPath("labelmaps/case_phantom_shared.seg.nrrd");
const TIMEOUT = 240_000;
const lessonFile = join(ROOT, "tests/data/phantom_lesson.json");
const lesson = JSON.parse(readFileSync(lessonFile, "utf8"));

/** The phantom's case glTF with its lesson, built by the CLI once per run. */
async function lessonCaseBytes() {
    const file = join(E2E_OUT, MODE, "lesson-case.glb");
    if (!existsSync(file)) {
        await cli.cliJson("case", "build", PHANTOM_NRRD, "--search", "local", "--lesson", lessonFile, "-o", file, "--json");
    }
    return readFileSync(file);
}

const viewingTheLesson = async () => ({ query: "?mode=viewer&case=cases/lesson.glb", routes: { "cases/lesson.glb": await lessonCaseBytes() } });
/** Whether `state` shows tour step `i` with its camera arrived. */
function arrived(state, i) {
    const c = state.view.camera;
    const want = lesson.steps[i].camera;
    const close = (a, b) => Math.abs(a - b) <= 1e-3 * Math.max(1, Math.abs(b));
    return state.tour?.step === i && c && close(c.yaw, want.yaw) && close(c.pitch, want.pitch) && close(c.distance, want.distance) && c.target.every((x, k) => close(x, want.target[k]));
}
const phantomShown = (app) => app.stateWhen((s) => s.structures?.structures.length === 4 && s.loading === null && s.layout.structures.length === 4, "the phantom's four structures");

testIn(EVERY_RUN, "L1 the viewer plays the case's tour: each step's structures, clip, caption and camera, by button and by call", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        const state = await phantomShown(app);
        assert.deepEqual(state.tour, { step: null, steps: 3, title: null, caption: null, left: null });
        const press = async (button) => {
            const s = await app.stateWhen((s) => s.layout.lesson?.[button], `the tour's ${button} button`);
            const r = s.layout.lesson[button];
            await app.page.mouse.click(r.x + r.width / 2, r.y + r.height / 2);
        };
        // At a step: its title and caption, and the camera arrived at its view.
        const atStep = (i) => app.stateWhen((s) => arrived(s, i), `step ${i + 1} shown, its camera arrived`);
        const shown = (s) => s.structures.structures.map((x) => [x.name, x.visible, Number(x.opacity.toFixed(3))]);

        await press("start");
        let s = await atStep(0);
        assert.equal(s.tour.title, lesson.steps[0].title);
        assert.equal(s.tour.caption, lesson.steps[0].caption);
        assert.deepEqual(shown(s), [["liver", true, 1], ["portal_vein", true, 1], ["tumor", true, 1], ["right_kidney", true, 1]]);
        const inView = (l) => l.x > s.view.x && l.x < s.view.x + s.view.width && l.y > s.view.y && l.y < s.view.y + s.view.height;
        assert.deepEqual(s.view.labels.map((l) => l.text), ["Liver", "Tumour"], "both labels drawn");
        assert.deepEqual(s.view.labels.map((l) => l.faded), [false, true], "the tumour's, inside the opaque liver, faded");
        assert.ok(s.view.labels.every(inView), `the labels' points lie in the view: ${JSON.stringify(s.view.labels)}`);
        // The same for a screen reader, read out as it changes.
        const mirror = () => app.page.locator("#case_lesson li").allTextContents();
        assert.deepEqual(await mirror(), [`Tour step 1 of 3: ${lesson.steps[0].title}. ${lesson.steps[0].caption}`, `Label: Liver. Note: ${lesson.labels[0].note}`, "Label: Tumour (behind a surface)"]);
        const first = drawn(await app.screenshot("L1-step-1"), s.view);
        // The labels' switch takes them away and brings them back.
        await press("labels");
        await app.stateWhen((s) => s.view.labels.length === 0, "the labels off");
        await press("labels");
        await app.stateWhen((s) => s.view.labels.length === 2, "the labels on again");

        await press("next");
        s = await atStep(1);
        assert.deepEqual(shown(s), [["liver", true, 0.3], ["portal_vein", true, 1], ["tumor", true, 1], ["right_kidney", false, 1]], "the kidney hidden, the liver see-through");
        assert.equal(s.structures.current, 2, "the tumour selected");
        s = await app.stateWhen((s) => s.view.labels.length === 2, "the labels at step 2");
        assert.equal(s.view.labels.find((l) => l.text === "Tumour").faded, false, "through the see-through liver, the tumour's label is clear");
        assert.equal(s.view.clip, null);
        const second = drawn(await app.screenshot("L1-step-2"), s.view);
        assert.ok(second.count > 500 && first.count > 500, `both views draw the case: ${first.count}, ${second.count} pixels`);

        // The platform's call, as its own buttons would make it.
        await app.call("showStep", 2);
        s = await atStep(2);
        const clip = lesson.steps[2].clip;
        assert.deepEqual({ ...s.view.clip, at: Math.fround(s.view.clip.at) }, { ...clip, at: Math.fround(clip.at) }, "the step's clip (f32)");
        assert.equal(s.view.toward_segmentation, 0.25);
        // The cut takes away the tumour's label (above it); the liver's lies below the plane.
        s = await app.stateWhen((s) => s.view.labels.length === 1, "one label left by the cut");
        assert.deepEqual(s.view.labels.map((l) => l.text), ["Liver"]);
        assert.deepEqual(shown(s).map((x) => x.slice(1)), [[true, 1], [true, 1], [true, 1], [true, 1]], "the step shows every structure again, opaque");
        await app.screenshot("L1-step-3");

        await press("back");
        s = await atStep(1);
        await press("leave");
        s = await app.stateWhen((s) => s.tour.step === null, "the tour left");
        assert.equal(Math.fround(s.view.camera.yaw), Math.fround(lesson.steps[1].camera.yaw), "the view stays where the tour left it");
        assert.equal(s.tour.left, 1);
        // Back to the step left, and out again.
        await press("resume");
        s = await atStep(1);
        assert.equal(s.tour.left, null);
        await press("leave");
        s = await app.stateWhen((s) => s.tour.step === null, "the tour left again");
        const refused = await app.attempt("showStep", 3);
        assert.equal(refused.ok, false);
        assert.match(refused.message, /the case's tour has steps 0 to 2: no step 3/);

        // The student's drag takes the camera from a flight under way: it stays where the hand
        // left it, not at the step's view.
        const want = lesson.steps[0].camera;
        await app.call("showStep", 0);
        s = await app.stateWhen((s) => s.tour.step === 0 && Math.abs(s.view.camera.yaw - want.yaw) > 0.05 && Math.abs(s.view.camera.yaw - lesson.steps[1].camera.yaw) > 0.01, "the camera on its way");
        const centre = { x: s.view.x + s.view.width / 2, y: s.view.y + s.view.height / 2 };
        await drag(app, "left", centre, { x: 120, y: 0 }, { steps: 3 });
        await new Promise((r) => setTimeout(r, 1500));
        s = await app.state();
        assert.ok(Math.abs(s.view.camera.yaw - want.yaw) > 0.05, `the drag ended the flight: yaw ${s.view.camera.yaw}, the step's ${want.yaw}`);
    }, await viewingTheLesson());
});

testIn(EVERY_RUN, "L7 a step's title and caption and a label's text in the reader's language, the English ones where it has none", { timeout: TIMEOUT }, async () => {
    const de = { title: lesson.steps[0].titles.de, caption: lesson.steps[0].captions.de };
    const viewing = await viewingTheLesson();
    await withApp(async (app) => {
        await phantomShown(app);
        await app.call("showStep", 0);
        const s = await app.stateWhen((s) => s.tour.step === 0, "the first step");
        assert.deepEqual([s.tour.title, s.tour.caption], [de.title, de.caption]);
        const german = await app.stateWhen((s) => arrived(s, 0) && s.view.labels.length === 2, "the labels drawn, the camera arrived");
        assert.equal(german.view.labels[1].text, lesson.labels[1].texts.de, "the tumour's label in German");
        await app.screenshot("L7-step-in-german");
        // The liver's note, in German, shown by a click on its label and hidden by another.
        const liver = german.view.labels[0];
        assert.deepEqual([liver.note, liver.open, german.view.labels[1].note], [lesson.labels[0].notes.de, false, ""]);
        const clickPlate = (p) => app.page.mouse.click(p.x + p.width / 2, p.y + p.height / 2);
        await clickPlate(liver.plate);
        const open = await app.stateWhen((s) => s.view.labels[0]?.open, "the liver's note shown");
        assert.equal(open.tour.step, 0, "the tour stays at its step");
        assert.equal(open.structures.current, german.structures.current, "the click selects nothing");
        assert.equal(open.view.pointed, null, "nor names the liver behind the label");
        await app.screenshot("L7-label-note-in-german");
        await clickPlate(open.view.labels[0].plate);
        await app.stateWhen((s) => s.view.labels.length === 2 && !s.view.labels[0].open, "the note hidden again");
        await app.call("showStep", 1);
        const next = await app.stateWhen((s) => s.tour.step === 1, "the second step");
        assert.equal(next.tour.title, lesson.steps[1].title, "no German title there: the English one");
    }, { ...viewing, query: `${viewing.query}&lang=de` });
    await withApp(async (app) => {
        await phantomShown(app);
        await app.call("showStep", 0);
        const s = await app.stateWhen((s) => s.tour.step === 0, "the first step");
        assert.equal(s.tour.title, lesson.steps[0].title, "a French reader gets the English one");
        const french = await app.stateWhen((s) => s.view.labels.length === 2, "the labels drawn");
        assert.equal(french.view.labels[1].text, lesson.labels[1].text, "and the English label");
    }, { ...viewing, query: `${viewing.query}&lang=fr` });
});

testIn(EVERY_RUN, "L2 the author records tour steps in the page; the case glTF carries them to the viewer and back", { timeout: TIMEOUT }, async () => {
    let exported;
    let authored;
    await withApp(async (app) => {
        await app.loadMesh(readFileSync(PHANTOM_NRRD), "case_phantom_shared.seg.nrrd", "loadCase");
        await app.stateWhen((s) => s.loading === null && s.view.camera, "the case open and framed");
        assert.equal(await app.call("recordStep", { title: "All four", caption: "The whole case." }), 1);
        await app.call("setStructure", { index: 0, opacity: 0.4 });
        await app.call("setView", { from: "S", clip: { axis: "axial", at: 0.5, flip: false } });
        await app.stateWhen((s) => s.view.clip?.axis === "axial", "the clip set");
        assert.equal(await app.call("recordStep", { title: "From above, cut" }), 2);
        const refused = await app.attempt("setLesson", { labels: [{ structure: "spleen", point: [0, 0, 0], text: "Spleen" }] });
        assert.match(refused.message, /setLesson: label 1 \('Spleen'\) names 'spleen', which the case does not have/);
        const lesson = await app.call("lesson");
        assert.deepEqual(lesson.steps.map((s) => s.title), ["All four", "From above, cut"]);
        assert.deepEqual(Object.keys(lesson.steps[1].opacity), ["liver"]);
        assert.equal(Math.fround(lesson.steps[1].opacity.liver), Math.fround(0.4));
        assert.equal(lesson.steps[1].clip.axis, "axial");
        lesson.labels = [{ structure: "tumor", point: [45.12, 38.06, 38.75], text: "Tumour" }];
        lesson.quiz = { structures: [], modes: ["find-it"], pass_mark: 0.5 };
        await app.call("setLesson", lesson);
        authored = await app.call("lesson");
        exported = Buffer.from(await app.call("exportCase", "glb"));
    });
    await withApp(async (app) => {
        const s = await app.stateWhen((s) => s.structures?.structures.length === 4 && s.loading === null, "the case in the viewer");
        assert.equal(s.tour.steps, 2);
        await app.call("showStep", 1);
        const at = await app.stateWhen((s) => s.tour.step === 1 && s.view.clip?.axis === "axial", "the second step");
        assert.equal(at.structures.structures[0].opacity.toFixed(3), "0.400");
    }, { query: "?mode=viewer&case=cases/authored.glb", routes: { "cases/authored.glb": exported } });
    await withApp(async (app) => {
        await app.loadMesh(exported, "authored.glb", "loadCase");
        assert.deepEqual(await app.call("lesson"), authored, "reopened in the page, the same lesson");
    });
});

testIn(EVERY_RUN, "L3 the student takes the case's quiz: find it by clicking, name it by picking, right and wrong at once, the score", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        let s = await phantomShown(app);
        assert.deepEqual(s.quiz, { running: false, modes: ["find-it", "name-it"], pass_mark: 0.5 });
        // The liver under the pointer where its label points, before the quiz hides the labels.
        const liver = s.view.labels.find((l) => l.text === "Liver");
        await app.page.mouse.move(liver.x, liver.y);
        await app.stateWhen((s) => s.view.pointed === "liver", "the liver under its label's point");
        const before = await app.screenshot("L3-before-the-quiz");
        const press = async (key) => {
            const state = await app.stateWhen((s) => s.layout.lesson?.[key], `the quiz's ${key} button`);
            const r = state.layout.lesson[key];
            await app.page.mouse.click(r.x + r.width / 2, r.y + r.height / 2);
        };

        await press("quiz");
        // The names' list gives way to the quiz, and the labels go.
        s = await app.stateWhen((s) => s.quiz.running && s.quiz.question === 0 && s.layout.structures.length === 0 && s.view.labels.length === 0, "the quiz started, no names shown");
        assert.equal(s.quiz.questions, 8, "four structures, two modes");
        let rightFound = 0;
        let rightNamed = 0;
        let highlighted = null;
        for (let q = 0; q < 8; q++) {
            // Drawn: the panel shows this question, not the last one's answer.
            s = await app.stateWhen((s) => s.quiz.question === q && !s.layout.lesson["next-question"], `question ${q + 1}`);
            const { mode, asked, choices } = s.quiz;
            assert.equal(mode, q < 4 ? "find-it" : "name-it", "the author's modes in order");
            let expectRight;
            if (mode === "find-it") {
                assert.deepEqual(choices, []);
                // Always the liver: right once, wrong for the other three.
                await app.page.mouse.click(liver.x, liver.y);
                expectRight = asked === "liver";
                rightFound += expectRight;
            } else {
                assert.equal(choices.length, 4);
                assert.ok(choices.includes(asked), `${asked} among ${choices}`);
                if (highlighted === null) {
                    await frames(app);
                    highlighted = await app.screenshot("L3-name-it-highlighted");
                }
                // Right the first time, wrong after.
                const pick = rightNamed === 0 ? choices.indexOf(asked) : choices.findIndex((c) => c !== asked);
                await press(`choice-${pick}`);
                expectRight = choices[pick] === asked;
                rightNamed += expectRight;
            }
            s = await app.stateWhen((s) => s.quiz.answer !== null, `question ${q + 1} answered`);
            assert.equal(s.quiz.answer.right, expectRight, `${mode} ${asked}: ${JSON.stringify(s.quiz.answer)}`);
            if (mode === "find-it") assert.equal(s.quiz.answer.given, "liver");
            // A screen reader hears the question, the choices and the outcome (written at the
            // next frame's start).
            await frames(app);
            const heard = await app.page.locator("#case_lesson li").allTextContents();
            assert.match(heard[0], new RegExp(`^Quiz: question ${q + 1} of 8\\. ${mode === "find-it" ? `Find it: click the ${asked}` : "Name it"}`));
            assert.equal(heard.at(-1).startsWith(expectRight ? "Right" : "No, that is the"), true, heard.join(" | "));
            if (mode === "name-it") assert.ok(heard.includes(`Choices: ${choices.join(", ")}.`), heard.join(" | "));
            if (q === 0) await app.screenshot("L3-answered");
            await press("next-question");
        }
        assert.equal(rightFound, 1, "the liver found once");
        assert.equal(rightNamed, 1, "one name right");
        s = await app.stateWhen((s) => s.quiz.finished, "the quiz finished");
        assert.equal(s.quiz.question, null);
        assert.equal(s.quiz.right, 2);
        assert.equal(s.quiz.answered, 8);
        assert.equal(s.quiz.score, 0.25);
        assert.equal(s.quiz.passed, false, "2 of 8 is below the pass mark of one half");
        await app.screenshot("L3-score");
        const view = s.view;
        assert.ok(changedPixels(highlighted, before, view) > 2000, "Name it singles out its structure (the others faded)");

        await press("again");
        s = await app.stateWhen((s) => s.quiz.running && s.quiz.question === 0 && s.quiz.answered === 0 && !s.layout.lesson.again, "the quiz again, drawn");
        await press("end-quiz");
        s = await app.stateWhen((s) => !s.quiz.running && s.layout.structures.length === 4, "the quiz ended, the list back");
        assert.equal(s.view.labels.length, 2, "the labels back");
        const refused = await app.attempt("nextQuestion");
        assert.match(refused.message, /nextQuestion: no quiz is running/);
    }, await viewingTheLesson());
});

testIn(EVERY_RUN, "L4 on a phone the tour and the quiz work by touch, the view first", { timeout: TIMEOUT }, async () => {
    const phone = { viewport: { width: 390, height: 844 }, isMobile: true, hasTouch: true, deviceScaleFactor: 1 };
    await withApp(async (app) => {
        let s = await phantomShown(app);
        assert.ok(s.view.width >= 380 && s.view.height > 844 * 0.4, `the view comes first and large: ${JSON.stringify(s.view)}`);
        const tap = async (key) => {
            const state = await app.stateWhen((s) => s.layout.lesson?.[key], `the ${key} button`);
            const r = state.layout.lesson[key];
            assert.ok(r.y > s.view.y + s.view.height, `${key} lies under the view, not over it`);
            await app.page.touchscreen.tap(r.x + r.width / 2, r.y + r.height / 2);
        };
        await tap("start");
        const want = lesson.steps[0].camera;
        s = await app.stateWhen((s) => s.tour.step === 0 && Math.abs(s.view.camera.distance - want.distance) < 1e-3 && s.view.labels.length === 2, "the first step by touch");
        const inView = (l) => l.x > s.view.x && l.x < s.view.x + s.view.width && l.y > s.view.y && l.y < s.view.y + s.view.height;
        assert.ok(s.view.labels.every(inView), `the labels lie in the view: ${JSON.stringify(s.view.labels)}`);
        await app.screenshot("L4-phone-tour");
        const liver = s.view.labels.find((l) => l.text === "Liver");
        assert.equal(liver.faded, false);
        await tap("quiz");
        s = await app.stateWhen((s) => s.quiz.running && s.quiz.question === 0 && !s.layout.lesson["next-question"], "the quiz by touch");
        assert.equal(s.quiz.mode, "find-it");
        await app.page.touchscreen.tap(liver.x, liver.y);
        s = await app.stateWhen((s) => s.quiz.answer !== null && s.layout.lesson["next-question"], "answered by a tap in the view");
        assert.equal(s.quiz.answer.given, "liver");
        await app.screenshot("L4-phone-quiz-answered");
        await tap("end-quiz");
        await app.stateWhen((s) => !s.quiz.running, "the quiz ended by touch");
    }, { ...(await viewingTheLesson()), device: phone });
});

testIn(EVERY_RUN, "L5 the author builds the lesson in the page's Lesson panel: three steps, two labels placed by clicking, a quiz; the viewer plays it", { timeout: TIMEOUT }, async () => {
    let exported;
    await withApp(async (app) => {
        await app.loadMesh(readFileSync(PHANTOM_NRRD), "case_phantom_shared.seg.nrrd", "loadCase");
        let s = await app.stateWhen((s) => s.loading === null && s.view.camera && s.layout.lesson?.["lesson-tab"], "the case open");
        const press = (key) => pressLessonControl(app, key);
        await press("lesson-tab");
        const typeInto = async (key, text) => {
            await press(key);
            await app.page.keyboard.press("Control+A");
            await app.page.keyboard.type(text);
            await frames(app);
        };
        const lessonNow = () => app.call("lesson");
        const lessonWhen = async (test, what) => {
            for (let tries = 0; tries < 100; tries++) {
                const l = await lessonNow();
                if (test(l)) return l;
                await frames(app);
            }
            throw new Error(`the lesson: ${what} not reached: ${JSON.stringify(await lessonNow())}`);
        };

        // Step 1, from the front as opened, titled and captioned in the panel.
        await press("record");
        await lessonWhen((l) => l.steps.length === 1, "one step");
        await typeInto("step-title-0", "The whole abdomen");
        await typeInto("step-caption-0", "Four structures of the phantom.");
        let lesson = await lessonWhen((l) => l.steps[0].title === "The whole abdomen" && l.steps[0].caption === "Four structures of the phantom.", "the first step's words");

        // Two labels placed by clicking: the liver at the view's centre, the kidney found along
        // the row through it.
        s = await app.state();
        const row = s.view.y + s.view.height / 2;
        const pointed = async (x) => {
            await app.page.mouse.move(x, row);
            await frames(app);
            return (await app.state()).view.pointed;
        };
        const under = { liver: [], right_kidney: [] };
        for (let x = s.view.x + 20; x < s.view.x + s.view.width - 20; x += 24) under[await pointed(x)]?.push(x);
        assert.ok(under.liver.length > 2 && under.right_kidney.length > 2, `the liver and the kidney under the row through the centre: ${JSON.stringify(under)}`);
        // Each clicked in the middle of its stretch of the row, away from its outline.
        const spots = Object.entries(under).map(([name, xs]) => [name, xs[Math.floor(xs.length / 2)]]);
        for (const [name, x] of spots) {
            await press("place-label");
            await app.page.mouse.click(x, row);
            await lessonWhen((l) => l.labels.some((label) => label.structure === name), `a label on the ${name}`);
        }
        lesson = await lessonNow();
        const kidney = lesson.labels.findIndex((l) => l.structure === "right_kidney");
        await typeInto(`label-text-${kidney}`, "Right kidney");
        await typeInto(`label-note-${kidney}`, "Filters the blood.");
        await lessonWhen((l) => l.labels[kidney].text === "Right kidney" && l.labels[kidney].note === "Filters the blood.", "the kidney's label text and note");

        // Steps 2 and 3 from above and cut; a fourth recorded, moved up and deleted.
        await app.call("setView", { from: "S" });
        await frames(app);
        await press("record");
        await app.call("setStructure", { index: 0, opacity: 0.3 });
        await app.call("setView", { clip: { axis: "axial", at: 0.5, flip: false } });
        await app.stateWhen((s) => s.view.clip?.axis === "axial", "the cut");
        await press("record");
        await press("record");
        await lessonWhen((l) => l.steps.length === 4, "four steps");
        await press("step-up-3");
        lesson = await lessonWhen((l) => l.steps[2].title === "Step 4", "the fourth step moved up");
        assert.deepEqual(lesson.steps.map((x) => x.title), ["The whole abdomen", "Step 2", "Step 4", "Step 3"]);
        await press("step-delete-2");
        lesson = await lessonWhen((l) => l.steps.length === 3, "three steps");
        assert.deepEqual(lesson.steps.map((x) => x.title), ["The whole abdomen", "Step 2", "Step 3"]);
        assert.equal(lesson.steps[2].clip.axis, "axial");
        assert.equal(Math.fround(lesson.steps[2].opacity.liver), Math.fround(0.3));

        // The quiz: on, both modes, one taken off and put back.
        await press("quiz-on");
        lesson = await lessonWhen((l) => l.quiz !== null, "a quiz");
        assert.deepEqual(lesson.quiz, { structures: [], modes: ["find-it", "name-it"], pass_mark: 0.5 });
        await press("quiz-name-it");
        await lessonWhen((l) => l.quiz.modes.join() === "find-it", "Find it alone");
        await press("quiz-name-it");
        lesson = await lessonWhen((l) => l.quiz.modes.join() === "find-it,name-it", "both modes again");
        // Asked about the liver and the kidney only.
        await press("quiz-structure-3");
        await press("quiz-structure-0");
        lesson = await lessonWhen((l) => l.quiz.structures.length === 2, "two structures asked");
        assert.deepEqual(lesson.quiz.structures, ["right_kidney", "liver"]);

        // The first step's title and caption and the kidney's label in German, the English
        // words kept; a German title emptied again falls back on the English one.
        await typeInto("lesson-language", "de");
        await typeInto("step-title-0", "Der ganze Bauch");
        await typeInto("step-caption-0", "Vier Strukturen des Phantoms.");
        await typeInto(`label-text-${kidney}`, "Rechte Niere");
        await typeInto(`label-note-${kidney}`, "Filtert das Blut.");
        await typeInto("step-title-1", "Von oben");
        lesson = await lessonWhen((l) => l.steps[0].titles.de === "Der ganze Bauch" && l.steps[0].captions.de === "Vier Strukturen des Phantoms." && l.labels[kidney].texts.de === "Rechte Niere" && l.labels[kidney].notes.de === "Filtert das Blut." && l.steps[1].titles.de === "Von oben", "the German words");
        assert.deepEqual([lesson.steps[0].title, lesson.steps[0].caption, lesson.labels[kidney].text, lesson.labels[kidney].note, lesson.steps[1].title], ["The whole abdomen", "Four structures of the phantom.", "Right kidney", "Filters the blood.", "Step 2"], "the English words stay");
        await press("step-title-1");
        await app.page.keyboard.press("Control+A");
        await app.page.keyboard.press("Backspace");
        lesson = await lessonWhen((l) => l.steps[1].titles.de === undefined, "the emptied German title gone");
        assert.equal(lesson.steps[1].title, "Step 2");
        await app.screenshot("L5-lesson-panel-german");
        // What is no language tag edits nothing; English picked again edits the English words.
        await typeInto("lesson-language", "Deutsch!");
        await typeInto("step-title-0", "Nichts");
        await frames(app);
        lesson = await lessonNow();
        assert.deepEqual([lesson.steps[0].title, lesson.steps[0].titles.de], ["The whole abdomen", "Der ganze Bauch"], "nothing edited without a language");
        await press("lesson-language-own");
        await typeInto("step-title-0", "The abdomen");
        lesson = await lessonWhen((l) => l.steps[0].title === "The abdomen", "the English title edited");
        assert.equal(lesson.steps[0].titles.de, "Der ganze Bauch");
        await app.screenshot("L5-lesson-panel");
        exported = Buffer.from(await app.call("exportCase", "glb"));
    });
    await withApp(async (app) => {
        const s = await app.stateWhen((s) => s.structures?.structures.length === 4 && s.loading === null && s.view.labels.length === 2, "the authored case in the viewer, its labels drawn");
        assert.equal(s.tour.steps, 3);
        assert.deepEqual(s.view.labels.map((l) => l.text).sort(), ["Right kidney", "liver"]);
        assert.equal(s.view.labels.find((l) => l.text === "Right kidney").note, "Filters the blood.");
        assert.equal(s.quiz.running, false);
        assert.deepEqual(s.quiz.modes, ["find-it", "name-it"]);
        await app.call("startQuiz");
        const quiz = (await app.stateWhen((s) => s.quiz.running, "the quiz")).quiz;
        assert.equal(quiz.questions, 4, "two structures in two modes");
        assert.ok(["liver", "right_kidney"].includes(quiz.asked));
        await app.call("endQuiz");
        await app.call("showStep", 2);
        await app.stateWhen((s) => s.tour.step === 2 && s.view.clip?.axis === "axial", "the third step, cut");
        await app.screenshot("L5-authored-step-3");
    }, { query: "?mode=viewer&case=cases/authored.glb", routes: { "cases/authored.glb": exported } });
    // A German reader gets the German words the author gave.
    await withApp(async (app) => {
        await app.stateWhen((s) => s.structures?.structures.length === 4 && s.loading === null, "the authored case in the viewer");
        await app.call("showStep", 0);
        const s = await app.stateWhen((s) => s.tour.step === 0 && s.view.labels.length === 2, "the first step, its labels drawn");
        assert.deepEqual([s.tour.title, s.tour.caption], ["Der ganze Bauch", "Vier Strukturen des Phantoms."]);
        assert.deepEqual(s.view.labels.map((l) => l.text).sort(), ["Rechte Niere", "liver"]);
        assert.equal(s.view.labels.find((l) => l.text === "Rechte Niere").note, "Filtert das Blut.");
    }, { query: "?mode=viewer&case=cases/authored.glb&lang=de", routes: { "cases/authored.glb": exported } });
});

testIn(EVERY_RUN, "L6 the author previews the sample's lesson as the student sees it, without exporting, and comes back", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        const sample = JSON.parse(readFileSync(join(ROOT, "web/sample/abdomen_phantom_lesson.json"), "utf8"));
        await app.stateWhen((s) => s.loading === null && s.tour.steps === sample.steps.length && s.layout.lesson?.["lesson-tab"], "the sample case with its lesson");
        const centreOf = (r) => [r.x + r.width / 2, r.y + r.height / 2];
        const press = async (key) => {
            const state = await app.stateWhen((s) => s.layout.lesson?.[key], `the ${key} button`);
            await app.page.mouse.click(...centreOf(state.layout.lesson[key]));
            await frames(app);
        };
        await press("lesson-tab");
        await press("preview");
        // The viewer's panel: the tour, the quiz, the case's list; no smoothing panel.
        let s = await app.stateWhen((s) => s.preview && s.layout.lesson["end-preview"] && s.layout.lesson.start && s.layout.lesson.quiz, "the preview");
        assert.equal(s.mode, "author", "the page stays the authoring page");
        assert.equal(s.layout.lesson.record, undefined, "no Lesson panel in the preview");
        await press("start");
        s = await app.stateWhen((s) => s.tour.step === 0, "the tour's first step");
        assert.equal(s.tour.title, sample.steps[0].title);
        await app.screenshot("L6-preview-tour");
        await press("quiz");
        await app.stateWhen((s) => s.quiz.running && s.layout.lesson["end-preview"], "the quiz in the preview");
        await press("end-preview");
        // Back to authoring: the Lesson panel again, the quiz ended, the lesson as it was.
        s = await app.stateWhen((s) => !s.preview && s.layout.lesson?.record, "the Lesson panel again");
        assert.equal(s.quiz.running, false, "the quiz ended with the preview");
        const lesson = await app.call("lesson");
        assert.deepEqual(lesson.steps.map((step) => step.title), sample.steps.map((step) => step.title));
    });
});
