// The lesson as a cmi5 assignable unit: the launch URL names the record store, the one-time
// token URL, the student, the registration and this unit's activity id. The viewer's
// statements go to the store as "cmi5 allowed" statements; the unit's own (initialized,
// completed, passed or failed, terminated) follow the order and the once-only rules of the
// cmi5 specification. It only uses the `fetch` and the storage it is given, so Node tests it
// against a fake store.

import { isoDuration, languageList } from "./formats.js";
import { Outbox } from "./outbox.js";
import { Progress } from "./progress.js";
import { RecordStore } from "./record_store.js";

const VERB = (name) => ({ id: `http://adlnet.gov/expapi/verbs/${name}`, display: { "en-US": name } });
const VERBS = {
    initialized: VERB("initialized"),
    completed: VERB("completed"),
    passed: VERB("passed"),
    failed: VERB("failed"),
    terminated: VERB("terminated"),
};
const CATEGORY_CMI5 = "https://w3id.org/xapi/cmi5/context/categories/cmi5";
const CATEGORY_MOVEON = "https://w3id.org/xapi/cmi5/context/categories/moveon";
const MASTERY_SCORE = "https://w3id.org/xapi/cmi5/context/extensions/masteryscore";
/** This unit's own state document: where the student is, and what was stated once for good. */
const PROGRESS_STATE = "meshsmooth.progress";

/**
 * The cmi5 launch parameters in the page's query (`location.search`), or null when one is
 * missing (the page was not launched by a cmi5 LMS).
 */
export function cmi5Launch(search) {
    const query = new URLSearchParams(search);
    const [endpoint, fetchUrl, actorText, registration, activityId] = ["endpoint", "fetch", "actor", "registration", "activityId"].map((k) => query.get(k));
    if (!endpoint || !fetchUrl || !actorText || !registration || !activityId) return null;
    let actor;
    try {
        actor = JSON.parse(actorText);
    } catch {
        return null;
    }
    return { endpoint: endpoint.endsWith("/") ? endpoint : `${endpoint}/`, fetchUrl, actor, registration, activityId };
}

/** A version 4 UUID; `crypto.randomUUID` exists only on secure pages. */
export function randomUuid() {
    if (globalThis.crypto?.randomUUID) return globalThis.crypto.randomUUID();
    const b = globalThis.crypto.getRandomValues(new Uint8Array(16));
    b[6] = (b[6] & 0x0f) | 0x40;
    b[8] = (b[8] & 0x3f) | 0x80;
    const hex = Array.from(b, (x) => x.toString(16).padStart(2, "0")).join("");
    return `${hex.slice(0, 8)}-${hex.slice(8, 12)}-${hex.slice(12, 16)}-${hex.slice(16, 20)}-${hex.slice(20)}`;
}

/** A list of `contextActivities` (xAPI allows one object or an array). */
const list = (v) => (Array.isArray(v) ? v : v ? [v] : []);
const clone = (v) => (v === undefined ? undefined : JSON.parse(JSON.stringify(v)));

export class Cmi5Session {
    /**
     * `launch`: from `cmi5Launch`; `lesson`: launch.json's `{steps, quiz}`; `fetch` and
     * `storage` (sessionStorage, or null) are the page's; `retry` the pauses of the outbox.
     */
    constructor(launch, lesson, { fetch, storage = null, now = () => Date.now(), uuid = randomUuid, timers = globalThis, retry, log = console } = {}) {
        Object.assign(this, { launch, fetch, storage, now, uuid, timers, log });
        this.retryPauses = retry ?? { first: 1000, max: 60000 };
        this.progress = new Progress(lesson);
        this.key = `meshsmooth.cmi5 ${launch.fetchUrl}`;
        // What this session did, kept for a reload of the page (the same session).
        this.saved = {
            token: null,
            initializedAt: null,
            initialized: false,
            terminated: false,
            // passed or failed stated this session, and a fail held until it ends
            judged: false,
            pendingFailed: null,
            // stated in this registration: never again
            completed: false,
            passed: false,
            ...this.#read(this.key),
        };
        this.store = new RecordStore(launch, { fetch, timers, retry: this.retryPauses, log });
        this.outbox = new Outbox({
            send: (item, options) => this.store.send(item, options, this.saved.token),
            store: { load: () => this.#read(`${this.key} outbox`) ?? [], save: (items) => this.#write(`${this.key} outbox`, items) },
            retry: this.retryPauses,
            timers,
        });
        this.inbox = [];
        this.ready = false;
        this.stopped = false;
        this.leaving = null;
    }

    /**
     * Gets the token (once: kept in storage across reloads), the launch data, the learner's
     * preferences and the progress of earlier sessions, then states "initialized".
     * Resolves `{resumeStep, language, launchMode, returnURL, ended}`, or null when the LMS
     * cannot be reached (the lesson then plays unrecorded).
     */
    async start() {
        const s = this.saved;
        s.initializedAt ??= this.now();
        this.lastStamp = s.initializedAt - 1;
        try {
            if (!s.token) {
                s.token = await this.store.fetchToken();
                this.#persist();
            }
            this.outbox.start();
            this.launchData = await this.store.state("LMS.LaunchData", s.token, { tries: Infinity });
            if (!this.launchData?.contextTemplate) throw new Error("the LMS.LaunchData document has no contextTemplate");
        } catch (error) {
            this.log.warn(`cmi5: cannot record this session: ${error.message}`);
            this.stopped = true;
            return null;
        }
        // A 403 or no document at all are answers too: the platform keeps no preferences.
        const preferences = await this.store.profile("cmi5LearnerPreferences", s.token).catch(() => null);
        const earlier = await this.store.state(PROGRESS_STATE, s.token, { tries: 3 }).catch((error) => {
            this.log.warn(`cmi5: the progress of earlier sessions is unknown: ${error.message}`);
            return null;
        });
        if (earlier && typeof earlier === "object") {
            this.progress.readText(earlier.progress);
            s.completed ||= earlier.completed === true;
            s.passed ||= earlier.passed === true;
        }
        const mode = this.launchData.launchMode;
        this.normal = mode === undefined || mode === "Normal";
        const mastery = this.launchData.masteryScore;
        const numeric = typeof mastery === "number" || (typeof mastery === "string" && mastery.trim() !== "");
        this.masteryScore = numeric && Number(mastery) >= 0 && Number(mastery) <= 1 ? Number(mastery) : null;
        if (s.completed) this.progress.tourDone = true;
        const ended = s.terminated;
        if (!s.initialized && !ended) {
            s.initialized = true;
            this.#queue(this.#defined("initialized", s.initializedAt));
        }
        this.ready = true;
        if (ended) this.stopped = true;
        for (const event of this.inbox.splice(0)) this.#handle(event);
        if (this.leaving !== null) this.#terminate(this.leaving.at, this.leaving.keepalive);
        return {
            resumeStep: this.progress.step,
            language: languageList(preferences?.languagePreference),
            launchMode: mode ?? "Normal",
            returnURL: typeof this.launchData.returnURL === "string" ? this.launchData.returnURL : null,
            ended,
        };
    }

    onLoaded() {
        this.#event("loaded", null);
    }

    /** A tour step shown (`{step, steps, statement}`). */
    onStep(detail) {
        this.#event("step", detail);
    }

    /** A quiz answer (`{..., statement}`). */
    onAnswer(detail) {
        this.#event("answer", detail);
    }

    /** The quiz finished (`{right, questions, score, passed, statement}`). */
    onFinished(detail) {
        this.#event("finished", detail);
    }

    /** The page went to the background: nothing to do, the outbox is already kept. */
    checkpoint() {}

    /**
     * Ends the session once: a held "failed", then "terminated". `keepalive` when the page is
     * going away, so the last requests outlive it.
     */
    finish({ keepalive = true } = {}) {
        if (this.leaving !== null) return;
        this.leaving = { at: this.now(), keepalive };
        if (this.ready) this.#terminate(this.leaving.at, keepalive);
    }

    /** Resolves once the store has taken everything stated. */
    whenSent() {
        return this.outbox.idle();
    }

    #event(kind, detail) {
        if (this.stopped || this.leaving !== null) return;
        const event = { kind, detail, at: this.now() };
        if (this.ready) this.#handle(event);
        else this.inbox.push(event);
    }

    #handle({ kind, detail, at }) {
        if (this.stopped) return;
        if (kind === "loaded") {
            if (this.progress.open()) this.#complete(at);
        } else if (kind === "step") {
            const last = this.progress.show(detail?.step, detail?.steps);
            this.#allowed(detail?.statement, at);
            if (last) this.#complete(at);
            this.#saveProgress();
        } else if (kind === "answer") {
            this.#allowed(detail?.statement, at);
        } else if (kind === "finished") {
            this.progress.quizDone = true;
            this.#judge(detail, at);
            this.#complete(at);
            this.#saveProgress();
        }
        this.#persist();
    }

    /**
     * "passed" or "failed" (Normal mode only), against the LMS's mastery score where it gives
     * one. Once per session, a pass once per registration and never a fail after it; a fail is
     * held until the session ends, so that a second try in the same session may still pass.
     */
    #judge(detail, at) {
        const s = this.saved;
        const questions = Number(detail?.questions) || 0;
        if (!this.normal || questions === 0 || s.passed || s.judged) return;
        const right = Number(detail.right) || 0;
        const scaled = right / questions;
        const passed = this.masteryScore === null ? Boolean(detail.passed) : scaled >= this.masteryScore;
        const result = { score: { scaled, raw: right, min: 0, max: questions }, success: passed, duration: this.#since(at) };
        const extensions = this.masteryScore === null ? undefined : { [MASTERY_SCORE]: this.masteryScore };
        const statement = this.#defined(passed ? "passed" : "failed", at, { result, moveOn: true, extensions });
        if (passed) {
            s.pendingFailed = null;
            s.judged = s.passed = true;
            this.#queue(statement);
        } else {
            s.pendingFailed = statement;
        }
    }

    /** "completed", once per registration, in Normal mode, when the lesson is done. */
    #complete(at) {
        const s = this.saved;
        if (!this.normal || s.completed || !this.progress.complete) return;
        s.completed = true;
        this.#queue(this.#defined("completed", at, { result: { completion: true, duration: this.#since(at) }, moveOn: true }));
    }

    #terminate(at, keepalive) {
        const s = this.saved;
        if (!s.terminated && !this.stopped) {
            if (s.pendingFailed && !s.judged) {
                this.#queue(s.pendingFailed);
                s.judged = true;
            }
            s.pendingFailed = null;
            this.#queue(this.#defined("terminated", at, { result: { duration: this.#since(at) } }));
            s.terminated = true;
            this.stopped = true;
            this.#persist();
        }
        if (keepalive) this.outbox.flush();
    }

    /** A viewer's statement as a "cmi5 allowed" one: the student, the session's context, an id. */
    #allowed(statement, at) {
        if (!statement || typeof statement !== "object") return;
        const own = clone(statement);
        const { verb, object, result } = own;
        this.#queue({
            id: this.uuid(),
            timestamp: this.#stamp(at),
            actor: this.launch.actor,
            verb,
            object,
            ...(result ? { result } : {}),
            context: this.#context({ base: own.context, defined: false }),
        });
    }

    /** A "cmi5 defined" statement about this unit. */
    #defined(verb, at, { result, moveOn = false, extensions } = {}) {
        return {
            id: this.uuid(),
            timestamp: this.#stamp(at),
            actor: this.launch.actor,
            verb: VERBS[verb],
            object: { objectType: "Activity", id: this.launch.activityId },
            ...(result ? { result } : {}),
            context: this.#context({ defined: true, moveOn, extensions }),
        };
    }

    /**
     * The LMS's context template with the registration, and what this statement adds: the
     * template's values are never overwritten, its lists only added to.
     */
    #context({ base = {}, defined, moveOn = false, extensions }) {
        const template = clone(this.launchData.contextTemplate) ?? {};
        const context = { ...base, ...template, registration: this.launch.registration };
        const ext = { ...base.extensions, ...extensions, ...template.extensions };
        if (Object.keys(ext).length) context.extensions = ext;
        else delete context.extensions;
        const activities = {};
        for (const kind of ["parent", "grouping", "category", "other"]) {
            const merged = new Map();
            const add = (activity) => activity?.id && !merged.has(activity.id) && merged.set(activity.id, activity);
            for (const activity of list(template.contextActivities?.[kind])) add(activity);
            for (const activity of list(base.contextActivities?.[kind])) add(activity);
            if (kind === "category" && defined) add({ objectType: "Activity", id: CATEGORY_CMI5 });
            if (kind === "category" && moveOn) add({ objectType: "Activity", id: CATEGORY_MOVEON });
            // An allowed statement names this unit as its parent, so reports find it with it.
            if (kind === "parent" && !defined && merged.size === 0) add({ objectType: "Activity", id: this.launch.activityId });
            if (merged.size) activities[kind] = [...merged.values()];
        }
        if (Object.keys(activities).length) context.contextActivities = activities;
        return context;
    }

    /** A statement to send, in order after the ones before it. */
    #queue(statement) {
        this.outbox.push({ kind: "statement", statement });
    }

    /** This unit's progress document, for resuming and the once-per-registration rules. */
    #saveProgress() {
        if (!this.normal) return;
        const s = this.saved;
        const document = { progress: this.progress.toText(), completed: s.completed, passed: s.passed };
        this.outbox.push({ kind: "state", key: `state ${PROGRESS_STATE}`, stateId: PROGRESS_STATE, document });
    }

    /** Timestamps that never go back and never tie, so the store's order is the unit's. */
    #stamp(at) {
        this.lastStamp = Math.max(at, this.lastStamp + 1);
        return new Date(this.lastStamp).toISOString();
    }

    #since(at) {
        return isoDuration(at - this.saved.initializedAt);
    }

    #persist() {
        this.#write(this.key, this.saved);
    }

    #read(key) {
        try {
            const text = this.storage?.getItem(key);
            return text ? JSON.parse(text) : null;
        } catch {
            return null;
        }
    }

    #write(key, value) {
        try {
            this.storage?.setItem(key, JSON.stringify(value));
        } catch {
            // Storage may be full or refused in a third-party frame: the session goes on in memory.
        }
    }
}
