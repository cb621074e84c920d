// End-to-end tests of the sources authors have, in the page: a FreeSurfer MGZ, a DICOM SEG and a
// TotalSegmentator multilabel NIfTI open into the structures the CLI extracts, with their names;
// the standard codes their names carry reach the viewer through a case glTF.
//
//   E2E_MODE=webgpu|cpu node --test tests/e2e/sources.test.mjs   (tests/e2e/run.sh runs both)
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import { join } from "node:path";

import * as cli from "./lib/cli.mjs";
import { E2E_OUT, ROOT } from "./lib/paths.mjs";
import { gltfValidator } from "./lib/deps.mjs";
import { EVERY_RUN, appSuite, testIn } from "./lib/suite.mjs";

const { MODE, withApp } = appSuite({ beforeAll: () => cli.requireCli() });

const ASEG_MGZ = join(ROOT, "tests/data/phantom_aseg.mgz");
const TIMEOUT = 240_000;

testIn(EVERY_RUN, "F1 a FreeSurfer MGZ opens with FreeSurfer's names and codes, as the CLI extracts it", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        await app.loadMesh(readFileSync(ASEG_MGZ), "phantom_aseg.mgz");
        const page = (await app.call("structures")).structures;
        const native = (await cli.cliJson("extract", ASEG_MGZ, "-o", join(E2E_OUT, `extract-mgz-${MODE}/`), "--json")).structures;
        assert.deepEqual(page.map((s) => s.name), ["Left-Thalamus", "Left-Hippocampus", "Right-Hippocampus", "ctx-rh-insula"]);
        assert.deepEqual(
            page.map((s) => [s.label, s.name, s.voxels, s.vertices, s.triangles]),
            native.map((s) => [s.label, s.name, s.voxels, s.vertices, s.triangles]),
        );
        page.forEach((s, i) => s.color.forEach((c, k) => assert.ok(Math.abs(c - native[i].color[k]) < 1e-6, `${s.name} colour`)));
        // The aseg labels' SNOMED CT codes from the shipped table; the cortical parcel has none.
        assert.deepEqual(page.map((s) => s.codes), native.map((s) => s.codes));
        assert.deepEqual(page.map((s) => s.codes?.type.value ?? null), ["119406000", "5366008", "5366008", null]);
        await app.screenshot("F1-aseg-mgz-names");
    });
});

testIn(EVERY_RUN, "F2 a TotalSegmentator multilabel NIfTI opens with its class names, readable, as the CLI extracts it", { timeout: TIMEOUT }, async () => {
    await withApp(async (app) => {
        const file = join(ROOT, "tests/data/totalseg_multilabel.nii.gz");
        await app.loadMesh(readFileSync(file), "totalseg_multilabel.nii.gz");
        const page = (await app.call("structures")).structures;
        const native = (await cli.cliJson("extract", file, "-o", join(E2E_OUT, `extract-totalseg-${MODE}/`), "--json")).structures;
        assert.deepEqual(page.map((s) => s.name), ["Right kidney", "Liver", "Portal vein and splenic vein"]);
        assert.deepEqual(
            page.map((s) => [s.label, s.name, s.voxels, s.vertices, s.triangles]),
            native.map((s) => [s.label, s.name, s.voxels, s.vertices, s.triangles]),
        );
        await app.screenshot("F2-totalsegmentator-names");
    });
});

testIn(EVERY_RUN, "F3 standard codes survive case build and case info into the viewer's structures() and details", { timeout: TIMEOUT }, async () => {
    const file = join(ROOT, "tests/data/totalseg_multilabel.nii.gz");
    const glb = join(E2E_OUT, MODE, "totalseg-case.glb");
    await cli.cliJson("case", "build", file, "--search", "local", "-o", glb, "--json");
    const info = await cli.cliJson("case", "info", glb, "--json");
    const kidney = {
        category: { scheme: "SCT", value: "123037004", meaning: "Anatomical Structure" },
        type: { scheme: "SCT", value: "64033007", meaning: "Kidney" },
        modifier: { scheme: "SCT", value: "24028007", meaning: "Right" },
    };
    assert.deepEqual(info.structures[0].codes, kidney);
    assert.equal(info.structures[1].codes.modifier, null);
    const report = await gltfValidator.validateBytes(new Uint8Array(readFileSync(glb)), { uri: "totalseg-case.glb", format: "glb" });
    const issues = report.issues.messages.filter((m) => m.severity <= 1).map((m) => `${m.code} ${m.pointer ?? ""}: ${m.message}`);
    assert.deepEqual(issues, [], "the case GLB with codes has no validator errors or warnings");
    await withApp(async (app) => {
        const opened = await app.loadMesh(readFileSync(glb), "totalseg-case.glb", "loadCase");
        assert.deepEqual(opened.structures.map((s) => s.codes), info.structures.map((s) => s.codes));
        assert.deepEqual(opened.structures[0].codes, kidney);
        assert.equal(opened.structures[1].codes.type.value, "10200004");
        await app.stateWhen((s) => s.layout.structures.length === 3 && s.loading === null, "the case's three rows");
        await app.screenshot("F3-viewer-codes");
    }, { query: "?mode=viewer" });
});

testIn(EVERY_RUN, "F4 a DICOM SEG opens with its segments' names, colours and codes, as the CLI extracts it and as the .seg.nrrd", { timeout: TIMEOUT }, async () => {
    const file = join(ROOT, "tests/data/dicom_seg/phantom.dcm");
    const nrrd = join(ROOT, "../shared/data/labelmaps/case_phantom_shared.seg.nrrd");
    await withApp(async (app) => {
        await app.loadMesh(readFileSync(file), "phantom.dcm");
        const page = (await app.call("structures")).structures;
        const native = (await cli.cliJson("extract", file, "-o", join(E2E_OUT, `extract-dicom-seg-${MODE}/`), "--json")).structures;
        const slicer = (await cli.cliJson("extract", nrrd, "-o", join(E2E_OUT, `extract-seg-nrrd-${MODE}/`), "--json")).structures;
        assert.deepEqual(page.map((s) => s.name), ["liver", "portal_vein", "tumor", "right_kidney"]);
        assert.deepEqual(
            page.map((s) => [s.label, s.name, s.voxels, s.vertices, s.triangles]),
            native.map((s) => [s.label, s.name, s.voxels, s.vertices, s.triangles]),
        );
        assert.deepEqual(page.map((s) => [s.name, s.voxels, s.triangles]), slicer.map((s) => [s.name, s.voxels, s.triangles]));
        page.forEach((s, i) => s.color.forEach((c, k) => assert.ok(Math.abs(c - slicer[i].color[k]) * 255 <= 2, `${s.name} colour`)));
        assert.deepEqual(page.map((s) => s.codes?.type.meaning), ["Liver", "Portal vein", "Neoplasm", "Kidney"]);
        assert.equal(page[3].codes.modifier.meaning, "Right");
        assert.equal(page[2].codes.category.meaning, "Morphologically Altered Structure");
        await app.screenshot("F4-dicom-seg");
    });
});
