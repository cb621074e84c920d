// What the tests feed the runtimes: the viewer's events as its messages carry them (see
// src/app/api/messages.rs, src/app/tour.rs, src/app/quiz.rs, src/case/xapi.rs), a clock, and a
// console that keeps what it is told.

export const CASE = "urn:meshsmooth:case:Abdominal-phantom";
export const START = Date.UTC(2026, 4, 1, 9, 0, 0);

/** A clock the test moves on. */
export function clock(at = START) {
    const now = () => at;
    now.tick = (ms) => (at += ms);
    return now;
}

/** A console that keeps warnings. */
export function quietLog() {
    const warnings = [];
    return { warnings, warn: (...parts) => warnings.push(parts.join(" ")), log() {}, info() {} };
}

/** The viewer's `step` event for step `step` (from 0) of `steps`. */
export function stepEvent(step, steps) {
    return {
        step,
        steps,
        title: `Step ${step + 1}`,
        caption: "",
        left: null,
        statement: {
            verb: { id: "http://adlnet.gov/expapi/verbs/experienced", display: { "en-US": "experienced" } },
            object: {
                objectType: "Activity",
                id: `${CASE}#step-${step + 1}`,
                definition: { type: "http://adlnet.gov/expapi/activities/interaction", name: { "en-US": `Step ${step + 1}` } },
            },
            context: { extensions: { "urn:meshsmooth:step": step + 1, "urn:meshsmooth:steps": steps } },
        },
    };
}

/** The viewer's `quizAnswered` event: `structure` asked in `mode`, `given` answered after `ms`. */
export function answerEvent(structure, mode, given, ms, choices = []) {
    const slug = structure.replace(/[^A-Za-z0-9]/g, "-");
    const definition = {
        type: "http://adlnet.gov/expapi/activities/cmi.interaction",
        name: { "en-US": mode === "find-it" ? `Find the ${structure}` : "Name the structure shown" },
        interactionType: mode === "find-it" ? "other" : "choice",
        correctResponsesPattern: [structure],
    };
    if (choices.length) definition.choices = choices.map((c) => ({ id: c, description: { "en-US": c } }));
    return {
        structure,
        mode,
        given,
        right: given === structure,
        ms,
        statement: {
            verb: { id: "http://adlnet.gov/expapi/verbs/answered", display: { "en-US": "answered" } },
            object: { objectType: "Activity", id: `${CASE}#quiz-${mode}-${slug}`, definition },
            result: { success: given === structure, response: given, duration: `PT${(ms / 1000).toFixed(2)}S` },
            context: { extensions: { "urn:meshsmooth:quiz-mode": mode } },
        },
    };
}

/** The viewer's `quizFinished` event: `right` of `questions`, judged against `passMark`. */
export function finishedEvent(right, questions, passMark) {
    const score = right / questions;
    const passed = score >= passMark;
    return {
        right,
        questions,
        score,
        passed,
        statement: {
            verb: { id: `http://adlnet.gov/expapi/verbs/${passed ? "passed" : "failed"}`, display: { "en-US": passed ? "passed" : "failed" } },
            object: { objectType: "Activity", id: `${CASE}#quiz` },
            result: { score: { scaled: score, raw: right, min: 0, max: questions }, success: passed, completion: true },
        },
    };
}

/** The four answers of the tests: one right and one wrong in each mode. */
export const ANSWERS = [
    answerEvent("left kidney", "find-it", "left kidney", 2345),
    answerEvent("liver", "find-it", "spleen", 4100),
    answerEvent("right kidney", "name-it", "right kidney", 1500, ["right kidney", "liver", "aorta", "spleen"]),
    answerEvent("aorta", "name-it", "liver", 61500, ["tumor", "liver", "aorta", "spleen"]),
];
