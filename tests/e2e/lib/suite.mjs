// The setup every e2e test file shares: which run takes which test, serving dist/, Chromium in
// the run's mode, and a fresh page per test that must make no foreign request and throw no
// uncaught error.
import { after, test } from "node:test";
import assert from "node:assert/strict";
import { existsSync } from "node:fs";
import { join } from "node:path";

import { AppPage } from "./app.mjs";
import { launchBrowser, modeFromEnv } from "./browser.mjs";
import { DIST, outputDir } from "./paths.mjs";
import { serveDirectory } from "./server.mjs";

/**
 * The runs each test takes part in. The webgpu run takes every test but those about the CPU
 * engine alone (CPU_RUN); the cpu run takes only the tests whose outcome its engine (the CPU
 * workers instead of the GPU) or its renderer (WebGL2 instead of WebGPU) can change.
 */
export const EVERY_RUN = ["webgpu", "cpu"];
export const WEBGPU_RUN = ["webgpu"];
export const CPU_RUN = ["cpu"];

/** `test(name, options, body)` where this run's mode is one of `modes`; nothing otherwise. */
export function testIn(modes, name, options, body) {
    if (modes.includes(modeFromEnv())) test(name, options, body);
}

/**
 * Returns `{MODE, OUT, withApp}`, where `withApp(body, options)` runs `body(app)` on a freshly
 * opened page and closes it. The server and browser start with the file's first page
 * (`beforeAll` just before them) and stop after its last test (then `afterAll`), so a file
 * with no test in this run starts nothing. `options` go to `AppPage.open` (`query`, `device`, `routes`, `files`,
 * `startTimeoutMs`); the page's API is awaited first unless the suite was made with
 * `waitForApi: false` (tests of the start itself).
 */
export function appSuite({ beforeAll = () => {}, afterAll = () => {}, waitForApi = true } = {}) {
    const MODE = modeFromEnv();
    const OUT = outputDir(MODE);
    let started = null;
    const start = async () => {
        if (!existsSync(join(DIST, "index.html"))) {
            throw new Error(`${DIST}/index.html is missing: build the page first (trunk build --release)`);
        }
        beforeAll();
        const server = await serveDirectory(DIST);
        const browser = await launchBrowser(MODE);
        console.log(`e2e: mode ${MODE}, Chromium ${browser.version()}, serving ${DIST} at ${server.url}`);
        return { server, browser };
    };
    after(async () => {
        if (!started) return;
        const { server, browser } = await started.catch(() => ({}));
        await browser?.close();
        await server?.close();
        afterAll();
    });
    async function withApp(body, options = {}) {
        started ??= start();
        const { server, browser } = await started;
        const app = await AppPage.open(browser, server, OUT, options);
        try {
            if (waitForApi) await app.api();
            const result = await body(app);
            assert.deepEqual(app.foreignRequests(), [], "the page requested something outside its own origin");
            assert.deepEqual(app.pageErrors.map(String), [], "uncaught errors in the page");
            return result;
        } finally {
            await app.close();
        }
    }
    return { MODE, OUT, withApp };
}
