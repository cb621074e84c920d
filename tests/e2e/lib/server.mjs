// A static file server for dist/ on a free port of 127.0.0.1: what Trunk built, nothing else.
// Also by hand, to serve a folder on a port (the example platform beside `bash web/serve.sh`):
//   node tests/e2e/lib/server.mjs web/examples/platform 8081
import { createServer } from "node:http";
import { readFile, stat } from "node:fs/promises";
import { extname, join, normalize, sep } from "node:path";
import { fileURLToPath } from "node:url";

const CONTENT_TYPES = {
    ".html": "text/html; charset=utf-8",
    ".js": "text/javascript; charset=utf-8",
    ".mjs": "text/javascript; charset=utf-8",
    ".wasm": "application/wasm",
    ".css": "text/css; charset=utf-8",
    ".json": "application/json",
    ".png": "image/png",
    ".svg": "image/svg+xml",
    ".ico": "image/x-icon",
    ".txt": "text/plain; charset=utf-8",
};

/**
 * Serves `root` until `close()`. Every request is recorded in `served` (method and path), so a
 * test can see what the page asked for from this side too. `types` names other content types
 * by extension (`{".wasm": "application/octet-stream"}`, as many servers send it).
 */
export async function serveDirectory(root, port = 0, { types = {} } = {}) {
    const contentTypes = { ...CONTENT_TYPES, ...types };
    const rootDir = normalize(root + sep);
    const served = [];
    const files = new Map();
    const server = createServer(async (request, response) => {
        const path = decodeURIComponent(new URL(request.url, "http://localhost").pathname);
        served.push(`${request.method} ${path}`);
        const file = normalize(join(rootDir, path.endsWith("/") ? path + "index.html" : path));
        if (!file.startsWith(rootDir) || (request.method !== "GET" && request.method !== "HEAD")) {
            response.writeHead(404).end();
            return;
        }
        try {
            const kept = files.get(path);
            if (kept === undefined && !(await stat(file)).isFile()) {
                throw new Error("not a file");
            }
            const body = kept ?? (await readFile(file));
            response.writeHead(200, {
                "Content-Type": contentTypes[extname(file)] ?? "application/octet-stream",
                "Content-Length": body.length,
                "Cache-Control": "no-store",
            });
            response.end(request.method === "HEAD" ? undefined : body);
        } catch {
            response.writeHead(404, { "Content-Type": "text/plain" }).end("not found\n");
        }
    });
    await new Promise((resolve, reject) => {
        server.once("error", reject);
        server.listen(port, "127.0.0.1", resolve);
    });
    port = server.address().port;
    return {
        url: `http://127.0.0.1:${port}/`,
        origin: `http://127.0.0.1:${port}`,
        served,
        /** Bodies served by path (`/cases/x.glb`) as if they were files of the folder. */
        files,
        close: () =>
            new Promise((resolve) => {
                server.closeAllConnections();
                server.close(() => resolve());
            }),
    };
}

if (process.argv[1] === fileURLToPath(import.meta.url)) {
    const [root, port] = process.argv.slice(2);
    if (!root) {
        console.error("usage: node tests/e2e/lib/server.mjs FOLDER [PORT]");
        process.exit(2);
    }
    const served = await serveDirectory(root, Number(port ?? 0));
    console.log(`serving ${root} at ${served.url} (Ctrl+C stops)`);
}
