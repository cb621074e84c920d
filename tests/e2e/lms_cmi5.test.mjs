// End-to-end test of a cmi5 package against a real record store: Ralph (PyPI ralph-malph,
// started by tests/lms/ralph.sh) keeps the statements. Ralph serves the statements API only, so
// the test LMS in front of it answers what cmi5 asks of the LMS itself (the launch, the token
// URL, the State API with LMS.LaunchData) and passes every statement request on to Ralph as it
// came. The student takes the tour and the quiz by clicks; the store is stopped in the middle of
// the quiz and started again; the statements are read back from Ralph.
//
//   E2E_MODE=cpu node --test tests/e2e/lms_cmi5.test.mjs   (tests/e2e/run.sh runs it in the cpu run)
import { after } from "node:test";
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { randomUUID } from "node:crypto";
import { createServer, request as httpRequest } from "node:http";
import { mkdtempSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";

import { launchBrowser, modeFromEnv } from "./lib/browser.mjs";
import { ROOT, outputDir } from "./lib/paths.mjs";
import { serveDirectory } from "./lib/server.mjs";
import { phantomPackage, phantomShown, press, stateWhen, takeQuiz, viewerOf } from "./lib/packaged.mjs";
import { CPU_RUN, testIn } from "./lib/suite.mjs";

const MODE = modeFromEnv();
const OUT = outputDir(MODE);
const TIMEOUT = 300_000;
const tmp = mkdtempSync(join(tmpdir(), "meshsmooth-cmi5-"));
const RALPH = join(ROOT, "tests/lms/ralph.sh");
const store = { dir: join(tmp, "ralph"), port: 18_000 + Math.floor(Math.random() * 2000) };
const ralph = (...args) => execFileSync("bash", [RALPH, ...args], { encoding: "utf8", stdio: ["ignore", "pipe", "inherit"] });
after(() => {
    // Stopped here whatever the test's outcome; it starts only in the run that takes the test.
    if (store.started) {
        try {
            ralph("stop", store.dir);
        } catch {
            // Stopped already.
        }
    }
    rmSync(tmp, { recursive: true, force: true });
});

const TOKEN = Buffer.from("student:secret").toString("base64");
const AU = "urn:meshsmooth:case:Abdominal-phantom";

/**
 * The LMS's side of cmi5 on `lms.url`: the package's files, the token URL (counted), the State
 * API in memory (LMS.LaunchData set before the launch) and no agent profiles; statements pass
 * on to Ralph, a 503 while it is down.
 */
async function testLms(packageDir, launchData) {
    // The wasm under a type of its own no browser knows, as some LMSs name unknown files.
    const files = await serveDirectory(packageDir, 0, { types: { ".wasm": "application/x-unknown" } });
    const states = new Map();
    const lms = { tokens: 0, statementRequests: 0, refusedWhileDown: 0 };
    const key = (q) => ["stateId", "activityId", "agent", "registration"].map((k) => q.get(k)).join("\n");
    const server = createServer((req, res) => {
        const url = new URL(req.url, "http://lms");
        const body = [];
        req.on("data", (c) => body.push(c));
        req.on("end", () => {
            const bytes = Buffer.concat(body);
            if (url.pathname === "/fetch" && req.method === "POST") {
                lms.tokens += 1;
                res.writeHead(200, { "Content-Type": "application/json" }).end(JSON.stringify({ "auth-token": TOKEN }));
            } else if (url.pathname === "/xapi/activities/state") {
                if (req.headers.authorization !== `Basic ${TOKEN}`) return res.writeHead(401).end();
                if (req.method === "GET") {
                    const doc = states.get(key(url.searchParams));
                    return doc ? res.writeHead(200, { "Content-Type": "application/json" }).end(doc) : res.writeHead(404).end();
                }
                states.set(key(url.searchParams), bytes.toString("utf8"));
                res.writeHead(204).end();
            } else if (url.pathname === "/xapi/statements") {
                lms.statementRequests += 1;
                const upstream = httpRequest({ host: "127.0.0.1", port: store.port, path: `/xAPI/statements${url.search}`, method: req.method, headers: { ...req.headers, host: `127.0.0.1:${store.port}` } }, (answer) => {
                    res.writeHead(answer.statusCode, answer.headers);
                    answer.pipe(res);
                });
                upstream.on("error", () => {
                    lms.refusedWhileDown += 1;
                    res.writeHead(503).end();
                });
                upstream.end(bytes);
            } else if (url.pathname.startsWith("/xapi/")) {
                res.writeHead(404).end();
            } else {
                // The package, from the same origin as the endpoint (an LMS serves both).
                const proxied = httpRequest(`${files.url}${url.pathname.slice(1)}${url.search}`, (answer) => {
                    res.writeHead(answer.statusCode, answer.headers);
                    answer.pipe(res);
                });
                proxied.end();
            }
        });
    });
    await new Promise((resolve) => server.listen(0, "127.0.0.1", resolve));
    lms.url = `http://127.0.0.1:${server.address().port}/`;
    lms.setLaunchData = (q, doc) => states.set(key(q), JSON.stringify(doc));
    lms.close = async () => {
        server.closeAllConnections();
        await new Promise((resolve) => server.close(resolve));
        await files.close();
    };
    return lms;
}

/** The statements Ralph holds for `registration`, oldest first by timestamp. */
async function statementsOf(registration) {
    const response = await fetch(`http://127.0.0.1:${store.port}/xAPI/statements?registration=${registration}&limit=500`, {
        headers: { Authorization: `Basic ${TOKEN}`, "X-Experience-API-Version": "1.0.3" },
    });
    assert.equal(response.status, 200);
    const { statements } = await response.json();
    return statements.sort((a, b) => Date.parse(a.timestamp) - Date.parse(b.timestamp));
}

testIn(CPU_RUN, "P6 cmi5: the statements reach a real record store in cmi5's order with the launch's actor and registration; none lost while it was down", { timeout: TIMEOUT }, async () => {
    await phantomPackage("cmi5", join(OUT, "phantom-cmi5.zip"), join(tmp, "package"));
    store.started = true;
    ralph("start", store.dir, String(store.port));
    const lms = await testLms(join(tmp, "package"));
    const browser = await launchBrowser(MODE);
    try {
        const registration = randomUUID();
        const actor = { objectType: "Agent", name: "Student", mbox: "mailto:student@example.org" };
        const launch = new URLSearchParams({ endpoint: `${lms.url}xapi/`, fetch: `${lms.url}fetch`, actor: JSON.stringify(actor), registration, activityId: AU });
        const sessionId = randomUUID();
        lms.setLaunchData(new URLSearchParams({ stateId: "LMS.LaunchData", activityId: AU, agent: JSON.stringify(actor), registration }), {
            contextTemplate: { extensions: { "https://w3id.org/xapi/cmi5/context/extensions/sessionid": sessionId } },
            launchMode: "Normal",
            masteryScore: 0.5,
            moveOn: "CompletedOrPassed",
        });
        const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
        const errors = [];
        page.on("pageerror", (e) => errors.push(String(e)));
        await page.goto(`${lms.url}index.html?${launch}`);
        const viewer = await viewerOf(page, "/viewer/index.html");
        await phantomShown(viewer);
        for (const [i, key] of ["start", "next", "next"].entries()) {
            await press(page, viewer, key);
            await stateWhen(viewer, (s) => s.tour?.step === i, `step ${i + 1}`);
        }
        await press(page, viewer, "leave");
        await stateWhen(viewer, (s) => s.tour.step === null && !s.layout.lesson?.leave, "the tour left, drawn");
        // The store goes away after the third answer and comes back after the sixth.
        const answers = await takeQuiz(page, viewer, 3, false, async (q) => {
            if (q === 2) ralph("stop", store.dir);
            if (q === 5) {
                assert.ok(lms.refusedWhileDown > 0, "statements were tried while the store was down");
                ralph("start", store.dir, String(store.port));
            }
        });
        await page.screenshot({ path: join(OUT, "lms-cmi5-score.png") });
        await page.close({ runBeforeUnload: true });

        // Everything queued reaches the store: 1 initialized, 3 experienced, 8 answered, passed,
        // completed, terminated.
        let statements = [];
        for (let tries = 0; tries < 120 && !statements.some((s) => s.verb.id.endsWith("/terminated")); tries++) {
            await new Promise((resolve) => setTimeout(resolve, 500));
            statements = await statementsOf(registration);
        }
        const verbs = statements.map((s) => s.verb.id.split("/").at(-1));
        console.log(`cmi5: the store holds, by timestamp: ${verbs.join(" ")} (${lms.refusedWhileDown} statement requests refused while it was down)`);
        assert.equal(verbs[0], "initialized", verbs.join(" "));
        assert.equal(verbs.at(-1), "terminated", verbs.join(" "));
        assert.equal(verbs.filter((v) => v === "experienced").length, 3, verbs.join(" "));
        assert.equal(verbs.filter((v) => v === "answered").length, answers.length, `every answer, none lost: ${verbs.join(" ")}`);
        const right = answers.filter((a) => a.right).length;
        assert.equal(right, 4);
        assert.ok(verbs.indexOf("passed") > verbs.lastIndexOf("answered"), "passed after the last answer");
        assert.ok(verbs.indexOf("completed") > verbs.lastIndexOf("experienced"), "completed after the tour's last step");
        assert.ok(!verbs.includes("failed"));
        const ids = new Set(statements.map((s) => s.id));
        assert.equal(ids.size, statements.length, "no statement twice");
        for (const s of statements) {
            assert.equal(s.context.registration, registration);
            assert.equal(s.actor.mbox, actor.mbox);
            assert.equal(s.context.extensions["https://w3id.org/xapi/cmi5/context/extensions/sessionid"], sessionId);
        }
        const passed = statements.find((s) => s.verb.id.endsWith("/passed"));
        assert.equal(passed.object.id, AU);
        assert.equal(passed.result.score.scaled, right / answers.length);
        assert.equal(passed.context.extensions["https://w3id.org/xapi/cmi5/context/extensions/masteryscore"], 0.5);
        assert.equal(lms.tokens, 1, "the token URL asked once");
        assert.deepEqual(errors, [], "uncaught errors");
    } finally {
        await browser.close();
        await lms.close();
    }
});
