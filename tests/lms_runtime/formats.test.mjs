// The value formats (web/lms/formats.js), the progress kept as suspend_data (progress.js), the
// outbox's order and coalescing (outbox.js) and the viewer's address (viewer_link.js).
import { describe, it } from "node:test";
import assert from "node:assert/strict";

import { clip, cmiTimeOfDay, cmiTimespan, identifier, isoDuration, languageList, scormTimestamp } from "../../web/lms/formats.js";
import { Outbox } from "../../web/lms/outbox.js";
import { Progress } from "../../web/lms/progress.js";
import { relativePath, viewerUrl } from "../../web/lms/viewer_link.js";

describe("formats", () => {
    it("writes SCORM 1.2 time spans and times of day", () => {
        assert.equal(cmiTimespan(0), "0000:00:00.00");
        assert.equal(cmiTimespan(2345), "0000:00:02.35");
        assert.equal(cmiTimespan(3_723_450), "0001:02:03.45");
        assert.equal(cmiTimespan(-5), "0000:00:00.00");
        assert.equal(cmiTimespan(1e12), "9999:59:59.99", "four digits of hours at most");
        assert.equal(cmiTimeOfDay(new Date(2026, 4, 1, 7, 5, 9)), "07:05:09");
    });

    it("writes ISO 8601 durations with hundredths at most, and SCORM 2004 timestamps", () => {
        assert.equal(isoDuration(0), "PT0S");
        assert.equal(isoDuration(2345), "PT2.35S");
        assert.equal(isoDuration(2300), "PT2.3S");
        assert.equal(isoDuration(60_000), "PT1M");
        assert.equal(isoDuration(3_723_450), "PT1H2M3.45S");
        assert.equal(isoDuration(90_000_000), "PT25H");
        assert.equal(scormTimestamp(new Date(Date.UTC(2026, 4, 1, 12, 34, 56, 789))), "2026-05-01T12:34:56.78Z");
    });

    it("makes identifiers without spaces from names in any script", () => {
        assert.equal(identifier("Left kidney"), "left-kidney");
        assert.equal(identifier("  Aorta (abdominal) "), "aorta-abdominal");
        assert.equal(identifier("Vena cava / inferior"), "vena-cava-inferior");
        assert.equal(identifier("肝臓"), "%E8%82%9D%E8%87%93");
        assert.equal(identifier("Niere (links)"), "niere-links");
        assert.equal(identifier("Ösophagus"), "%C3%B6sophagus");
        assert.equal(identifier("?!"), "structure");
        const long = identifier("肝".repeat(100), 20);
        assert.ok(long.length <= 20 && /^(%[0-9A-F]{2})+$/.test(long), long);
        assert.equal(clip("ab😀cd", 3), "ab😀");
    });

    it("passes on well-formed language tags only", () => {
        assert.equal(languageList("de-CH, fr"), "de-CH,fr");
        assert.equal(languageList("English"), null);
        assert.equal(languageList(""), null);
    });
});

describe("progress", () => {
    it("writes and reads the suspend_data form", () => {
        const p = new Progress({ steps: 10, quiz: null });
        p.show(0, 10);
        p.show(5, 10);
        p.show(9, 10);
        assert.equal(p.toText(), "1:9:122");
        assert.equal(p.tourDone, true);
        const back = new Progress({ steps: 10, quiz: null });
        assert.equal(back.readText("1:9:122"), true);
        assert.deepEqual([...back.seen].sort((a, b) => a - b), [0, 5, 9]);
        assert.equal(back.step, 9);
        assert.equal(new Progress({ steps: 3 }).toText(), "1:-:");
        assert.equal(back.readText("someone else's data"), false);
    });

    it("stays under SCORM 1.2's 4,096 characters for long tours", () => {
        const p = new Progress({ steps: 200, quiz: null });
        for (let i = 0; i < 200; i++) p.show(i, 200);
        assert.ok(p.toText().length < 60, p.toText());
        const huge = new Progress({ steps: 16000, quiz: null });
        for (let i = 0; i < 16000; i++) huge.show(i, 16000);
        assert.ok(huge.toText().length < 4096, `${huge.toText().length}`);
    });

    it("measures steps seen and the quiz, 1 once complete", () => {
        const p = new Progress({ steps: 3, quiz: { questions: 4 } });
        p.show(0, 3);
        assert.equal(p.measure, 0.25);
        p.quizDone = true;
        assert.equal(p.measure, 1);
        assert.equal(p.finished, true);
    });
});

describe("outbox", () => {
    it("sends in order, retries the first until it goes, and keeps only the last of a document", async () => {
        const sent = [];
        let down = 3;
        const saved = [];
        const outbox = new Outbox({
            send: async (item) => {
                if (item.n === 1 && down-- > 0) return "retry";
                sent.push(item.n);
                return "done";
            },
            store: { load: () => [{ n: 0 }], save: (items) => saved.push(items.map((i) => i.n)) },
            retry: { first: 1, max: 4 },
        });
        outbox.push({ n: 1 });
        outbox.push({ n: 2, key: "doc" });
        outbox.push({ n: 3 });
        outbox.push({ n: 4, key: "doc" });
        assert.equal(outbox.size, 4, "nothing goes before start");
        outbox.start();
        await outbox.idle();
        assert.deepEqual(sent, [0, 1, 3, 4]);
        assert.deepEqual(saved.at(-1), []);
    });
});

describe("the viewer's address", () => {
    it("names the case relative to the viewer and this page's origin as its parent", () => {
        const url = new URL(viewerUrl("https://lms.example/content/42/index.html?endpoint=x", { viewer: "viewer/index.html", caseFile: "case.glb", language: "de" }));
        assert.equal(url.pathname, "/content/42/viewer/index.html");
        assert.deepEqual(Object.fromEntries(url.searchParams), { mode: "viewer", case: "../case.glb", parent: "https://lms.example", lang: "de" });
        assert.equal(new URL(viewerUrl("file:///tmp/p/index.html")).searchParams.get("parent"), null, "a file has no origin to name");
        assert.equal(relativePath("https://a/x/v/w/i.html", "https://a/x/c/case.glb"), "../../c/case.glb");
    });
});
