// The setup every e2e test file shares: serve dist/, launch Chromium in the run's mode, and
// open a fresh page per test that must make no foreign request and throw no uncaught error.
import { after, before } from "node:test";
import assert from "node:assert/strict";
import { existsSync } from "node:fs";
import { join } from "node:path";

import { AppPage } from "./app.mjs";
import { launchBrowser, modeFromEnv } from "./browser.mjs";
import { DIST, outputDir } from "./paths.mjs";
import { serveDirectory } from "./server.mjs";

/**
 * Registers the file's before/after hooks (`beforeAll`/`afterAll` run with them); returns
 * `{MODE, OUT, withApp}`, where `withApp(body, options)` runs `body(app)` on a freshly opened
 * page and closes it. `options` go to `AppPage.open` (`query`, `startTimeoutMs`); the page's
 * API is awaited first unless the suite was made with `waitForApi: false` (tests of the start
 * itself).
 */
export function appSuite({ beforeAll = () => {}, afterAll = () => {}, waitForApi = true } = {}) {
    const MODE = modeFromEnv();
    const OUT = outputDir(MODE);
    let server;
    let browser;
    before(async () => {
        if (!existsSync(join(DIST, "index.html"))) {
            throw new Error(`${DIST}/index.html is missing: build the page first (trunk build --release)`);
        }
        beforeAll();
        server = await serveDirectory(DIST);
        browser = await launchBrowser(MODE);
        console.log(`e2e: mode ${MODE}, Chromium ${browser.version()}, serving ${DIST} at ${server.url}`);
    });
    after(async () => {
        await browser?.close();
        await server?.close();
        afterAll();
    });
    async function withApp(body, options = {}) {
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
