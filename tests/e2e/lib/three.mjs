// three.js in a page of its own, for checking what other viewers make of our glTF files: a
// small server on 127.0.0.1 that serves one test page, three's module files (from
// web/node_modules/three, its build/ and examples/jsm/ only) and the files a test hands it, all
// from one origin, so the page loads nothing from anywhere else. An import map resolves `three`
// and `three/addons/` to those files, as three's own documentation sets a page up.
import { createServer } from "node:http";
import { existsSync, readFileSync } from "node:fs";
import { readFile, stat } from "node:fs/promises";
import { extname, join, normalize, sep } from "node:path";

import { ROOT } from "./paths.mjs";

export const THREE_DIR = join(ROOT, "web", "node_modules", "three");

/** The parts of the three package the page may load. */
const SERVED_PARTS = ["build", join("examples", "jsm")].map((part) => normalize(join(THREE_DIR, part) + sep));

/** The version of three in web/node_modules (web/package.json pins it). */
export function threeVersion() {
    if (!existsSync(join(THREE_DIR, "package.json"))) {
        throw new Error(`three is missing from web/node_modules (${THREE_DIR}): run bash .ci/install.sh`);
    }
    return JSON.parse(readFileSync(join(THREE_DIR, "package.json"), "utf8")).version;
}

const PAGE = `<!doctype html>
<html>
<head>
<meta charset="utf-8">
<title>three.js glTF check</title>
<style>html, body { margin: 0; background: #202428; } canvas { display: block; }</style>
<script type="importmap">
{ "imports": { "three": "/three/build/three.module.js", "three/addons/": "/three/examples/jsm/" } }
</script>
</head>
<body>
<canvas id="view"></canvas>
<script type="module" src="/check.mjs"></script>
</body>
</html>
`;

/**
 * The page's script: `window.gltfCheck` with `load(url)` (GLTFLoader.parse on the fetched
 * bytes; returns what three made of the file) and `render(width, height)` (draws the loaded
 * scene once on the page's canvas, seen from +Z with +Y up).
 */
const CHECK_SCRIPT = `
import * as THREE from "three";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";
import { MeshoptDecoder } from "three/addons/libs/meshopt_decoder.module.js";

let loaded = null;
let cameras = [];

/** The page's canvas as a renderer of width x height, and a scene holding the loaded file. */
function stage(width, height) {
    const canvas = document.getElementById("view");
    const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
    renderer.setPixelRatio(1);
    renderer.setSize(width, height);
    const scene = new THREE.Scene();
    scene.background = new THREE.Color(0x202428);
    scene.add(loaded);
    return { renderer, scene };
}

window.gltfCheck = {
    revision: THREE.REVISION,

    /** three's form of a node name (GLTFLoader gives objects sanitised, unique names). */
    sanitise: (names) => names.map((name) => THREE.PropertyBinding.sanitizeNodeName(name)),

    async load(url) {
        const response = await fetch(url);
        if (!response.ok) throw new Error(url + ": HTTP " + response.status);
        const bytes = await response.arrayBuffer();
        // Case glTFs are EXT_meshopt_compression'ed: three decodes them with its MeshoptDecoder.
        const gltf = await new GLTFLoader().setMeshoptDecoder(MeshoptDecoder).parseAsync(bytes, "");
        loaded = gltf.scene;
        cameras = gltf.cameras;
        loaded.updateMatrixWorld(true);
        const meshes = [];
        const marked = [];
        const v = new THREE.Vector3();
        // Nodes without a mesh that carry a name and extras (a case's labels): where they are.
        loaded.traverse((object) => {
            if (object.isMesh || object.isCamera || !object.userData.meshsmooth) return;
            marked.push({ name: object.userData.name, world: object.getWorldPosition(new THREE.Vector3()).toArray(), parent: object.parent?.userData.name ?? null });
        });
        const views = cameras.map((c) => ({
            name: c.userData.name ?? c.name,
            type: c.type,
            world: c.getWorldPosition(new THREE.Vector3()).toArray(),
            looking: c.getWorldDirection(new THREE.Vector3()).toArray(),
        }));
        loaded.traverse((object) => {
            if (!object.isMesh) return;
            // The glTF node's own name is kept in userData.name; the mesh is that node unless
            // the node held more than one object.
            let named = object;
            while (named && named.userData.name === undefined) named = named.parent;
            const position = object.geometry.getAttribute("position");
            const mean = new THREE.Vector3();
            for (let i = 0; i < position.count; i++) {
                object.getVertexPosition(i, v);
                mean.add(v.applyMatrix4(object.matrixWorld));
            }
            mean.divideScalar(position.count);
            const material = object.material;
            meshes.push({
                name: object.name,
                nodeName: named ? named.userData.name : null,
                material: material.name,
                materialType: material.type,
                color: material.color.toArray(),
                colorSpace: THREE.ColorManagement.workingColorSpace,
                colorSrgbHex: "#" + material.color.getHexString(),
                opacity: material.opacity,
                transparent: material.transparent,
                vertices: position.count,
                meanWorld: mean.toArray(),
            });
        });
        // precise: from the vertices themselves (morph targets would widen the quick box).
        const box = new THREE.Box3().setFromObject(loaded, true);
        return { revision: THREE.REVISION, meshes, marked, views, box: { min: box.min.toArray(), max: box.max.toArray() } };
    },

    /** Draws the loaded scene through the file's camera number index (a case's tour step). */
    renderFrom(index, width, height) {
        const { renderer, scene } = stage(width, height);
        scene.add(new THREE.HemisphereLight(0xffffff, 0x404040, 2.5));
        const camera = cameras[index];
        camera.aspect = width / height;
        camera.updateProjectionMatrix();
        renderer.render(scene, camera);
        return { name: camera.name };
    },

    render(width, height) {
        const { renderer, scene } = stage(width, height);
        const box = new THREE.Box3().setFromObject(loaded, true);
        const centre = box.getCenter(new THREE.Vector3());
        const size = box.getSize(new THREE.Vector3());
        const fov = 30;
        const camera = new THREE.PerspectiveCamera(fov, width / height, 1e-4, 100);
        const half = 0.55 * Math.max(size.y, size.x / camera.aspect);
        const distance = half / Math.tan(THREE.MathUtils.degToRad(fov / 2)) + size.z / 2;
        camera.position.set(centre.x, centre.y, centre.z + distance);
        camera.up.set(0, 1, 0);
        camera.lookAt(centre);
        camera.near = distance / 100;
        camera.far = distance * 10;
        camera.updateProjectionMatrix();
        scene.add(new THREE.HemisphereLight(0xffffff, 0x404040, 1.5));
        const light = new THREE.DirectionalLight(0xffffff, 2);
        light.position.copy(camera.position).add(new THREE.Vector3(0, size.y, 0));
        light.target.position.copy(centre);
        scene.add(light, light.target);
        renderer.render(scene, camera);
        const gl = renderer.getContext();
        const debug = gl.getExtension("WEBGL_debug_renderer_info");
        return {
            webgl: gl instanceof WebGL2RenderingContext ? 2 : 1,
            renderer: debug ? gl.getParameter(debug.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER),
            camera: camera.position.toArray(),
            distance,
        };
    },
};
`;

const CONTENT_TYPES = {
    ".js": "text/javascript; charset=utf-8",
    ".mjs": "text/javascript; charset=utf-8",
    ".glb": "model/gltf-binary",
    ".gltf": "model/gltf+json",
};

/**
 * Starts the server; `files` maps a served name (`/files/<name>`) to the Buffer a test put
 * there. Every request is recorded in `served`. Close it with `close()`.
 */
export async function serveThreePage() {
    const files = new Map();
    const served = [];
    const server = createServer(async (request, response) => {
        const path = decodeURIComponent(new URL(request.url, "http://localhost").pathname);
        served.push(`${request.method} ${path}`);
        const send = (body, type) => {
            response.writeHead(200, { "Content-Type": type, "Content-Length": body.length, "Cache-Control": "no-store" });
            response.end(request.method === "HEAD" ? undefined : body);
        };
        if (request.method !== "GET" && request.method !== "HEAD") {
            response.writeHead(405).end();
        } else if (path === "/") {
            send(Buffer.from(PAGE), "text/html; charset=utf-8");
        } else if (path === "/check.mjs") {
            send(Buffer.from(CHECK_SCRIPT), CONTENT_TYPES[".mjs"]);
        } else if (path === "/favicon.ico") {
            response.writeHead(204).end();
        } else if (path.startsWith("/files/") && files.has(path.slice("/files/".length))) {
            send(files.get(path.slice("/files/".length)), CONTENT_TYPES[extname(path)] ?? "application/octet-stream");
        } else if (path.startsWith("/three/")) {
            const file = normalize(join(THREE_DIR, path.slice("/three/".length)));
            try {
                if (!SERVED_PARTS.some((part) => file.startsWith(part)) || !(await stat(file)).isFile()) {
                    throw new Error("not served");
                }
                send(await readFile(file), CONTENT_TYPES[extname(file)] ?? "application/octet-stream");
            } catch {
                response.writeHead(404, { "Content-Type": "text/plain" }).end("not found\n");
            }
        } else {
            response.writeHead(404, { "Content-Type": "text/plain" }).end("not found\n");
        }
    });
    await new Promise((resolve, reject) => {
        server.once("error", reject);
        server.listen(0, "127.0.0.1", resolve);
    });
    const { port } = server.address();
    return {
        url: `http://127.0.0.1:${port}/`,
        origin: `http://127.0.0.1:${port}`,
        files,
        served,
        close: () =>
            new Promise((resolve) => {
                server.closeAllConnections();
                server.close(() => resolve());
            }),
    };
}

/**
 * Opens the test page in a fresh context of `browser` and waits for `window.gltfCheck`.
 * Returns `{page, context, requests, console, pageErrors, foreignRequests(), close()}`.
 */
export async function openThreePage(browser, server, viewport) {
    const context = await browser.newContext({ viewport, deviceScaleFactor: 1 });
    const page = await context.newPage();
    const opened = {
        page,
        context,
        requests: [],
        console: [],
        pageErrors: [],
        foreignRequests() {
            return this.requests.filter((url) => {
                const parsed = new URL(url);
                return parsed.protocol !== "data:" && parsed.origin !== server.origin;
            });
        },
        close: () => context.close(),
    };
    page.on("request", (request) => opened.requests.push(request.url()));
    page.on("console", (message) => opened.console.push({ type: message.type(), text: message.text() }));
    page.on("pageerror", (error) => opened.pageErrors.push(error));
    try {
        await page.goto(server.url, { waitUntil: "load", timeout: 60_000 });
        await page.waitForFunction(() => window.gltfCheck !== undefined, null, { timeout: 30_000 });
    } catch (e) {
        const messages = opened.console.map((l) => `  [${l.type}] ${l.text}`).join("\n");
        await context.close();
        throw new Error(`the three.js test page did not start: ${e.message}\n${opened.pageErrors.join("\n")}\n${messages}`);
    }
    return opened;
}
