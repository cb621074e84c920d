// The cmi5 runtime (web/lms/cmi5.js) against a fake LMS (fake_lrs.mjs): the token fetched once,
// the launch data read, the statements in cmi5's order with the student, the registration and
// the context template on each, the launch modes, and a record store that fails for a while.
import { describe, it } from "node:test";
import assert from "node:assert/strict";

import { Cmi5Session, cmi5Launch } from "../../web/lms/cmi5.js";
import { ANSWERS, clock, finishedEvent, quietLog, stepEvent } from "./lesson.mjs";
import { ACTIVITY_ID, ACTOR, ENDPOINT, FETCH_URL, PUBLISHER_ID, REGISTRATION, SESSION_ID, TOKEN, fakeLms, launchData, launchQuery, memoryStorage } from "./fake_lrs.mjs";

const LESSON = { steps: 3, quiz: { questions: 5, pass_mark: 0.8 } };
const CMI5_CATEGORY = "https://w3id.org/xapi/cmi5/context/categories/cmi5";
const MOVEON_CATEGORY = "https://w3id.org/xapi/cmi5/context/categories/moveon";
const SESSION_EXTENSION = "https://w3id.org/xapi/cmi5/context/extensions/sessionid";
const MASTERY_EXTENSION = "https://w3id.org/xapi/cmi5/context/extensions/masteryscore";
const UUID = /^[0-9a-f]{8}-[0-9a-f]{4}-4[0-9a-f]{3}-[89ab][0-9a-f]{3}-[0-9a-f]{12}$/;

/** A session launched by `lms`, on `storage` (the tab's sessionStorage). */
function launch(lms, { storage = memoryStorage(), lesson = LESSON, now = clock() } = {}) {
    const log = quietLog();
    const session = new Cmi5Session(cmi5Launch(launchQuery()), lesson, { fetch: lms.fetch, storage, now, log, retry: { first: 2, max: 10 } });
    return { session, log, storage, now };
}

const verbs = (statements) => statements.map((s) => s.verb.display["en-US"]);
const categories = (s) => (s.context.contextActivities?.category ?? []).map((a) => a.id);
const byTime = (statements) => [...statements].sort((a, b) => a.timestamp.localeCompare(b.timestamp));

/** A whole session: a step or two, the four answers, the quiz's end, leaving. */
async function playQuiz(run, finished, { steps = [0, 1] } = {}) {
    const result = await run.session.start();
    run.session.onLoaded();
    for (const i of steps) {
        run.now.tick(5000);
        run.session.onStep(stepEvent(i, 3));
    }
    for (const answer of ANSWERS) {
        run.now.tick(answer.ms);
        run.session.onAnswer(answer);
    }
    run.now.tick(1000);
    run.session.onFinished(finished);
    run.now.tick(2000);
    run.session.finish();
    await run.session.whenSent();
    return result;
}

describe("cmi5", () => {
    it("reads the launch parameters, or finds none", () => {
        assert.deepEqual(cmi5Launch(launchQuery()), { endpoint: ENDPOINT, fetchUrl: FETCH_URL, actor: ACTOR, registration: REGISTRATION, activityId: ACTIVITY_ID });
        const noSlash = new URLSearchParams(launchQuery());
        noSlash.set("endpoint", "https://lrs.example/xapi");
        assert.equal(cmi5Launch(`?${noSlash}`).endpoint, ENDPOINT);
        assert.equal(cmi5Launch("?endpoint=x&fetch=y"), null);
        assert.equal(cmi5Launch(""), null);
        const badActor = new URLSearchParams(launchQuery());
        badActor.set("actor", "{not json");
        assert.equal(cmi5Launch(`?${badActor}`), null);
    });

    it("fetches the token once, reads the launch data and the learner's preferences", async () => {
        const lms = fakeLms({ profile: { languagePreference: "fr-FR,en-US", audioPreference: "on" } });
        const run = launch(lms);
        const result = await run.session.start();
        assert.deepEqual(result, { resumeStep: null, language: "fr-FR,en-US", launchMode: "Normal", returnURL: "https://lms.example/course/7", ended: false });
        assert.equal(lms.tokenCalls, 1);
        const [token, state] = lms.requests;
        assert.equal(token.url, FETCH_URL);
        assert.equal(token.method, "POST");
        const url = new URL(state.url);
        assert.equal(`${url.origin}${url.pathname}`, `${ENDPOINT}activities/state`);
        assert.equal(url.searchParams.get("stateId"), "LMS.LaunchData");
        assert.equal(url.searchParams.get("activityId"), ACTIVITY_ID);
        assert.equal(url.searchParams.get("registration"), REGISTRATION);
        assert.deepEqual(JSON.parse(url.searchParams.get("agent")), ACTOR);
        for (const request of lms.requests.slice(1)) {
            assert.equal(request.headers.Authorization, `Basic ${TOKEN}`);
            assert.equal(request.headers["X-Experience-API-Version"], "1.0.3");
        }
        await run.session.whenSent();
        assert.deepEqual(verbs(lms.statements), ["initialized"]);
        assert.ok(!lms.requests.some((r) => r.method === "PUT" && r.url.includes("LMS.LaunchData")), "the launch data is only read");
    });

    it("states initialized, the viewer's statements, passed, completed and terminated, in order", async () => {
        const lms = fakeLms();
        const run = launch(lms);
        await playQuiz(run, finishedEvent(4, 5, 0.8));
        const statements = lms.statements;
        assert.deepEqual(verbs(statements), ["initialized", "experienced", "experienced", "answered", "answered", "answered", "answered", "passed", "completed", "terminated"]);
        assert.deepEqual(byTime(statements), statements, "the timestamps keep the same order");
        assert.equal(new Set(statements.map((s) => s.timestamp)).size, statements.length, "no two at once");
        assert.equal(new Set(statements.map((s) => s.id)).size, statements.length);
        for (const s of statements) {
            assert.match(s.id, UUID);
            assert.match(s.timestamp, /^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z$/);
            assert.deepEqual(s.actor, ACTOR);
            assert.equal(s.context.registration, REGISTRATION);
            assert.equal(s.context.extensions[SESSION_EXTENSION], SESSION_ID, "the template's session id");
            assert.deepEqual(s.context.contextActivities.grouping, [{ objectType: "Activity", id: PUBLISHER_ID }], "the template's publisher id");
        }
        const defined = statements.filter((s) => ["initialized", "passed", "completed", "terminated"].includes(s.verb.display["en-US"]));
        for (const s of defined) {
            assert.equal(s.object.id, ACTIVITY_ID);
            assert.ok(categories(s).includes(CMI5_CATEGORY), `${s.verb.id} is cmi5 defined`);
            assert.equal(categories(s).includes(MOVEON_CATEGORY), ["passed", "completed"].includes(s.verb.display["en-US"]), `${s.verb.id}: moveon only with success or completion`);
        }
        const allowed = statements.filter((s) => !defined.includes(s));
        for (const s of allowed) {
            assert.match(s.object.id, /^urn:meshsmooth:case:Abdominal-phantom#/, "the viewer's object");
            assert.deepEqual(categories(s), [], "an allowed statement has no cmi5 category");
            assert.deepEqual(s.context.contextActivities.parent, [{ objectType: "Activity", id: ACTIVITY_ID }]);
        }
        assert.equal(allowed[0].context.extensions["urn:meshsmooth:step"], 1, "the viewer's own context is kept");
        assert.deepEqual(allowed[3].result, { success: false, response: "spleen", duration: "PT4.10S" });
        assert.equal(allowed[3].object.definition.interactionType, "other");

        const [initialized, , , , , , , passed, completed, terminated] = statements;
        assert.equal(initialized.result, undefined);
        assert.deepEqual(passed.result, { score: { scaled: 0.8, raw: 4, min: 0, max: 5 }, success: true, duration: "PT1M20.45S" });
        assert.equal(passed.context.extensions[MASTERY_EXTENSION], undefined, "no mastery score was given");
        assert.deepEqual(completed.result, { completion: true, duration: "PT1M20.45S" });
        assert.deepEqual(terminated.result, { duration: "PT1M22.45S" });
        assert.deepEqual(run.log.warnings, []);
        assert.deepEqual(lms.documents.get("meshsmooth.progress"), { progress: "1:1:3", completed: true, passed: true });
    });

    it("judges by the LMS's mastery score, holds a fail until the end, and a pass in the same session replaces it", async () => {
        const lms = fakeLms({ documents: { "LMS.LaunchData": launchData({ masteryScore: 0.8 }) } });
        const run = launch(lms);
        // The viewer's own mark passes three of five; the LMS's mastery score does not.
        await run.session.start();
        run.now.tick(1000);
        run.session.onFinished(finishedEvent(3, 5, 0.6));
        await run.session.whenSent();
        assert.deepEqual(verbs(lms.statements), ["initialized", "completed"], "the fail is held");
        run.now.tick(1000);
        run.session.finish();
        await run.session.whenSent();
        const statements = lms.statements;
        assert.deepEqual(verbs(statements), ["initialized", "completed", "failed", "terminated"]);
        assert.deepEqual(verbs(byTime(statements)), ["initialized", "failed", "completed", "terminated"], "in time the fail comes first");
        const failed = statements[2];
        assert.deepEqual(failed.result, { score: { scaled: 0.6, raw: 3, min: 0, max: 5 }, success: false, duration: "PT1S" });
        assert.equal(failed.context.extensions[MASTERY_EXTENSION], 0.8);
        assert.ok(categories(failed).includes(MOVEON_CATEGORY));

        const retry = fakeLms({ documents: { "LMS.LaunchData": launchData({ masteryScore: 0.8 }) } });
        const second = launch(retry);
        await second.session.start();
        second.session.onFinished(finishedEvent(2, 5, 0.8));
        second.session.onFinished(finishedEvent(5, 5, 0.8));
        second.session.onFinished(finishedEvent(1, 5, 0.8));
        second.session.finish();
        await second.session.whenSent();
        assert.deepEqual(verbs(retry.statements), ["initialized", "completed", "passed", "terminated"], "one of passed or failed a session, and no fail after a pass");
    });

    it("states nothing of passing or completion in Browse and Review mode", async () => {
        for (const launchMode of ["Browse", "Review"]) {
            const lms = fakeLms({ documents: { "LMS.LaunchData": launchData({ launchMode }) } });
            const run = launch(lms);
            const result = await playQuiz(run, finishedEvent(5, 5, 0.8), { steps: [0, 1, 2] });
            assert.equal(result.launchMode, launchMode);
            assert.deepEqual(verbs(lms.statements), ["initialized", "experienced", "experienced", "experienced", "answered", "answered", "answered", "answered", "terminated"]);
            assert.ok(!lms.requests.some((r) => r.method === "PUT"), "no progress document either");
        }
    });

    it("completes once when the tour's last step is seen", async () => {
        const lms = fakeLms();
        const run = launch(lms, { lesson: { steps: 3, quiz: null } });
        await run.session.start();
        for (const i of [0, 1, 2, 1, 2]) run.session.onStep(stepEvent(i, 3));
        run.session.finish();
        await run.session.whenSent();
        assert.deepEqual(verbs(lms.statements), ["initialized", "experienced", "experienced", "experienced", "completed", "experienced", "experienced", "terminated"]);
    });

    it("keeps the token and the session across a reload of the page", async () => {
        const lms = fakeLms();
        const storage = memoryStorage();
        const first = launch(lms, { storage });
        await first.session.start();
        first.session.onStep(stepEvent(0, 3));
        await first.session.whenSent();

        const reloaded = launch(lms, { storage });
        const result = await reloaded.session.start();
        assert.equal(result.resumeStep, 0, "back at the step shown");
        reloaded.session.onStep(stepEvent(1, 3));
        reloaded.session.finish();
        await reloaded.session.whenSent();
        assert.equal(lms.tokenCalls, 1, "the token URL is posted to once");
        assert.deepEqual(verbs(lms.statements), ["initialized", "experienced", "experienced", "terminated"], "one initialized a session");
        assert.deepEqual(reloaded.log.warnings, []);

        const afterTheEnd = launch(lms, { storage });
        assert.equal((await afterTheEnd.session.start()).ended, true, "a session that terminated stays ended");
        afterTheEnd.session.onStep(stepEvent(2, 3));
        afterTheEnd.session.finish();
        await afterTheEnd.session.whenSent();
        assert.equal(lms.statements.length, 4);
    });

    it("a new session knows what earlier ones stated: a pass and completion are not stated again", async () => {
        const lms = fakeLms({ documents: { "meshsmooth.progress": { progress: "1:2:7", completed: true, passed: true } } });
        const run = launch(lms);
        const result = await playQuiz(run, finishedEvent(2, 5, 0.8), { steps: [2] });
        assert.equal(result.resumeStep, 2);
        assert.deepEqual(verbs(lms.statements), ["initialized", "experienced", "answered", "answered", "answered", "answered", "terminated"]);
    });

    it("a record store down for a while loses no statement and keeps their order", async () => {
        const lms = fakeLms();
        const storage = memoryStorage();
        const run = launch(lms, { storage });
        await run.session.start();
        await run.session.whenSent();
        let failures = 0;
        lms.outage = (request) => {
            if (request.method !== "POST" || failures >= 7) return null;
            failures++;
            return failures <= 4 ? "network" : 503;
        };
        run.session.onStep(stepEvent(0, 3));
        run.session.onAnswer(ANSWERS[0]);
        run.session.onAnswer(ANSWERS[1]);
        const queued = JSON.parse(storage.getItem(`meshsmooth.cmi5 ${FETCH_URL} outbox`));
        assert.ok(queued.length >= 3, "the waiting statements are kept for a reload");
        run.session.onFinished(finishedEvent(5, 5, 0.8));
        run.session.finish({ keepalive: false });
        await run.session.whenSent();
        assert.equal(failures, 7);
        assert.deepEqual(verbs(lms.statements), ["initialized", "experienced", "answered", "answered", "passed", "completed", "terminated"]);
        assert.deepEqual(byTime(lms.statements), lms.statements);
        assert.deepEqual(JSON.parse(storage.getItem(`meshsmooth.cmi5 ${FETCH_URL} outbox`)), []);
        assert.deepEqual(run.log.warnings, [], "an outage is waited out, not reported");
    });

    it("waits out a store that cannot give the launch data yet; events meanwhile follow initialized", async () => {
        const lms = fakeLms();
        let refusals = 0;
        lms.outage = (request) => (request.url.includes("LMS.LaunchData") && refusals++ < 3 ? 502 : null);
        const run = launch(lms);
        const starting = run.session.start();
        run.now.tick(100);
        run.session.onLoaded();
        run.session.onStep(stepEvent(0, 3));
        const result = await starting;
        assert.equal(result.launchMode, "Normal");
        await run.session.whenSent();
        assert.deepEqual(verbs(lms.statements), ["initialized", "experienced"]);
        assert.deepEqual(byTime(lms.statements), lms.statements);
    });

    it("sends the last statements with keepalive when the page goes away", async () => {
        const lms = fakeLms();
        const run = launch(lms);
        await run.session.start();
        await run.session.whenSent();
        lms.outage = (request) => (request.keepalive ? null : "network");
        run.session.onStep(stepEvent(0, 3));
        run.session.finish();
        await new Promise((resolve) => setTimeout(resolve, 20));
        const kept = lms.requests.filter((r) => r.keepalive);
        assert.ok(kept.some((r) => JSON.parse(r.body).verb?.display?.["en-US"] === "terminated"));
        assert.deepEqual(verbs(lms.statements).slice(0, 1), ["initialized"]);
        assert.ok(verbs(lms.statements).includes("terminated"));
        // The page stayed after all: the outbox still sends in order, the store knowing each by its id.
        lms.outage = () => null;
        await run.session.whenSent();
        assert.deepEqual(verbs(lms.statements), ["initialized", "experienced", "terminated"]);
    });

    it("a token the LMS will not give leaves the lesson unrecorded", async () => {
        const lms = fakeLms();
        lms.tokenCalls = 1;
        const run = launch(lms);
        assert.equal(await run.session.start(), null);
        run.session.onStep(stepEvent(0, 3));
        run.session.finish();
        assert.deepEqual(lms.statements, []);
        assert.match(run.log.warnings[0], /already been returned/);
    });
});
