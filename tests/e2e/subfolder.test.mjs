// End-to-end test of where the page is served from: a server's subfolder (a platform's, an LMS's
// package folder), with the wasm named application/octet-stream as many servers name it.
//
//   E2E_MODE=webgpu|cpu node --test tests/e2e/subfolder.test.mjs   (tests/e2e/run.sh runs both)
import { after } from "node:test";
import assert from "node:assert/strict";
import { mkdirSync, mkdtempSync, rmSync, symlinkSync } from "node:fs";
import { tmpdir } from "node:os";
import { join, resolve } from "node:path";

import { AppPage } from "./lib/app.mjs";
import { launchBrowser, modeFromEnv } from "./lib/browser.mjs";
import { DIST, outputDir } from "./lib/paths.mjs";
import { serveDirectory } from "./lib/server.mjs";
import { EVERY_RUN, testIn } from "./lib/suite.mjs";

const MODE = modeFromEnv();
const OUT = outputDir(MODE);
const tmp = mkdtempSync(join(tmpdir(), "meshsmooth-subfolder-"));
after(() => rmSync(tmp, { recursive: true, force: true }));

testIn(EVERY_RUN, "H1 served from a subfolder, its wasm as octet-stream, the app starts, opens its sample and asks nothing outside its folder", { timeout: 180_000 }, async () => {
    mkdirSync(join(tmp, "course"));
    symlinkSync(resolve(DIST), join(tmp, "course", "viewer"));
    const server = await serveDirectory(tmp, 0, { types: { ".wasm": "application/octet-stream" } });
    const browser = await launchBrowser(MODE);
    try {
        const app = await AppPage.open(browser, server, OUT, { query: "course/viewer/" });
        try {
            await app.api();
            const state = await app.stateWhen((s) => s.structures?.structures.length === 4, "the sample case");
            assert.equal(state.model, "abdomen_phantom.glb: liver");
            await app.screenshot("H1-subfolder");
            const folder = `${server.url}course/viewer/`;
            const outside = app.requests.filter((url) => !/^(data|blob):/.test(url) && !url.startsWith(folder));
            assert.deepEqual(outside, [], "requests outside the page's folder");
            assert.ok(server.served.some((line) => line.endsWith(".wasm")), "the wasm was fetched");
            assert.deepEqual(app.pageErrors.map(String), [], "uncaught errors in the page");
        } finally {
            await app.close();
        }
    } finally {
        await browser.close();
        await server.close();
    }
});
