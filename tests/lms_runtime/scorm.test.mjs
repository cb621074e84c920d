// The SCORM runtime (web/lms/scorm.js) against scorm-again's Scorm12API and Scorm2004API, which
// check every value against their data model: a launch, tour steps, answers, the quiz's end,
// leaving and a relaunch, in both versions.
//
//   node --test tests/lms_runtime/
import { describe, it } from "node:test";
import assert from "node:assert/strict";

import { Scorm12API } from "../../web/node_modules/scorm-again/dist/esm/scorm12.js";
import { Scorm2004API } from "../../web/node_modules/scorm-again/dist/esm/scorm2004.js";
import { ScormSession } from "../../web/lms/scorm.js";
import { ANSWERS, clock, finishedEvent, quietLog, stepEvent } from "./lesson.mjs";

/**
 * An LMS: scorm-again's API of `version`, loaded with `cmi` (what the LMS kept), logging its
 * errors into `errors` and committing nowhere; `calls` lists each call the runtime made.
 */
function lms(version, cmi = null) {
    const errors = [];
    const settings = { lmsCommitUrl: false, autocommit: false, logLevel: 4, onLogMessage: (_level, message) => errors.push(message) };
    const api = version === "1.2" ? new Scorm12API(settings) : new Scorm2004API(settings);
    if (cmi) api.loadFromJSON(cmi);
    const calls = [];
    const lastError = version === "1.2" ? "LMSGetLastError" : "GetLastError";
    for (const name of Object.values(NAMES[version])) {
        const real = api[name].bind(api);
        api[name] = (...args) => {
            const result = real(...args);
            calls.push({ name, args, result, error: api[lastError]() });
            return result;
        };
    }
    return { api, errors, calls, cmi: () => api.renderCMIToJSONObject().cmi };
}

const NAMES = {
    "1.2": { init: "LMSInitialize", set: "LMSSetValue", commit: "LMSCommit", finish: "LMSFinish" },
    2004: { init: "Initialize", set: "SetValue", commit: "Commit", finish: "Terminate" },
};

/** What the LMS keeps for the next launch, as it would launch it: a resume after "suspend". */
function relaunchData(version, cmi) {
    const kept = structuredClone(cmi);
    if (version === "1.2") {
        kept.core.entry = kept.core.exit === "suspend" ? "resume" : "";
        delete kept.core.exit;
        delete kept.core.session_time;
    } else {
        kept.entry = kept.exit === "suspend" ? "resume" : "";
        delete kept.exit;
        delete kept.session_time;
        delete kept.total_time;
    }
    return kept;
}

const LESSON = { steps: 5, quiz: { questions: 4, pass_mark: 0.8 } };

/** A session of `version` on a fresh LMS, started. */
function launched(version, lesson = LESSON, cmi = null) {
    const platform = lms(version, cmi);
    const now = clock();
    const log = quietLog();
    const session = new ScormSession(platform.api, version, lesson, { now, log });
    const started = session.start();
    return { ...platform, session, now, log, started };
}

/** Every SetValue the runtime made was taken, and nothing was logged as an error. */
function assertAllTaken({ calls, errors, log }, version) {
    const refused = calls.filter((c) => c.name === NAMES[version].set && c.result !== "true");
    assert.deepEqual(refused, [], "every value set is valid");
    assert.deepEqual(errors, [], "scorm-again logged no error");
    assert.deepEqual(log.warnings, [], "the runtime warned of nothing");
}

const ISO_TIMESTAMP = /^\d{4}-\d{2}-\d{2}T\d{2}:\d{2}:\d{2}\.\d{2}Z$/;

describe("SCORM 1.2", () => {
    it("a fresh launch is incomplete and suspended; steps set the location, suspend_data and status", () => {
        const run = launched("1.2");
        assert.deepEqual(run.started, { resumeStep: null, language: null });
        let cmi = run.cmi();
        assert.equal(cmi.core.lesson_status, "incomplete");
        assert.equal(cmi.core.exit, "suspend");
        for (const i of [0, 1, 2]) {
            run.now.tick(10_000);
            run.session.onStep(stepEvent(i, 5));
        }
        cmi = run.cmi();
        assert.equal(cmi.core.lesson_location, "3", "the bookmark counts from 1");
        assert.equal(cmi.suspend_data, "1:2:7", "step index 2; steps 0, 1, 2 seen");
        assert.equal(cmi.core.lesson_status, "incomplete");
        assert.equal(cmi.core.session_time, "00:00:30", "scorm-again keeps CMITimespan without zero hundredths");
        const commits = run.calls.filter((c) => c.name === "LMSCommit");
        assert.equal(commits.length, 4, "a commit at the start and after each step");
        assertAllTaken(run, "1.2");
    });

    it("answers are interactions with their type, responses, result, time and latency", () => {
        const run = launched("1.2");
        for (const answer of ANSWERS) run.session.onAnswer(answer);
        const interactions = run.cmi().interactions;
        const got = Object.values(interactions).map((i) => ({
            id: i.id,
            type: i.type,
            pattern: i.correct_responses[0]?.pattern,
            response: i.student_response,
            result: i.result,
            latency: i.latency,
        }));
        assert.deepEqual(got, [
            { id: "find-it-left-kidney", type: "performance", pattern: "left kidney", response: "left kidney", result: "correct", latency: "00:00:02.35" },
            { id: "find-it-liver", type: "performance", pattern: "liver", response: "spleen", result: "wrong", latency: "00:00:04.10" },
            { id: "name-it-right-kidney", type: "fill-in", pattern: "right kidney", response: "right kidney", result: "correct", latency: "00:00:01.5" },
            { id: "name-it-aorta", type: "fill-in", pattern: "aorta", response: "liver", result: "wrong", latency: "00:01:01.5" },
        ]);
        for (const i of Object.values(interactions)) assert.match(i.time, /^\d{2}:\d{2}:\d{2}$/);
        const latencies = run.calls.filter((c) => c.name === "LMSSetValue" && c.args[0].endsWith(".latency")).map((c) => c.args[1]);
        assert.deepEqual(latencies, ["0000:00:02.35", "0000:00:04.10", "0000:00:01.50", "0000:01:01.50"], "HHHH:MM:SS.SS as written");
        assertAllTaken(run, "1.2");
    });

    it("a finished quiz scores 0 to 100 and passes or fails by the pass mark; a pass stands", () => {
        const failing = launched("1.2");
        failing.session.onFinished(finishedEvent(3, 4, 0.8));
        let cmi = failing.cmi();
        assert.deepEqual(cmi.core.score, { raw: "75", min: "0", max: "100" });
        assert.equal(cmi.core.lesson_status, "failed");
        assert.equal(cmi.core.exit, "", "the quiz is done: nothing to resume");
        failing.session.onFinished(finishedEvent(4, 4, 0.8));
        assert.equal(failing.cmi().core.lesson_status, "passed", "a second try passes");
        failing.session.onFinished(finishedEvent(1, 4, 0.8));
        cmi = failing.cmi();
        assert.equal(cmi.core.lesson_status, "passed", "a later fail does not take the pass back");
        assert.equal(cmi.core.score.raw, "100");
        assertAllTaken(failing, "1.2");

        const mastery = launched("1.2", LESSON, { student_data: { mastery_score: "70" } });
        mastery.session.onFinished(finishedEvent(3, 4, 0.8));
        assert.equal(mastery.cmi().core.lesson_status, "passed", "the LMS's mastery score decides");
    });

    it("without a quiz the tour's last step completes the lesson; with one it waits for the quiz", () => {
        const tourOnly = launched("1.2", { steps: 3, quiz: null });
        for (const i of [0, 1, 2]) tourOnly.session.onStep(stepEvent(i, 3));
        assert.equal(tourOnly.cmi().core.lesson_status, "completed");
        assert.equal(tourOnly.cmi().core.exit, "");
        assertAllTaken(tourOnly, "1.2");

        const withQuiz = launched("1.2", { steps: 3, quiz: { questions: 4, pass_mark: 0.8 } });
        for (const i of [0, 1, 2]) withQuiz.session.onStep(stepEvent(i, 3));
        assert.equal(withQuiz.cmi().core.lesson_status, "incomplete", "1.2 has one status: the quiz's to report");
        assert.equal(withQuiz.cmi().core.exit, "suspend");

        const nothing = launched("1.2", { steps: 0, quiz: null });
        nothing.session.onLoaded();
        assert.equal(nothing.cmi().core.lesson_status, "completed", "a case to look at is done once open");
    });

    it("leaving sets the session time and exit, commits and finishes once", () => {
        const run = launched("1.2");
        run.session.onStep(stepEvent(1, 5));
        run.now.tick(3_723_450);
        run.session.finish();
        run.session.finish();
        run.session.onStep(stepEvent(2, 5));
        const finishes = run.calls.filter((c) => c.name === "LMSFinish");
        assert.equal(finishes.length, 1);
        const times = run.calls.filter((c) => c.name === "LMSSetValue" && c.args[0] === "cmi.core.session_time");
        assert.equal(times.at(-1).args[1], "0001:02:03.45");
        const last = run.calls.at(-1);
        assert.equal(last.name, "LMSFinish");
        assert.equal(run.calls.at(-2).name, "LMSCommit", "committed right before finishing");
        assert.equal(run.cmi().core.exit, "suspend");
        assert.equal(run.cmi().core.lesson_location, "2", "nothing after leaving");
        assertAllTaken(run, "1.2");
    });

    it("a relaunch resumes at the saved step, keeps the steps seen and appends interactions", () => {
        const first = launched("1.2");
        for (const i of [0, 1, 2]) first.session.onStep(stepEvent(i, 5));
        first.session.onAnswer(ANSWERS[0]);
        first.session.onAnswer(ANSWERS[1]);
        first.session.finish();

        const second = launched("1.2", LESSON, relaunchData("1.2", first.cmi()));
        assert.deepEqual(second.started, { resumeStep: 2, language: null });
        second.session.onStep(stepEvent(2, 5));
        second.session.onStep(stepEvent(4, 5));
        second.session.onAnswer(ANSWERS[2]);
        const cmi = second.cmi();
        assert.equal(cmi.suspend_data, "1:4:71", "steps 0, 1, 2 and 4 seen");
        assert.equal(cmi.core.lesson_status, "incomplete");
        assert.equal(Object.keys(cmi.interactions).length, 3, "the third answer is interaction 2");
        assert.equal(cmi.interactions[2].id, "name-it-right-kidney");
        assertAllTaken(second, "1.2");
    });

    it("suspend_data stays short for a tour of 200 steps", () => {
        const run = launched("1.2", { steps: 200, quiz: null });
        for (let i = 0; i < 200; i++) run.session.onStep(stepEvent(i, 200));
        const data = run.cmi().suspend_data;
        assert.ok(data.length < 4096, `${data.length} characters`);
        assert.ok(data.length <= 60, `${data.length} characters: four steps a character`);
        assertAllTaken(run, "1.2");
    });

    it("reads the student's language and leaves review mode unrecorded", () => {
        const french = launched("1.2", LESSON, { student_preference: { language: "fr" } });
        assert.equal(french.started.language, "fr");
        const review = launched("1.2", LESSON, { core: { lesson_mode: "review", lesson_status: "passed", entry: "resume", lesson_location: "2" } });
        assert.equal(review.started.resumeStep, 1);
        review.session.onAnswer(ANSWERS[0]);
        review.session.onFinished(finishedEvent(0, 4, 0.8));
        const cmi = review.cmi();
        assert.equal(cmi.core.lesson_status, "passed");
        assert.deepEqual(cmi.interactions, {});
    });
});

describe("SCORM 2004", () => {
    it("a fresh launch is incomplete and suspended; steps set the location, suspend_data and progress", () => {
        const run = launched("2004");
        assert.deepEqual(run.started, { resumeStep: null, language: null });
        let cmi = run.cmi();
        assert.equal(cmi.completion_status, "incomplete");
        assert.equal(cmi.success_status, "unknown");
        assert.equal(cmi.exit, "suspend");
        for (const i of [0, 1, 2]) {
            run.now.tick(10_000);
            run.session.onStep(stepEvent(i, 5));
        }
        cmi = run.cmi();
        assert.equal(cmi.location, "3");
        assert.equal(cmi.suspend_data, "1:2:7");
        assert.equal(cmi.progress_measure, "0.5", "three of five steps and a quiz");
        const times = run.calls.filter((c) => c.name === "SetValue" && c.args[0] === "cmi.session_time");
        assert.equal(times.at(-1).args[1], "PT30S");
        assertAllTaken(run, "2004");
    });

    it("answers are interactions: other for find-it, choice with identifiers for name-it", () => {
        const run = launched("2004");
        run.now.tick(1234);
        for (const answer of ANSWERS) run.session.onAnswer(answer);
        const interactions = Object.values(run.cmi().interactions);
        const got = interactions.map((i) => ({
            id: i.id,
            type: i.type,
            description: i.description,
            pattern: i.correct_responses[0]?.pattern,
            response: i.learner_response,
            result: i.result,
            latency: i.latency,
        }));
        assert.deepEqual(got, [
            { id: "urn:meshsmooth:quiz:find-it-left-kidney", type: "other", description: "Find the left kidney", pattern: "left kidney", response: "left kidney", result: "correct", latency: "PT2.35S" },
            { id: "urn:meshsmooth:quiz:find-it-liver", type: "other", description: "Find the liver", pattern: "liver", response: "spleen", result: "incorrect", latency: "PT4.1S" },
            { id: "urn:meshsmooth:quiz:name-it-right-kidney", type: "choice", description: "Name the structure shown", pattern: "right-kidney", response: "right-kidney", result: "correct", latency: "PT1.5S" },
            { id: "urn:meshsmooth:quiz:name-it-aorta", type: "choice", description: "Name the structure shown", pattern: "aorta", response: "liver", result: "incorrect", latency: "PT1M1.5S" },
        ]);
        for (const i of interactions) {
            assert.match(i.timestamp, ISO_TIMESTAMP);
            assert.equal(i.timestamp, "2026-05-01T09:00:01.23Z");
        }
        assertAllTaken(run, "2004");
    });

    it("a finished quiz sets the scaled score, success by the pass mark, and completion", () => {
        const run = launched("2004");
        run.session.onStep(stepEvent(0, 5));
        run.session.onFinished(finishedEvent(3, 4, 0.8));
        let cmi = run.cmi();
        assert.deepEqual(cmi.score, { scaled: "0.75", raw: "75", min: "0", max: "100" });
        assert.equal(cmi.success_status, "failed");
        assert.equal(cmi.completion_status, "completed");
        assert.equal(cmi.progress_measure, "1");
        assert.equal(cmi.exit, "normal");
        run.session.onFinished(finishedEvent(4, 5, 0.8));
        cmi = run.cmi();
        assert.equal(cmi.success_status, "passed", "four of five reach the mark of 0.8");
        assert.equal(cmi.score.scaled, "0.8");
        run.session.onFinished(finishedEvent(2, 3, 0.8));
        assert.equal(run.cmi().success_status, "passed", "a pass stands");
        assertAllTaken(run, "2004");

        const lms_mark = launched("2004", LESSON, { scaled_passing_score: "0.6" });
        lms_mark.session.onFinished(finishedEvent(2, 3, 0.8));
        assert.equal(lms_mark.cmi().success_status, "passed", "the LMS's scaled passing score decides");
        assert.equal(lms_mark.cmi().score.scaled, "0.6666667");
    });

    it("the tour's last step completes the lesson; exit stays suspend until the quiz is done", () => {
        const run = launched("2004");
        for (const i of [0, 1, 2, 3, 4]) run.session.onStep(stepEvent(i, 5));
        const cmi = run.cmi();
        assert.equal(cmi.completion_status, "completed");
        assert.equal(cmi.progress_measure, "1");
        assert.equal(cmi.exit, "suspend", "the quiz is still to take");
        assertAllTaken(run, "2004");

        const tourOnly = launched("2004", { steps: 2, quiz: null });
        tourOnly.session.onStep(stepEvent(0, 2));
        assert.equal(tourOnly.cmi().progress_measure, "0.5");
        tourOnly.session.onStep(stepEvent(1, 2));
        assert.equal(tourOnly.cmi().exit, "normal");
    });

    it("leaving sets the ISO session time, commits and terminates once", () => {
        const run = launched("2004");
        run.now.tick(3_723_450);
        run.session.finish();
        run.session.finish();
        assert.equal(run.calls.filter((c) => c.name === "Terminate").length, 1);
        const times = run.calls.filter((c) => c.name === "SetValue" && c.args[0] === "cmi.session_time");
        assert.equal(times.at(-1).args[1], "PT1H2M3.45S");
        assert.equal(run.calls.at(-2).name, "Commit");
        assertAllTaken(run, "2004");
    });

    it("a relaunch resumes at the saved step, keeps the steps seen and appends interactions", () => {
        const first = launched("2004");
        for (const i of [0, 1, 2]) first.session.onStep(stepEvent(i, 5));
        for (const answer of ANSWERS) first.session.onAnswer(answer);
        first.session.finish();

        const second = launched("2004", LESSON, relaunchData("2004", first.cmi()));
        assert.deepEqual(second.started, { resumeStep: 2, language: null });
        second.session.onStep(stepEvent(2, 5));
        second.session.onStep(stepEvent(3, 5));
        second.session.onAnswer(ANSWERS[0]);
        const cmi = second.cmi();
        assert.equal(cmi.suspend_data, "1:3:f");
        assert.equal(cmi.progress_measure, "0.6666667", "four of five steps and a quiz");
        assert.equal(Object.keys(cmi.interactions).length, 5, "the fifth answer is interaction 4");
        assert.equal(cmi.interactions[4].id, "urn:meshsmooth:quiz:find-it-left-kidney");
        assertAllTaken(second, "2004");
    });

    it("a normal exit starts afresh; the learner's language is passed on", () => {
        const first = launched("2004", { steps: 2, quiz: null });
        first.session.onStep(stepEvent(0, 2));
        first.session.onStep(stepEvent(1, 2));
        first.session.finish();
        const kept = relaunchData("2004", first.cmi());
        assert.equal(kept.entry, "", "exit normal: no resume");
        kept.learner_preference = { language: "de-CH" };
        const second = launched("2004", { steps: 2, quiz: null }, kept);
        assert.deepEqual(second.started, { resumeStep: null, language: "de-CH" });
    });
});

describe("an LMS that refuses", () => {
    /** An API of `version` whose every call fails with error 101. */
    function refusing(version, { initialize = true } = {}) {
        const calls = [];
        const names = version === "1.2"
            ? ["LMSInitialize", "LMSGetValue", "LMSSetValue", "LMSCommit", "LMSFinish"]
            : ["Initialize", "GetValue", "SetValue", "Commit", "Terminate"];
        const api = {};
        for (const name of names) {
            api[name] = (...args) => {
                calls.push(name);
                if (name.endsWith("Initialize")) return initialize ? "true" : "false";
                return name.endsWith("GetValue") ? "" : "false";
            };
        }
        api[version === "1.2" ? "LMSGetLastError" : "GetLastError"] = () => "101";
        api[version === "1.2" ? "LMSGetErrorString" : "GetErrorString"] = (code) => (code === "101" ? "General exception" : "");
        return { api, calls };
    }

    for (const version of ["1.2", "2004"]) {
        it(`SCORM ${version}: failed calls are warned of with the error code and text, and the lesson goes on`, () => {
            const { api } = refusing(version);
            const log = quietLog();
            const session = new ScormSession(api, version, LESSON, { now: clock(), log });
            assert.deepEqual(session.start(), { resumeStep: null, language: null });
            session.onStep(stepEvent(0, 5));
            session.onAnswer(ANSWERS[0]);
            session.onFinished(finishedEvent(4, 4, 0.8));
            session.finish();
            assert.ok(log.warnings.length > 0);
            assert.ok(log.warnings.every((w) => /failed: error 101 \(General exception\)$/.test(w)), log.warnings.join("\n"));
        });

        it(`SCORM ${version}: a refused initialize leaves the lesson unrecorded`, () => {
            const { api, calls } = refusing(version, { initialize: false });
            const log = quietLog();
            const session = new ScormSession(api, version, LESSON, { now: clock(), log });
            assert.equal(session.start(), null);
            session.onStep(stepEvent(0, 5));
            session.finish();
            assert.equal(calls.length, 1, "nothing after the refused initialize");
            assert.equal(log.warnings.length, 1);
        });
    }

    it("an API that throws is warned of, never thrown on", () => {
        const log = quietLog();
        const api = { LMSInitialize: () => "true", LMSGetLastError: () => "0", LMSGetErrorString: () => "" };
        for (const name of ["LMSGetValue", "LMSSetValue", "LMSCommit", "LMSFinish"]) api[name] = () => { throw new Error("the LMS's frame went away"); };
        const session = new ScormSession(api, "1.2", LESSON, { now: clock(), log });
        session.start();
        session.onStep(stepEvent(0, 5));
        session.finish();
        assert.ok(log.warnings.some((w) => w.includes("threw: the LMS's frame went away")));
    });
});
