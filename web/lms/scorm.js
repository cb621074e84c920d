// The lesson in SCORM's run-time data model, 1.2 or 2004 (4th edition): the tour step as the
// bookmark, each quiz answer as an interaction, the quiz's score and pass, completion, and the
// session's time and exit. It only talks to the API object it is given, so Node tests it
// against a real SCORM runtime; finding the API and hearing the viewer are lms.js's work.

import { clip, cmiTimeOfDay, cmiTimespan, identifier, isoDuration, languageList, scormTimestamp } from "./formats.js";
import { Progress } from "./progress.js";

/** A decimal as SCORM's real (10, 7) takes it: at most seven places, no exponent. */
const decimal = (x) => String(Number(x.toFixed(7)));

/** The quiz's score as a percentage, exact for whole counts (SCORM 1.2 raw scores are 0 to 100). */
const percent = (right, questions) => Number(((right * 100) / questions).toFixed(2));

/** An interaction's question, for 2004's description, from the viewer's statement if it has one. */
function question(detail, mode) {
    const named = detail.statement?.object?.definition?.name?.["en-US"];
    if (typeof named === "string" && named.trim()) return named.trim();
    return mode === "name-it" ? "Name the structure shown" : `Find the ${detail.structure}`;
}

const SCORM12 = {
    calls: {
        initialize: "LMSInitialize",
        terminate: "LMSFinish",
        get: "LMSGetValue",
        set: "LMSSetValue",
        commit: "LMSCommit",
        lastError: "LMSGetLastError",
        errorString: "LMSGetErrorString",
    },
    entry: "cmi.core.entry",
    mode: "cmi.core.lesson_mode",
    location: "cmi.core.lesson_location",
    locationMax: 255,
    suspendData: "cmi.suspend_data",
    suspendMax: 4096,
    language: "cmi.student_preference.language",
    statusElement: "cmi.core.lesson_status",
    exit: "cmi.core.exit",
    sessionTime: "cmi.core.session_time",
    timespan: cmiTimespan,
    /** A finished lesson leaves with "": the next launch is not a resume. */
    exitDone: "",
    /** Get errors that only mean "no value here". */
    quietGetErrors: [],

    /** What the LMS has recorded: passed, completed, and the pass mark it imposes (0 to 1). */
    read(get) {
        const status = get("cmi.core.lesson_status");
        const mastery = get("cmi.student_data.mastery_score");
        return {
            status,
            passed: status === "passed",
            quizDone: status === "passed" || status === "failed",
            tourDone: status === "completed",
            passMark: /^\d+(\.\d+)?$/.test(mastery) ? Number(mastery) / 100 : null,
        };
    },
    /** The first launch is an attempt begun. */
    begin(s) {
        if (s.status === "not attempted" || s.status === "") s.write("cmi.core.lesson_status", "incomplete");
    },
    /**
     * Done: 1.2 has one status, so a case with a quiz reports passed or failed and never
     * "completed"; without a quiz the tour's end completes it.
     */
    complete(s) {
        if (!s.progress.hasQuiz && !["passed", "failed", "completed"].includes(s.status)) {
            s.write("cmi.core.lesson_status", "completed");
        }
    },
    progress() {},
    score(s, { right, questions, passed }) {
        s.write("cmi.core.score.raw", String(percent(right, questions)));
        s.write("cmi.core.score.min", "0");
        s.write("cmi.core.score.max", "100");
        s.write("cmi.core.lesson_status", passed ? "passed" : "failed");
    },
    /** find-it as "performance" (1.2 has no "other"), name-it as "fill-in": both take the name. */
    interaction(n, detail, date) {
        const mode = identifier(detail.mode, 20);
        const at = `cmi.interactions.${n}`;
        return [
            [`${at}.id`, `${mode}-${identifier(detail.structure, 255 - mode.length - 1)}`],
            [`${at}.type`, mode === "name-it" ? "fill-in" : "performance"],
            [`${at}.time`, cmiTimeOfDay(date)],
            [`${at}.correct_responses.0.pattern`, clip(detail.structure, 255)],
            [`${at}.student_response`, clip(detail.given, 255)],
            [`${at}.result`, detail.right ? "correct" : "wrong"],
            [`${at}.latency`, cmiTimespan(detail.ms)],
        ];
    },
};

const SCORM2004 = {
    calls: {
        initialize: "Initialize",
        terminate: "Terminate",
        get: "GetValue",
        set: "SetValue",
        commit: "Commit",
        lastError: "GetLastError",
        errorString: "GetErrorString",
    },
    entry: "cmi.entry",
    mode: "cmi.mode",
    location: "cmi.location",
    locationMax: 1000,
    suspendData: "cmi.suspend_data",
    suspendMax: 64000,
    language: "cmi.learner_preference.language",
    statusElement: "cmi.completion_status",
    exit: "cmi.exit",
    sessionTime: "cmi.session_time",
    timespan: isoDuration,
    exitDone: "normal",
    /** 403: "data model element value not initialized", as an unset location reads. */
    quietGetErrors: ["403"],

    read(get) {
        const completion = get("cmi.completion_status");
        const success = get("cmi.success_status");
        const passing = get("cmi.scaled_passing_score");
        return {
            status: completion,
            passed: success === "passed",
            quizDone: success === "passed" || success === "failed",
            tourDone: completion === "completed",
            passMark: /^-?\d+(\.\d+)?$/.test(passing) ? Number(passing) : null,
        };
    },
    begin(s) {
        if (["unknown", "not attempted", ""].includes(s.status)) s.write("cmi.completion_status", "incomplete");
    },
    complete(s) {
        // With a completion threshold the LMS judges by the progress measure: keep it at 1.
        s.write("cmi.progress_measure", "1");
        if (s.status !== "completed") s.write("cmi.completion_status", "completed");
    },
    progress(s) {
        s.write("cmi.progress_measure", decimal(s.progress.measure));
    },
    score(s, { right, questions, scaled, passed }) {
        s.write("cmi.score.scaled", decimal(scaled));
        s.write("cmi.score.raw", String(percent(right, questions)));
        s.write("cmi.score.min", "0");
        s.write("cmi.score.max", "100");
        s.write("cmi.success_status", passed ? "passed" : "failed");
    },
    /**
     * find-it as "other" (the name clicked), name-it as "choice", whose responses are
     * short_identifier_type: the names as identifiers. The id is a URN, as long_identifier_type
     * asks for a URI.
     */
    interaction(n, detail, date) {
        const mode = identifier(detail.mode, 20);
        const choice = mode === "name-it";
        const at = `cmi.interactions.${n}`;
        return [
            [`${at}.id`, `urn:meshsmooth:quiz:${mode}-${identifier(detail.structure, 200)}`],
            [`${at}.type`, choice ? "choice" : "other"],
            [`${at}.description`, clip(question(detail, mode), 250)],
            [`${at}.timestamp`, scormTimestamp(date)],
            [`${at}.correct_responses.0.pattern`, choice ? identifier(detail.structure) : clip(detail.structure, 4000)],
            [`${at}.learner_response`, choice ? identifier(detail.given) : clip(detail.given, 4000)],
            [`${at}.result`, detail.right ? "correct" : "incorrect"],
            [`${at}.latency`, isoDuration(detail.ms)],
        ];
    },
};

export const VERSIONS = { "1.2": SCORM12, 2004: SCORM2004 };

/** The bookmark: the step shown, counted from 1 as the student reads it. */
const locationOf = (step) => String(step + 1);
function stepAt(location, steps) {
    if (!/^\d+$/.test(location)) return null;
    const step = Number(location) - 1;
    return step >= 0 && (steps === 0 || step < steps) ? step : null;
}

export class ScormSession {
    /**
     * `api`: the LMS's API object (`API` or `API_1484_11`); `version`: "1.2" or "2004";
     * `lesson`: launch.json's `{steps, quiz}`. `now` and `log` are the clock and the console.
     */
    constructor(api, version, lesson, { now = () => Date.now(), log = console } = {}) {
        this.api = api;
        this.version = version;
        this.dialect = VERSIONS[version];
        if (!this.dialect) throw new Error(`no SCORM version ${version}: 1.2 or 2004`);
        this.progress = new Progress(lesson);
        this.now = now;
        this.log = log;
        this.live = false;
        this.ended = false;
    }

    /**
     * Initializes the session and reads what a relaunch resumes: `{resumeStep, language}`,
     * or null when the LMS refused (the lesson then plays unrecorded).
     */
    start() {
        const d = this.dialect;
        if (!this.#ok(this.#call(d.calls.initialize, ""))) {
            this.#warn(`${d.calls.initialize}("")`);
            return null;
        }
        this.live = true;
        this.startedAt = this.now();
        const get = (element) => this.#get(element);
        const mode = get(d.mode);
        // Browse and review record nothing of the student's results, only the bookmark.
        this.recording = mode === "" || mode === "normal";
        const entry = get(d.entry);
        const location = get(d.location);
        this.progress.readText(get(d.suspendData));
        const recorded = d.read(get);
        Object.assign(this, { status: recorded.status, passed: recorded.passed, passMark: recorded.passMark });
        if (recorded.tourDone) this.progress.tourDone = true;
        if (recorded.quizDone) this.progress.quizDone = true;
        this.nextInteraction = Number.parseInt(get("cmi.interactions._count"), 10) || 0;
        const resumeStep = entry === "resume" ? stepAt(location, this.progress.steps) ?? this.progress.step : null;
        const language = languageList(get(d.language));
        if (this.recording) d.begin(this);
        this.#save();
        return { resumeStep, language };
    }

    /** The case is open: a case with neither tour nor quiz is done once seen. */
    onLoaded() {
        if (!this.live) return;
        if (this.progress.open() && this.recording) {
            this.dialect.complete(this);
            this.#save();
        }
    }

    /** A tour step shown (`{step, steps}`, step from 0). */
    onStep(detail) {
        if (!this.live) return;
        const last = this.progress.show(detail?.step, detail?.steps);
        if (this.progress.step === null) return;
        const d = this.dialect;
        this.write(d.location, clip(locationOf(this.progress.step), d.locationMax));
        this.write(d.suspendData, clip(this.progress.toText(), d.suspendMax));
        if (this.recording) {
            d.progress(this);
            if (last) d.complete(this);
        }
        this.#save();
    }

    /** A quiz answer (`{structure, mode, given, right, ms, statement}`): a new interaction. */
    onAnswer(detail) {
        if (!this.live || !this.recording || !detail) return;
        const n = this.nextInteraction++;
        for (const [element, value] of this.dialect.interaction(n, detail, new Date(this.now()))) {
            this.write(element, value);
        }
        this.#save();
    }

    /** The quiz finished (`{right, questions, score, passed}`): score, pass or fail, completion. */
    onFinished(detail) {
        if (!this.live || !detail) return;
        this.progress.quizDone = true;
        if (this.recording) {
            const questions = Number(detail.questions) || 0;
            const right = Number(detail.right) || 0;
            const scaled = questions > 0 ? right / questions : Number(detail.score) || 0;
            // The LMS's own pass mark, where it sets one, is what it will judge by.
            const passed = this.passMark === null ? Boolean(detail.passed) : scaled >= this.passMark;
            // A pass stands: a later try that fails does not take it back.
            if (questions > 0 && (passed || !this.passed)) {
                this.dialect.score(this, { right, questions, scaled, passed });
                this.passed = this.passed || passed;
            }
            this.dialect.complete(this);
        }
        this.#save();
    }

    /** Saves the session time so far (the page may be going to the background). */
    checkpoint() {
        if (this.live) this.#save();
    }

    /** Ends the session once: exit, session time, commit, then LMSFinish or Terminate. */
    finish() {
        if (!this.live) return;
        this.#save();
        this.live = false;
        this.ended = true;
        const terminate = this.dialect.calls.terminate;
        if (!this.#ok(this.#call(terminate, ""))) this.#warn(`${terminate}("")`);
    }

    /** Sets one element; a refusal is logged and the lesson goes on. */
    write(element, value) {
        if (element === this.dialect.statusElement) this.status = value;
        const set = this.dialect.calls.set;
        const ok = this.#ok(this.#call(set, element, value));
        if (!ok) this.#warn(`${set}("${element}", ${JSON.stringify(value)})`);
        return ok;
    }

    /** Exit as the lesson stands, the session time, and a commit. */
    #save() {
        const d = this.dialect;
        this.write(d.exit, this.progress.finished ? d.exitDone : "suspend");
        this.write(d.sessionTime, d.timespan(this.now() - this.startedAt));
        if (!this.#ok(this.#call(d.calls.commit, ""))) this.#warn(`${d.calls.commit}("")`);
    }

    #get(element) {
        const value = this.#call(this.dialect.calls.get, element);
        const code = String(this.#call(this.dialect.calls.lastError) ?? "0");
        if (code === "0") return String(value ?? "");
        if (!this.dialect.quietGetErrors.includes(code)) this.#warn(`${this.dialect.calls.get}("${element}")`, code);
        return "";
    }

    #call(name, ...args) {
        try {
            return this.api[name](...args);
        } catch (error) {
            this.log.warn(`SCORM ${name} threw: ${error?.message ?? error}`);
            return null;
        }
    }

    #ok(result) {
        return result === true || result === "true";
    }

    #warn(what, code = String(this.#call(this.dialect.calls.lastError) ?? "")) {
        const text = this.#call(this.dialect.calls.errorString, code);
        this.log.warn(`SCORM ${what} failed: error ${code}${text ? ` (${text})` : ""}`);
    }
}
