// The example platform: the authoring page and the viewer in iframes from meshsmooth's own
// origin (`?app=URL`, by default http://127.0.0.1:8080/), driven by their postMessage protocol.
import { connect } from "./meshsmooth-frame.js";

const app = new URL(new URLSearchParams(location.search).get("app") ?? "http://127.0.0.1:8080/");
const author = connect(document.getElementById("author"), app.origin);
const viewer = connect(document.getElementById("viewer"), app.origin);
author.open(app.pathname, { shortcuts: "off" });
viewer.open(app.pathname, { mode: "viewer" });

const $ = (id) => document.getElementById(id);
/** What happened, newest last; `window.platform.log` for whoever drives this page. */
const events = [];
function log(line) {
    events.push(line);
    const item = document.createElement("li");
    item.textContent = line;
    $("log").append(item);
}
/** For whoever drives this page (its end-to-end test): the log, both pages, the case received. */
window.platform = { log: events, author, viewer, published: null, statements: [] };

/** Runs `work`, logging why it failed instead of leaving the button dead. */
function action(button, work) {
    button.addEventListener("click", async () => {
        button.disabled = true;
        try {
            await work();
        } catch (error) {
            log(`failed: ${error.message}`);
        } finally {
            button.disabled = false;
        }
    });
}

author.ready.then((page) => log(`authoring page ready (${page.backend})`));
viewer.ready.then((page) => log(`viewer ready (${page.backend})`));
author.on("loaded", (c) => {
    log(`authoring page opened ${c.file}: ${c.structures.length} structures`);
    $("suggest").disabled = $("publish").disabled = false;
});
author.on("failed", (e) => log(`authoring page could not open the file: ${e.error}`));
author.on("changed", (c) => log(`case changed: ${c.structures.filter((s) => s.visible).length} of ${c.structures.length} structures shown`));
viewer.on("loaded", (c) => {
    log(`viewer shows ${c.structures.length} structures`);
    $("published").replaceChildren(...c.structures.map((s) => {
        const item = document.createElement("li");
        const swatch = document.createElement("span");
        swatch.style.background = `rgb(${s.color.slice(0, 3).map((v) => Math.round(v * 255)).join(",")})`;
        item.append(swatch, s.group ? `${s.name} (${s.group})` : s.name);
        if (s.description) item.append(`: ${s.description}`);
        return item;
    }));
});

// What the student did, as xAPI statements a learning record store keeps (with the actor,
// which only the platform knows).
const record = (statement) => window.platform.statements.push({ actor: { name: "the signed-in student" }, ...statement });
viewer.on("step", (s) => {
    log(`student at step ${s.step + 1} of ${s.steps}: ${s.title}`);
    record(s.statement);
});
viewer.on("quizAnswered", (a) => {
    log(`student answered ${a.mode} on ${a.structure}: ${a.right ? "right" : `wrong (${a.given})`} in ${(a.ms / 1000).toFixed(1)} s`);
    record(a.statement);
});
viewer.on("quizFinished", (f) => {
    log(`student finished the quiz: ${f.right} of ${f.questions}, ${f.passed ? "passed" : "not passed"}`);
    record(f.statement);
});

$("segmentation").addEventListener("change", async (event) => {
    const file = event.target.files[0];
    if (!file) return;
    log(`handing ${file.name} to the authoring page`);
    try {
        await author.call("loadCase", new Uint8Array(await file.arrayBuffer()), file.name);
    } catch (error) {
        log(`failed: ${error.message}`);
    }
});
action($("suggest"), async () => {
    const result = await author.call("suggestAll", {});
    log(`suggested and smoothed ${result.done} of ${result.total} structures`);
});
action($("publish"), async () => {
    const bytes = await author.call("exportCase", "glb");
    window.platform.published = bytes;
    log(`received the case: ${bytes.length} bytes`);
    await viewer.call("loadCase", bytes, "case.glb");
});
