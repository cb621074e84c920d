// End-to-end check of the case GLBs `meshsmooth case build` and the authoring page write, as other
// tools see them: the Khronos glTF-Validator passes each with no error or warning, and three.js's
// GLTFLoader in headless Chromium finds every structure by name, in its colour and opacity, in
// metres with +Y superior. Only the webgpu run takes these checks (three renders in WebGL2: see
// BROWSER_MODE); the page's case is made by the page in that run.
//
//   node --test tests/e2e/case_gltf.test.mjs   (tests/e2e/run.sh runs it)
//
// The GLBs and a rendering of each (case-<name>.png) go to target/e2e/<mode>/.
import { after } from "node:test";
import assert from "node:assert/strict";
import { readFileSync, writeFileSync } from "node:fs";
import { basename, join } from "node:path";

import { launchBrowser, modeFromEnv } from "./lib/browser.mjs";
import * as cli from "./lib/cli.mjs";
import { gltfValidator } from "./lib/deps.mjs";
import { meshNodes, readGlb } from "./lib/glb.mjs";
import { ROOT, meshPath, outputDir } from "./lib/paths.mjs";
import { assertNotBlank, colourHistogram, decodePng } from "./lib/png.mjs";
import { WEBGPU_RUN, appSuite, testIn } from "./lib/suite.mjs";
import { openThreePage, serveThreePage, threeVersion } from "./lib/three.mjs";

const MODE = modeFromEnv();
const OUT = outputDir(MODE);
const TIMEOUT = 240_000;
const VIEWPORT = { width: 960, height: 720 };

/**
 * The one command under test: writes the case GLB of `input` (a label map) to `output`, its
 * labels named by the colour table `colors` when given.
 */
function writeCaseGlb(input, output, { colors, lesson } = {}) {
    // The local search keeps the 48 structures of the atlas to seconds; the file is the same
    // kind (smoothed surfaces, originals as morph targets, records) either way.
    const table = colors ? ["--colors", colors] : [];
    const taught = lesson ? ["--lesson", lesson] : [];
    return cli.cli("case", "build", input, ...table, ...taught, "--search", "local", "--local-error", "-o", output);
}

const CASES = [
    {
        key: "phantom",
        what: "the phantom's",
        input: meshPath("labelmaps/case_phantom_shared.nii.gz"),
        colors: meshPath("labelmaps/case_phantom_shared_labels.txt"),
        lesson: join(ROOT, "tests/data/phantom_lesson.json"),
        structures: 4,
    },
    {
        key: "jhu",
        what: "the JHU atlas's",
        input: meshPath("labelmaps/JHU-WhiteMatter-labels-1mm.nii.gz"),
        colors: meshPath("labelmaps/JHU-WhiteMatter-labels-1mm.nii.txt"),
        structures: 48,
    },
    {
        key: "page",
        what: "the authoring page's (renamed, recoloured, grouped, translucent)",
        input: meshPath("labelmaps/case_phantom_shared.seg.nrrd"),
        fromPage: true,
        structures: 4,
    },
];

const { withApp } = appSuite({ beforeAll: () => cli.requireCli() });

/**
 * The page's case GLB of the phantom as an author arranges it: every structure suggested and
 * smoothed, the liver translucent, the portal vein renamed, recoloured and grouped. Returns
 * the bytes and the structures as the page lists them (the names, colours and opacity the GLB
 * must carry).
 */
function writePageCaseGlb(input, output) {
    return withApp(async (app) => {
        await app.loadMesh(readFileSync(input), basename(input));
        await app.call("suggestAll", { tau: 0.5, search: "local" });
        await app.call("setStructure", { index: 0, opacity: 0.4 });
        await app.call("setStructure", { index: 1, name: "portal vein", color: [0.2, 0.3, 0.9], group: "Vessels" });
        await app.call("setCase", { title: "Abdominal phantom", description: "Exported by the page" });
        await app.metrics();
        const bytes = Buffer.from(await app.call("exportCase", "glb"));
        writeFileSync(output, bytes);
        const listed = (await app.call("structures")).structures;
        return listed.map((s) => ({ label: s.label, name: s.name, color: s.color, opacity: s.opacity }));
    });
}

// --- what the GLB must hold ---

/**
 * A colour table's entries by label: `{name, color?}` (sRGB 0..1). Reads the two kinds the
 * test data has: Slicer/FreeSurfer lines `label name R G B A` and FSL lines `label name`.
 */
function readColourTable(path) {
    const entries = new Map();
    for (const line of readFileSync(path, "utf8").split(/\r?\n/)) {
        const fields = line.trim().split(/\s+/);
        if (fields[0] === "" || fields[0].startsWith("#") || !/^\d+$/.test(fields[0]) || fields.length < 2) {
            continue;
        }
        const rgb = fields.slice(2, 5).map(Number);
        const entry = { name: fields[1] };
        if (rgb.length === 3 && rgb.every(Number.isFinite)) {
            entry.color = rgb.map((c) => c / 255);
        }
        entries.set(Number(fields[0]), entry);
    }
    return entries;
}

/**
 * The structures the GLB must hold, in order: `meshsmooth info --json` of the label map (labels,
 * default names and colours), renamed and recoloured by the colour table as `--colors` does.
 * Opaque: info gives no opacity.
 */
async function expectedStructures(c) {
    if (c.fromPage) return (await caseGlb(c)).listed;
    const info = await cli.info(c.input);
    const table = c.colors ? readColourTable(c.colors) : new Map();
    return info.structures.map((s) => {
        const entry = table.get(s.label) ?? {};
        return { label: s.label, name: entry.name ?? s.name, color: entry.color ?? s.color, opacity: 1 };
    });
}

/**
 * Every node with a mesh, in scene order (depth first, as three traverses): its name, its
 * material, and its positions (RAS mm, decoded and dequantized where compressed): vertex
 * count, min/max, mean.
 */
function glbStructures(bytes) {
    const { json } = readGlb(bytes);
    const materials = [];
    const visit = (index) => {
        const node = json.nodes[index];
        if (node.mesh !== undefined) {
            const primitives = json.meshes[node.mesh].primitives;
            assert.equal(primitives.length, 1, "one primitive per structure");
            materials.push(json.materials[primitives[0].material] ?? {});
        }
        for (const child of node.children ?? []) visit(child);
    };
    for (const root of json.scenes[json.scene ?? 0].nodes) visit(root);
    return meshNodes(bytes).map((n, i) => {
        const min = [Infinity, Infinity, Infinity];
        const max = [-Infinity, -Infinity, -Infinity];
        const sum = [0, 0, 0];
        n.positions.forEach((v, j) => {
            const k = j % 3;
            min[k] = Math.min(min[k], v);
            max[k] = Math.max(max[k], v);
            sum[k] += v;
        });
        const count = n.positions.length / 3;
        return {
            name: n.name,
            baseColorFactor: materials[i].pbrMetallicRoughness?.baseColorFactor ?? [1, 1, 1, 1],
            alphaMode: materials[i].alphaMode ?? "OPAQUE",
            vertices: count,
            min,
            max,
            mean: sum.map((s) => s / count),
            quantization: n.quantization,
        };
    });
}

/** An sRGB component (0..1) in linear light, as three's Color holds it. */
function srgbToLinear(c) {
    return c <= 0.04045 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4;
}

const written = new Map();

/** The case's GLB (written once per run and mode): `{file, bytes}`. */
function caseGlb(c) {
    if (!written.has(c.key)) {
        const file = join(OUT, `case-${c.key}.glb`);
        const writing = c.fromPage ? writePageCaseGlb(c.input, file) : writeCaseGlb(c.input, file, { colors: c.colors, lesson: c.lesson });
        written.set(
            c.key,
            writing.then((listed) => ({ file, bytes: readFileSync(file), listed })),
        );
    }
    return written.get(c.key);
}

// --- the checks ---

/**
 * The browser is the same in both runs: three's WebGLRenderer needs WebGL, which headless
 * Chromium does not give with the webgpu mode's flags (ANGLE on SwiftShader Vulkan: "Error
 * creating WebGL context"); the cpu mode's flags give WebGL2 on SwiftShader. Nothing here
 * depends on the app's engine.
 */
const BROWSER_MODE = "cpu";

/** The page server and browser, started with the first check that renders. */
let started = null;
function threePage() {
    started ??= (async () => {
        const three = threeVersion();
        const server = await serveThreePage();
        const browser = await launchBrowser(BROWSER_MODE);
        console.log(`e2e: mode ${MODE} (browser flags of ${BROWSER_MODE}), Chromium ${browser.version()}, three ${three} served at ${server.url}`);
        return { server, browser };
    })();
    return started;
}

after(async () => {
    if (!started) return;
    const { server, browser } = await started.catch(() => ({}));
    await browser?.close();
    await server?.close();
});

const SEVERITIES = ["error", "warning", "info", "hint"];

/** RAS millimetres in glTF metres: right -> -X, superior -> +Y, anterior -> +Z. */
const metres = ([r, a, s]) => [-r / 1000, s / 1000, a / 1000];
const distance = (p, q) => Math.hypot(...p.map((x, k) => x - q[k]));

/**
 * The lesson as three sees it: each tour step a camera, named by its title, at the step's eye
 * and looking at its target; each label a node named by its text under its structure, within
 * 0.01 mm of its point. The first step's view is drawn through three's camera.
 */
async function checkLesson(t, c, seen, opened) {
    const lesson = JSON.parse(readFileSync(c.lesson, "utf8"));
    assert.deepEqual(seen.views.map((v) => [v.name, v.type]), lesson.steps.map((s) => [s.title, "PerspectiveCamera"]), "a camera per step, in order");
    lesson.steps.forEach((step, i) => {
        const { target, yaw, pitch, distance: d } = step.camera;
        const towardEye = [-Math.sin(yaw) * Math.cos(pitch), Math.cos(yaw) * Math.cos(pitch), Math.sin(pitch)];
        const eye = metres(target.map((x, k) => x + d * towardEye[k]));
        const view = seen.views[i];
        assert.ok(distance(view.world, eye) < 1e-5, `${step.title}: three's camera at ${view.world}, the step's eye at ${eye}`);
        const look = metres(towardEye.map((x) => -x * 1000));
        assert.ok(distance(view.looking, look) < 1e-4, `${step.title}: looks along ${view.looking}, expected ${look}`);
    });
    const problems = [];
    for (const label of lesson.labels) {
        const node = seen.marked.find((m) => m.name === label.text);
        if (!node) {
            problems.push(`${label.text}: no node of that name`);
            continue;
        }
        const off = distance(node.world, metres(label.point)) * 1000;
        if (node.parent !== label.structure || off > 0.01) {
            problems.push(`${label.text}: under ${node.parent}, ${off.toFixed(4)} mm from its point`);
        }
    }
    assert.deepEqual(problems, [], "labels as named nodes at their points");
    await opened.page.evaluate(([w, h]) => window.gltfCheck.renderFrom(0, w, h), [VIEWPORT.width, VIEWPORT.height]);
    await opened.page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
    const shot = join(OUT, `case-${c.key}-step1.png`);
    const png = await opened.page.screenshot();
    writeFileSync(shot, png);
    assertNotBlank(decodePng(png), shot);
    t.diagnostic(`the first step through three's camera: ${shot}`);
}

CASES.forEach((c, n) => {
    testIn(WEBGPU_RUN, `GLB${2 * n + 1} ${c.what} scene GLB passes the Khronos glTF-Validator with no error or warning`, { timeout: TIMEOUT }, async (t) => {
        const { file, bytes } = await caseGlb(c);
        const report = await gltfValidator.validateBytes(new Uint8Array(bytes), { uri: basename(file), format: "glb" });
        const { numErrors, numWarnings, numInfos, numHints, messages, truncated } = report.issues;
        const summary = `${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos, ${numHints} hints`;
        const listed = messages.map((m) => `  [${SEVERITIES[m.severity]}] ${m.code} ${m.pointer ?? ""}: ${m.message}`);
        t.diagnostic(`glTF-Validator ${report.validatorVersion}: ${summary}`);
        console.log(
            JSON.stringify({
                e2e: "gltf-validator",
                mode: MODE,
                file: basename(file),
                validator: report.validatorVersion,
                errors: numErrors,
                warnings: numWarnings,
                infos: numInfos,
                hints: numHints,
                codes: [...new Set(messages.map((m) => `${SEVERITIES[m.severity]}:${m.code}`))],
                draw_calls: report.info.drawCallCount,
                vertices: report.info.totalVertexCount,
                triangles: report.info.totalTriangleCount,
            }),
        );
        assert.ok(numErrors === 0 && numWarnings === 0, `glTF-Validator on ${file}: ${summary}${truncated ? " (list truncated)" : ""}:\n${listed.join("\n")}`);
        // Compressed by default: both extensions required, each structure's quantization error
        // stated and below 0.05 voxel diagonals.
        const { json } = readGlb(bytes);
        assert.deepEqual(json.extensionsRequired, ["EXT_meshopt_compression", "KHR_mesh_quantization"], "the case is compressed");
        for (const s of glbStructures(bytes)) {
            const q = s.quantization;
            assert.ok(q && q.max_error_mm > 0, `${s.name}: its record states the quantization`);
            assert.ok(q.max_error_voxel_diagonals < 0.05, `${s.name}: ${q.max_error_voxel_diagonals} voxel diagonals`);
        }
        assert.equal(report.info.drawCallCount, c.structures, "one draw call (mesh primitive) per structure");
    });

    testIn(WEBGPU_RUN, `GLB${2 * n + 2} three.js loads ${c.what} scene GLB in Chromium: names, colours, size in metres, +Y superior (rendered)`, { timeout: TIMEOUT }, async (t) => {
        const { file, bytes } = await caseGlb(c);
        const expected = await expectedStructures(c);
        assert.equal(expected.length, c.structures, `meshsmooth info lists ${c.structures} structures`);
        const glb = glbStructures(bytes);
        const name = basename(file);
        const { server, browser } = await threePage();
        server.files.set(name, bytes);
        const opened = await openThreePage(browser, server, VIEWPORT);
        try {
            const seen = await opened.page.evaluate((url) => window.gltfCheck.load(url), `/files/${name}`);
            const meshes = seen.meshes;
            const names = expected.map((s) => s.name);

            // Names: the glTF node names (userData.name), the material names, three's object names.
            assert.deepEqual(glb.map((s) => s.name), names, "the GLB's mesh nodes are the structures, in order");
            assert.deepEqual(meshes.map((m) => m.nodeName), names, "three's meshes come from the structures' nodes, in order");
            assert.deepEqual(meshes.map((m) => m.material), names, "each mesh's material is named after its structure");
            const sanitised = await opened.page.evaluate((names) => window.gltfCheck.sanitise(names), names);
            assert.deepEqual(meshes.map((m) => m.name), sanitised, "three names each mesh after its node (sanitised)");
            assert.deepEqual(meshes.map((m) => m.vertices), glb.map((s) => s.vertices), "vertex counts");

            // Colours (three's Color is linear) and opacity.
            const problems = [];
            meshes.forEach((m, i) => {
                assert.equal(m.colorSpace, "srgb-linear", "three's working colour space");
                const want = expected[i].color.map(srgbToLinear);
                const worst = Math.max(...want.map((w, k) => Math.abs(m.color[k] - w)));
                if (worst > 1 / 255) {
                    problems.push(`${names[i]}: linear colour ${m.color.map((x) => x.toFixed(4))} (sRGB ${m.colorSrgbHex}), expected ${want.map((x) => x.toFixed(4))} (sRGB ${expected[i].color.map((x) => Math.round(x * 255))})`);
                }
                const g = glb[i];
                if (Math.abs(m.opacity - expected[i].opacity) > 1e-6 || Math.abs(m.opacity - g.baseColorFactor[3]) > 1e-6) {
                    problems.push(`${names[i]}: opacity ${m.opacity}, expected ${expected[i].opacity} (baseColorFactor alpha ${g.baseColorFactor[3]})`);
                }
                if (m.transparent !== (g.alphaMode === "BLEND") || m.transparent !== (expected[i].opacity < 1)) {
                    problems.push(`${names[i]}: transparent ${m.transparent} with alphaMode ${g.alphaMode} and opacity ${expected[i].opacity}`);
                }
            });
            assert.deepEqual(problems, [], `materials differ from the structures:\n${problems.join("\n")}`);

            // Size and place: the data's extent (RAS mm, from the GLB's POSITION accessors)
            // in metres, right -> -X, superior -> +Y, anterior -> +Z.
            const min = [0, 1, 2].map((k) => Math.min(...glb.map((s) => s.min[k])));
            const max = [0, 1, 2].map((k) => Math.max(...glb.map((s) => s.max[k])));
            const extentMm = max.map((x, k) => x - min[k]);
            const wantBox = {
                min: [-max[0] / 1000, min[2] / 1000, min[1] / 1000],
                max: [-min[0] / 1000, max[2] / 1000, max[1] / 1000],
            };
            const axisOf = ["X (R-L)", "Y (S-I)", "Z (A-P)"];
            const extentOfAxis = [extentMm[0], extentMm[2], extentMm[1]];
            const size = seen.box.max.map((x, k) => x - seen.box.min[k]);
            const boxProblems = [];
            for (let k = 0; k < 3; k++) {
                const wantSize = extentOfAxis[k] / 1000;
                if (Math.abs(size[k] - wantSize) > 0.01 * wantSize) {
                    boxProblems.push(`${axisOf[k]}: three's box is ${size[k].toFixed(5)} m, the data ${extentOfAxis[k].toFixed(2)} mm`);
                }
                for (const end of ["min", "max"]) {
                    if (Math.abs(seen.box[end][k] - wantBox[end][k]) > 0.01 * wantSize) {
                        boxProblems.push(`${axisOf[k]}: box ${end} ${seen.box[end][k].toFixed(5)} m, expected ${wantBox[end][k].toFixed(5)} m`);
                    }
                }
            }
            assert.deepEqual(boxProblems, [], `three's world box differs from the data's extent:\n${boxProblems.join("\n")}`);

            // Orientation, structure by structure: the highest (most superior) structure is
            // the highest in three's world, and so on for right and anterior.
            const argmax = (values) => values.reduce((best, v, i) => (v > values[best] ? i : best), 0);
            const orientation = [
                ["superior (+S) is +Y", argmax(glb.map((s) => s.mean[2])), argmax(meshes.map((m) => m.meanWorld[1]))],
                ["anterior (+A) is +Z", argmax(glb.map((s) => s.mean[1])), argmax(meshes.map((m) => m.meanWorld[2]))],
                ["right (+R) is -X", argmax(glb.map((s) => s.mean[0])), argmax(meshes.map((m) => -m.meanWorld[0]))],
            ];
            for (const [what, inData, inThree] of orientation) {
                assert.equal(names[inThree], names[inData], `${what}: the data's extreme structure is ${names[inData]}, three's is ${names[inThree]}`);
            }
            const tolerance = 1e-3 * Math.max(...extentMm);
            meshes.forEach((m, i) => {
                const [r, a, s] = glb[i].mean;
                const want = [-r, s, a];
                const off = Math.max(...want.map((w, k) => Math.abs(m.meanWorld[k] * 1000 - w)));
                assert.ok(off <= tolerance, `${names[i]}: centre in three's world ${m.meanWorld.map((x) => (x * 1000).toFixed(2))} mm, expected (-R, S, A) = ${want.map((x) => x.toFixed(2))} mm`);
            });

            if (c.lesson) await checkLesson(t, c, seen, opened);

            // One rendering, seen from the front (+Z, anterior) with superior up.
            const rendered = await opened.page.evaluate(([w, h]) => window.gltfCheck.render(w, h), [VIEWPORT.width, VIEWPORT.height]);
            await opened.page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
            const png = await opened.page.screenshot();
            const shot = join(OUT, `case-${c.key}.png`);
            writeFileSync(shot, png);
            const image = decodePng(png);
            assertNotBlank(image, shot);
            const background = colourHistogram(image)[0][1] / (image.width * image.height);
            t.diagnostic(`rendered with WebGL${rendered.webgl} on ${rendered.renderer}: ${shot}`);

            assert.deepEqual(opened.foreignRequests(), [], "the page requested something outside its own origin");
            assert.deepEqual(opened.pageErrors.map(String), [], "uncaught errors in the page");
            const threeWarnings = opened.console.filter((l) => (l.type === "warning" || l.type === "error") && /THREE/.test(l.text));
            assert.deepEqual(threeWarnings, [], "three.js warned about the file");
            console.log(
                JSON.stringify({
                    e2e: "three-gltf",
                    mode: MODE,
                    file: name,
                    three: seen.revision,
                    meshes: meshes.length,
                    vertices: meshes.reduce((n, m) => n + m.vertices, 0),
                    box_size_m: size.map((x) => Number(x.toFixed(6))),
                    data_extent_mm_ras: extentMm.map((x) => Number(x.toFixed(3))),
                    top: names[argmax(meshes.map((m) => m.meanWorld[1]))],
                    colours: meshes.slice(0, 6).map((m) => `${m.name} ${m.colorSrgbHex}`),
                    webgl: rendered.renderer,
                    screenshot_background_share: Number(background.toFixed(3)),
                    requests: opened.requests.map((u) => new URL(u).pathname),
                    console: opened.console.map((l) => `[${l.type}] ${l.text}`),
                }),
            );
        } finally {
            await opened.close();
            server.files.delete(name);
        }
    });
});
