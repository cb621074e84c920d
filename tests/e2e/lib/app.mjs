// One page of the app under test, and the embedding API (`window.meshsmooth`) seen from Node.
//
// Every test opens its own page (a fresh browser context), so no test depends on what another
// left behind: the app starts with its bundled sample each time.
import { writeFileSync } from "node:fs";
import { join } from "node:path";
import { assertNotBlank, decodePng } from "./png.mjs";

/** How long a started page may take to announce `window.meshsmooth` (meshsmooth-ready). */
const API_WAIT_MS = Number(process.env.E2E_API_WAIT_MS ?? 10_000);

export const VIEWPORT = { width: 1280, height: 800 };

/**
 * The bytes a request received (body and headers). Chromium sometimes reports the case that
 * index.html reads as a stream as aborted once it has read it all, without sizes: then its
 * Content-Length counts.
 */
async function responseBytes(request) {
    const sizes = await request.sizes().catch(() => null);
    const length = Number((await request.response().catch(() => null))?.headers()["content-length"] ?? 0);
    return Math.max(sizes ? sizes.responseBodySize + sizes.responseHeadersSize : 0, length);
}

export class AppPage {
    /**
     * Opens the served page and waits until the app has started (eframe removed the loading
     * text) or crashed (then throws with the page's crash message). Requests and console
     * messages are recorded from before the first navigation.
     */
    static async open(browser, server, outDir, { startTimeoutMs = 60_000, query = "", device = {}, routes = {}, files = {} } = {}) {
        const context = await browser.newContext({ viewport: VIEWPORT, deviceScaleFactor: 1, ...device });
        // Files the server serves as its own (what a timing must see: routes pass through Node).
        for (const [path, body] of Object.entries(files)) {
            server.files.set(new URL(path, server.url).pathname, body);
        }
        // Files the page fetches from its own origin (`?case=cases/x.glb`) without being in dist/.
        for (const [path, body] of Object.entries(routes)) {
            await context.route(new URL(path, server.url).href, (route) =>
                route.fulfill({ status: 200, body, contentType: "application/octet-stream", headers: { "Cache-Control": "no-store" } }));
        }
        const page = await context.newPage();
        const app = new AppPage(context, page, server, outDir);
        const started = Date.now();
        await page.goto(server.url + query, { waitUntil: "load", timeout: startTimeoutMs });
        await app.waitForStart(startTimeoutMs);
        app.startSeconds = (Date.now() - started) / 1000;
        return app;
    }

    constructor(context, page, server, outDir) {
        this.context = context;
        this.page = page;
        this.server = server;
        this.outDir = outDir;
        /** Every URL the page requested, in order. */
        this.requests = [];
        /** Console messages as `{type, text}`, in order. */
        this.console = [];
        this.pageErrors = [];
        this.consoleWaiters = new Set();
        page.on("request", (request) => this.requests.push(request.url()));
        /** The sizes of the responses the page received, as they finish (promises). */
        this.received = [];
        page.on("requestfinished", (request) => this.received.push(responseBytes(request)));
        page.on("requestfailed", (request) => this.received.push(responseBytes(request)));
        page.on("pageerror", (error) => this.pageErrors.push(error));
        page.on("console", (message) => {
            const line = { type: message.type(), text: message.text() };
            this.console.push(line);
            for (const waiter of this.consoleWaiters) {
                waiter(line);
            }
        });
    }

    /** Bytes the page received so far (bodies and headers; files its workers fetched too). */
    async bytesReceived() {
        const sizes = await Promise.all(this.received);
        return sizes.reduce((sum, s) => sum + s, 0);
    }

    async close() {
        await this.context.close();
    }

    async waitForStart(timeoutMs) {
        const handle = await this.page.waitForFunction(
            () => {
                const crash = document.getElementById("crash_message");
                if (crash && !crash.hidden) {
                    return { crashed: crash.innerText };
                }
                return document.getElementById("loading_text") === null ? { started: true } : false;
            },
            null,
            { timeout: timeoutMs },
        );
        const result = await handle.jsonValue();
        if (result.crashed) {
            throw new Error(`the app crashed while starting: ${result.crashed}`);
        }
    }

    /** The first console message (already logged or still to come) whose text matches `pattern`. */
    waitForConsole(pattern, timeoutMs = 30_000) {
        const found = this.console.find((line) => pattern.test(line.text));
        if (found) {
            return Promise.resolve(found);
        }
        return new Promise((resolve, reject) => {
            const timer = setTimeout(() => {
                this.consoleWaiters.delete(waiter);
                const recent = this.console.slice(-10).map((l) => `  [${l.type}] ${l.text}`);
                reject(new Error(`no console message matching ${pattern} within ${timeoutMs} ms; last messages:\n${recent.join("\n")}`));
            }, timeoutMs);
            const waiter = (line) => {
                if (pattern.test(line.text)) {
                    clearTimeout(timer);
                    this.consoleWaiters.delete(waiter);
                    resolve(line);
                }
            };
            this.consoleWaiters.add(waiter);
        });
    }

    /** Saves a screenshot as `<outDir>/<name>.png`, checks it is not blank, returns the image. */
    async screenshot(name) {
        const bytes = await this.page.screenshot();
        const path = join(this.outDir, `${name}.png`);
        writeFileSync(path, bytes);
        const image = decodePng(bytes);
        assertNotBlank(image, path);
        image.path = path;
        return image;
    }

    /**
     * Takes screenshots until `predicate(image)` holds (the next frames may still be on their
     * way), then saves the last one as `<name>.png`.
     */
    async screenshotWhen(name, predicate, what, timeoutMs = 30_000) {
        const deadline = Date.now() + timeoutMs;
        for (;;) {
            const image = await this.screenshot(name);
            if (predicate(image)) {
                return image;
            }
            if (Date.now() > deadline) {
                throw new Error(`${what}: not seen on screen within ${timeoutMs} ms (last screenshot: ${image.path})`);
            }
            // Wait for the next frames the browser paints, not for a fixed time.
            await this.page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
        }
    }

    /** URLs the page requested outside its own origin (data: URLs and own-origin blob: URLs are local). */
    foreignRequests() {
        return this.requests.filter((url) => {
            const parsed = new URL(url);
            if (parsed.protocol === "data:") {
                return false;
            }
            if (parsed.protocol === "blob:") {
                return new URL(parsed.pathname).origin !== this.server.origin;
            }
            return parsed.origin !== this.server.origin;
        });
    }

    // --- the embedding API ---

    /**
     * Waits for `window.meshsmooth` (it may already be there, or come with the
     * `meshsmooth-ready` event); throws "window.meshsmooth missing" when it does not come.
     */
    async api() {
        if (this.apiReady) {
            return;
        }
        const seen = await this.page.evaluate(
            (ms) =>
                new Promise((resolve) => {
                    if (window.meshsmooth) {
                        resolve("present");
                        return;
                    }
                    const timer = setTimeout(() => resolve(window.meshsmooth ? "present" : "none"), ms);
                    window.addEventListener(
                        "meshsmooth-ready",
                        () => {
                            clearTimeout(timer);
                            resolve(window.meshsmooth ? "present" : "event-only");
                        },
                        { once: true },
                    );
                }),
            API_WAIT_MS,
        );
        if (seen === "none") {
            throw new Error(
                `window.meshsmooth missing: the app started, but no meshsmooth-ready event came within ${API_WAIT_MS} ms ` +
                    "and window.meshsmooth is undefined (this build of dist/ has no embedding API)",
            );
        }
        if (seen === "event-only") {
            throw new Error("window.meshsmooth missing: the meshsmooth-ready event fired but window.meshsmooth is undefined");
        }
        this.apiReady = true;
    }

    /** Calls `window.meshsmooth[method](...args)` and awaits its result. */
    async call(method, ...args) {
        await this.api();
        return this.page.evaluate(
            async ([method, args]) => {
                if (typeof window.meshsmooth[method] !== "function") {
                    throw new Error(`window.meshsmooth.${method} is not a function`);
                }
                return await window.meshsmooth[method](...args);
            },
            [method, args],
        );
    }

    /**
     * Calls a method and reports how it ended, without throwing: `{ok, value}` or
     * `{ok: false, isError, message}` (whether it threw/rejected with an Error, and its message).
     */
    async attempt(method, ...args) {
        await this.api();
        return this.page.evaluate(
            async ([method, args]) => {
                try {
                    return { ok: true, value: await window.meshsmooth[method](...args) };
                } catch (e) {
                    return { ok: false, isError: e instanceof Error, message: e instanceof Error ? e.message : String(e) };
                }
            },
            [method, args],
        );
    }

    state() {
        return this.call("state");
    }

    /** Polls `state()` until `test(state)` holds (20 s at most); returns that state. */
    async stateWhen(test, what) {
        const deadline = Date.now() + 20_000;
        let state = await this.state();
        while (!test(state)) {
            if (Date.now() > deadline) {
                throw new Error(`timed out waiting for ${what}`);
            }
            await new Promise((resolve) => setTimeout(resolve, 100));
            state = await this.state();
        }
        return state;
    }

    backend() {
        return this.call("backend");
    }

    setFilter(name) {
        return this.call("setFilter", name);
    }

    setParams(params) {
        return this.call("setParams", params);
    }

    metrics() {
        return this.call("metrics");
    }

    /**
     * `loadMesh(bytes, name)` with the bytes of a Node Buffer; resolves with the info object.
     * `method` may be another call taking bytes and a name (`loadCase`, `addFile`, `addImage`),
     * `extra` its further arguments.
     */
    async loadMesh(bytes, name, method = "loadMesh", ...extra) {
        const result = await this.attemptLoad(bytes, name, method, ...extra);
        if (!result.ok) {
            throw new Error(`${method}(${name}) rejected: ${result.message}`);
        }
        return result.value;
    }

    /**
     * `loadMesh` (or `method`: `loadCase`, `addFile`, which take the same arguments) without
     * throwing: `{ok, value}` or `{ok: false, isError, message}`.
     */
    async attemptLoad(bytes, name, method = "loadMesh", ...extra) {
        await this.api();
        return this.page.evaluate(
            async ([base64, name, method, extra]) => {
                const text = atob(base64);
                const bytes = new Uint8Array(text.length);
                for (let i = 0; i < text.length; i++) {
                    bytes[i] = text.charCodeAt(i);
                }
                try {
                    return { ok: true, value: await window.meshsmooth[method](bytes, name, ...extra) };
                } catch (e) {
                    return { ok: false, isError: e instanceof Error, message: e instanceof Error ? e.message : String(e) };
                }
            },
            [Buffer.from(bytes).toString("base64"), name, method, extra],
        );
    }

    /** `exportMesh(format)` as a Node Buffer; throws unless it resolves with a Uint8Array. */
    exportMesh(format) {
        return this.callBytes("exportMesh", format);
    }

    /** `method(...args)` as a Node Buffer; throws unless it resolves with a Uint8Array. */
    async callBytes(method, ...args) {
        await this.api();
        const result = await this.page.evaluate(async ([method, args]) => {
            const bytes = await window.meshsmooth[method](...args);
            if (!(bytes instanceof Uint8Array)) {
                return { error: `${method}(${args.join(", ")}) resolved with ${Object.prototype.toString.call(bytes)}, not a Uint8Array` };
            }
            let text = "";
            for (let i = 0; i < bytes.length; i += 0x8000) {
                text += String.fromCharCode.apply(null, bytes.subarray(i, i + 0x8000));
            }
            return { base64: btoa(text) };
        }, [method, args]);
        if (result.error) {
            throw new Error(result.error);
        }
        return Buffer.from(result.base64, "base64");
    }

    /**
     * Drops a file on the canvas the way a browser does: dragenter, dragover, then drop, each
     * carrying a DataTransfer built in the page with one File.
     */
    async dropFile(bytes, name) {
        await this.dropFiles([{ bytes, name }]);
    }

    /** Drops several files at once (`[{bytes, name}]`), in one DataTransfer, in that order. */
    async dropFiles(files) {
        const encoded = files.map(({ bytes, name }) => [Buffer.from(bytes).toString("base64"), name]);
        const dataTransfer = await this.page.evaluateHandle((files) => {
            const transfer = new DataTransfer();
            for (const [base64, name] of files) {
                const text = atob(base64);
                const data = new Uint8Array(text.length);
                for (let i = 0; i < text.length; i++) {
                    data[i] = text.charCodeAt(i);
                }
                transfer.items.add(new File([data], name, { type: "application/octet-stream" }));
            }
            return transfer;
        }, encoded);
        for (const type of ["dragenter", "dragover", "drop"]) {
            await this.page.dispatchEvent("#meshsmooth_canvas", type, { dataTransfer });
        }
        await dataTransfer.dispose();
    }

    /**
     * Drops a folder `name` of `files` (`[{bytes, name}]`, a name with slashes in subfolders)
     * on the canvas, as the browser's File and Directory Entries API shows a dropped folder:
     * listed in batches of two (each `batchMs` after it is asked for), the folder also among the
     * drop's files as Chromium gives it. Playwright cannot drop a real folder, so the entries are
     * made here; the files are real ones.
     */
    async dropFolder(name, files, { batchMs = 0 } = {}) {
        const encoded = files.map(({ bytes, name, fails }) => [Buffer.from(bytes).toString("base64"), name, Boolean(fails)]);
        await this.page.evaluate(([folder, files, batchMs]) => {
            const bytesOf = (base64) => Uint8Array.from(atob(base64), (c) => c.charCodeAt(0));
            // A file that `fails` is one the browser cannot read (gone since the drop, say).
            const gone = () => new DOMException("A requested file or directory could not be found", "NotFoundError");
            const fileEntry = (file, fails) => ({ isFile: true, isDirectory: false, name: file.name, file: (ok, fail) => setTimeout(() => (fails ? fail(gone()) : ok(file))) });
            const folderEntry = (name, entries) => ({
                isFile: false,
                isDirectory: true,
                name,
                entries,
                createReader() {
                    let at = 0;
                    return {
                        readEntries(ok) {
                            const batch = entries.slice(at, at + 2);
                            at += batch.length;
                            setTimeout(() => ok(batch), batchMs);
                        },
                    };
                },
            });
            // A name with slashes is a file in subfolders, made as the paths need them.
            const root = folderEntry(folder, []);
            const folders = new Map([["", root]]);
            const folderAt = (path) => {
                if (!folders.has(path)) {
                    const cut = path.lastIndexOf("/");
                    const made = folderEntry(path.slice(cut + 1), []);
                    folderAt(cut < 0 ? "" : path.slice(0, cut)).entries.push(made);
                    folders.set(path, made);
                }
                return folders.get(path);
            };
            for (const [base64, path, fails] of files) {
                const cut = path.lastIndexOf("/");
                const name = path.slice(cut + 1);
                folderAt(cut < 0 ? "" : path.slice(0, cut)).entries.push(fileEntry(new File([bytesOf(base64)], name), fails));
            }
            const asFile = new DataTransfer();
            asFile.items.add(new File([], folder));
            const transfer = { items: { length: 1, 0: { kind: "file", type: "", webkitGetAsEntry: () => root } }, files: asFile.files };
            const drop = new DragEvent("drop", { bubbles: true, cancelable: true });
            Object.defineProperty(drop, "dataTransfer", { value: transfer });
            document.getElementById("meshsmooth_canvas").dispatchEvent(drop);
        }, [name, encoded, batchMs]);
    }
}
