// The launch page's runtime: reads launch.json, finds the learning platform (a SCORM API in a
// window above this one, or cmi5's launch parameters), opens the viewer in the iframe and hands
// the platform what the student does there. Without a platform the viewer plays as it would
// anywhere, and one line says that nothing is recorded. A platform that fails is logged to the
// console and never stops the lesson.

import { Cmi5Session, cmi5Launch } from "./cmi5.js";
import { findApi } from "./find_api.js";
import { NOTICES, showNotice } from "./notice.js";
import { ScormSession } from "./scorm.js";
import { connectViewer, viewerUrl } from "./viewer_link.js";

/** How long the viewer waits for the platform's language before opening without it. */
const LANGUAGE_WAIT_MS = 3000;

async function readLaunch() {
    try {
        const response = await fetch("launch.json", { cache: "no-cache" });
        if (!response.ok) throw new Error(`HTTP ${response.status}`);
        return await response.json();
    } catch (error) {
        console.warn(`launch page: cannot read launch.json (${error.message}); opening the viewer alone`);
        return {};
    }
}

/** sessionStorage, or null where the browser refuses it (a third-party frame, say). */
function sessionStore() {
    try {
        window.sessionStorage.getItem("");
        return window.sessionStorage;
    } catch {
        return null;
    }
}

/** The session with the platform launch.json names, or null when none launched this page. */
function openSession(launch) {
    if (launch.format === "cmi5") {
        const params = cmi5Launch(window.location.search);
        return params && new Cmi5Session(params, launch, { fetch: window.fetch.bind(window), storage: sessionStore() });
    }
    const version = { scorm12: "1.2", scorm2004: "2004" }[launch.format];
    const api = version && findApi(window, version);
    return api ? new ScormSession(api, version, launch) : null;
}

async function main() {
    const launch = await readLaunch();
    if (typeof launch.title === "string" && launch.title) document.title = launch.title;
    const session = openSession(launch);
    if (!session) showNotice(document, NOTICES.outside);

    const started = (async () => (session ? session.start() : null))().catch((error) => {
        console.warn("launch page: the learning platform's session did not start:", error);
        return null;
    });
    const early = await Promise.race([started, new Promise((resolve) => setTimeout(resolve, LANGUAGE_WAIT_MS))]);

    const frame = document.getElementById("viewer");
    const page = window.location.href;
    frame.src = viewerUrl(page, { viewer: launch.viewer, caseFile: launch.case, language: early?.language });
    const viewer = connectViewer(frame, window.location.origin);
    const loaded = new Promise((resolve) => viewer.on("loaded", resolve));

    if (session) {
        viewer.on("loaded", () => session.onLoaded());
        viewer.on("step", (detail) => session.onStep(detail));
        viewer.on("quizAnswered", (detail) => session.onAnswer(detail));
        viewer.on("quizFinished", (detail) => session.onFinished(detail));
        listenForLeaving(session);
    }
    viewer.on("failed", (detail) => console.warn(`launch page: the viewer could not open the case: ${detail?.error}`));

    const result = await started;
    if (session && !result) showNotice(document, NOTICES.unreachable);
    else if (result?.ended) showNotice(document, NOTICES.ended);
    else if (/^https?:/i.test(result?.returnURL ?? "")) offerReturn(session, result.returnURL);
    if (Number.isInteger(result?.resumeStep) && !result.ended) {
        await loaded;
        viewer.call("showStep", result.resumeStep).catch((error) => console.warn(`launch page: could not resume at step ${result.resumeStep + 1}: ${error.message}`));
    }
}

/**
 * Ends the session once when the student leaves, whichever of these comes first (not on
 * beforeunload: a prompt may still keep the page).
 */
function listenForLeaving(session) {
    const leave = () => session.finish();
    for (const event of ["pagehide", "unload"]) window.addEventListener(event, leave);
    document.addEventListener("visibilitychange", () => {
        if (document.visibilityState === "hidden") session.checkpoint();
    });
    window.addEventListener("online", () => session.outbox?.kick());
    // Back from the browser's page cache after leaving: the session cannot start again.
    window.addEventListener("pageshow", (event) => {
        if (event.persisted) showNotice(document, NOTICES.ended);
    });
}

/** cmi5's returnURL: a link that ends the session and goes there once everything is sent. */
function offerReturn(session, returnURL) {
    showNotice(document, NOTICES.done, async () => {
        showNotice(document, NOTICES.saving);
        session.finish({ keepalive: false });
        await session.whenSent();
        window.location.assign(returnURL);
    });
}

main();
