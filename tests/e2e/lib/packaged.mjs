// Driving a packaged lesson: the phantom's package built by the CLI and unzipped, and the
// student's clicks and taps on the viewer framed by its launch page, framed in turn by a test LMS.
import { execFileSync } from "node:child_process";
import { join } from "node:path";

import * as cli from "./cli.mjs";
import { ROOT, VIEWER_DIST, meshPath } from "./paths.mjs";

export const LESSON_FILE = join(ROOT, "tests/data/phantom_lesson.json");

/** `meshsmooth case package` of the phantom with its lesson in `format` into `zip`, unzipped into `folder`. */
export async function phantomPackage(format, zip, folder) {
    const map = meshPath("labelmaps/case_phantom_shared.seg.nrrd");
    await cli.cliJson("case", "package", map, "--search", "local", "--lesson", LESSON_FILE, "--title", "Abdominal phantom", "--format", format, "--viewer", VIEWER_DIST, "-o", zip, "--json");
    execFileSync("python3", ["-m", "zipfile", "-e", zip, folder]);
}

/** The viewer's frame inside the launch page's, with its API and its place on the LMS page. */
export async function viewerOf(page, path = "/package/viewer/index.html") {
    const deadline = Date.now() + 60_000;
    for (;;) {
        const frame = page.frames().find((f) => URL.canParse(f.url()) && new URL(f.url()).pathname === path);
        if (frame && (await frame.evaluate(() => Boolean(window.meshsmooth)).catch(() => false))) {
            const box = await (await frame.frameElement()).boundingBox();
            return { frame, box };
        }
        if (Date.now() > deadline) throw new Error("the packaged viewer did not start");
        await new Promise((resolve) => setTimeout(resolve, 200));
    }
}

/** Polls the viewer's `state()` until `test` holds. */
export async function stateWhen(viewer, test, what) {
    const deadline = Date.now() + 30_000;
    for (;;) {
        const state = await viewer.frame.evaluate(() => window.meshsmooth.state());
        if (test(state)) return state;
        if (Date.now() > deadline) throw new Error(`timed out waiting for ${what}`);
        await new Promise((resolve) => setTimeout(resolve, 100));
    }
}

/** A click (or a tap) at a point of the viewer's page, on the LMS page. */
export async function touch(page, viewer, x, y, tap) {
    const [px, py] = [viewer.box.x + x, viewer.box.y + y];
    if (tap) await page.touchscreen.tap(px, py);
    else await page.mouse.click(px, py);
}

export async function press(page, viewer, key, tap = false) {
    const s = await stateWhen(viewer, (s) => s.layout.lesson?.[key], `the ${key} button`);
    const r = s.layout.lesson[key];
    await touch(page, viewer, r.x + r.width / 2, r.y + r.height / 2, tap);
}

export const phantomShown = (viewer) => stateWhen(viewer, (s) => s.structures?.structures.length === 4 && s.loading === null, "the phantom's four structures");

/**
 * A point of the view on `name` as the view stands: the pointer is moved over the view from its
 * centre outwards until the viewer says that structure lies under it.
 */
export async function pointOn(page, viewer, name) {
    const s = await stateWhen(viewer, (s) => s.view, "the view");
    const { x, y, width, height } = s.view;
    const points = [];
    for (let i = 1; i < 12; i++) for (let j = 1; j < 12; j++) points.push([x + (width * i) / 12, y + (height * j) / 12]);
    const [cx, cy] = [x + width / 2, y + height / 2];
    points.sort((a, b) => Math.hypot(a[0] - cx, a[1] - cy) - Math.hypot(b[0] - cx, b[1] - cy));
    for (const [px, py] of points) {
        await page.mouse.move(viewer.box.x + px, viewer.box.y + py);
        // Two frames for the view to pick what lies under the pointer.
        await new Promise((resolve) => setTimeout(resolve, 150));
        const pointed = await viewer.frame.evaluate(() => window.meshsmooth.state().view.pointed);
        if (pointed === name) return { x: px, y: py };
    }
    throw new Error(`no point of the view shows the ${name}`);
}

/**
 * Takes the quiz by clicks (or taps): "Find it" by clicking the liver (right once), "Name it" by
 * picking the right name `namedRight` times, a wrong one after. Returns the answers as the
 * viewer saw them; `onAnswered(q)` runs after each.
 */
export async function takeQuiz(page, viewer, namedRight, tap = false, onAnswered = async () => {}) {
    await press(page, viewer, "quiz", tap);
    let s = await stateWhen(viewer, (s) => s.quiz?.running && s.quiz.question === 0, "the quiz started");
    const liver = await pointOn(page, viewer, "liver");
    const answers = [];
    for (let q = 0; q < s.quiz.questions; q++) {
        s = await stateWhen(viewer, (s) => s.quiz.question === q && !s.layout.lesson["next-question"], `question ${q + 1}`);
        const { mode, asked, choices } = s.quiz;
        if (mode === "find-it") {
            await touch(page, viewer, liver.x, liver.y, tap);
        } else {
            const named = answers.filter((a) => a.mode === "name-it" && a.right).length;
            const pick = named < namedRight ? choices.indexOf(asked) : choices.findIndex((c) => c !== asked);
            await press(page, viewer, `choice-${pick}`, tap);
        }
        s = await stateWhen(viewer, (s) => s.quiz.answer !== null, `question ${q + 1} answered`);
        answers.push({ mode, asked, ...s.quiz.answer });
        await onAnswered(q);
        await press(page, viewer, "next-question", tap);
    }
    await stateWhen(viewer, (s) => s.quiz.finished, "the quiz finished");
    return answers;
}

