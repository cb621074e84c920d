// Reading the GLBs the app and the CLI write, without three.js: the chunks, and each mesh
// node's attributes in the data's millimetres. Compressed files (the default: 16-bit positions
// on a lattice that each structure's node scales, EXT_meshopt_compression views) are decoded
// with three's MeshoptDecoder, the decoder other viewers use.
import assert from "node:assert/strict";
import { join } from "node:path";
import { pathToFileURL } from "node:url";

import { ROOT } from "./paths.mjs";

const { MeshoptDecoder } = await import(
    pathToFileURL(join(ROOT, "web", "node_modules", "three", "examples", "jsm", "libs", "meshopt_decoder.module.js")).href
);
await MeshoptDecoder.ready;

/** The JSON and binary chunks of a GLB. */
export function readGlb(bytes) {
    assert.equal(bytes.toString("latin1", 0, 4), "glTF", "GLB magic");
    assert.equal(bytes.readUInt32LE(4), 2, "GLB version");
    assert.equal(bytes.readUInt32LE(8), bytes.length, "GLB length");
    const jsonLength = bytes.readUInt32LE(12);
    assert.equal(bytes.toString("latin1", 16, 20), "JSON");
    const json = JSON.parse(bytes.toString("utf8", 20, 20 + jsonLength));
    const at = 20 + jsonLength;
    const bin = at < bytes.length ? bytes.subarray(at + 8, at + 8 + bytes.readUInt32LE(at)) : Buffer.alloc(0);
    return { json, bin };
}

/** A buffer view's bytes (from the BIN chunk), decoded where the view is compressed. */
export function viewBytes(json, bin, index) {
    const view = json.bufferViews[index];
    const compressed = view.extensions?.EXT_meshopt_compression;
    if (!compressed) {
        assert.equal(view.buffer, 0, "an uncompressed view reads the BIN chunk");
        const start = view.byteOffset ?? 0;
        return bin.subarray(start, start + view.byteLength);
    }
    assert.equal(compressed.buffer, 0, "compressed bytes are in the BIN chunk");
    const start = compressed.byteOffset ?? 0;
    const source = new Uint8Array(bin.subarray(start, start + compressed.byteLength));
    const target = new Uint8Array(compressed.count * compressed.byteStride);
    MeshoptDecoder.decodeGltfBuffer(target, compressed.count, compressed.byteStride, source, compressed.mode, compressed.filter ?? "NONE");
    return Buffer.from(target.buffer);
}

/** Size, reader and normalized range of each component type. */
const COMPONENTS = {
    5120: [1, "readInt8", 127],
    5121: [1, "readUInt8", 255],
    5122: [2, "readInt16LE", 32767],
    5123: [2, "readUInt16LE", 65535],
    5126: [4, "readFloatLE", 0],
};

/** A VEC3 accessor's values as a plain array of numbers (normalized ones mapped to [-1, 1]). */
function vec3s(json, bin, index) {
    const accessor = json.accessors[index];
    assert.equal(accessor.type, "VEC3");
    const [size, read, max] = COMPONENTS[accessor.componentType];
    const view = json.bufferViews[accessor.bufferView];
    const bytes = viewBytes(json, bin, accessor.bufferView);
    const stride = view.byteStride ?? 3 * size;
    const start = accessor.byteOffset ?? 0;
    const out = [];
    for (let i = 0; i < accessor.count; i++) {
        for (let k = 0; k < 3; k++) {
            const raw = bytes[read](start + i * stride + size * k);
            out.push(accessor.normalized ? Math.max(raw / max, -1) : raw);
        }
    }
    return out;
}

/**
 * A structure node's own transform (a compressed case's lattice: translation and uniform
 * scale; none in an uncompressed one) applied to flat xyz values; `offset` false for
 * displacements.
 */
function placed(node, values, offset = true) {
    const t = offset ? (node.translation ?? [0, 0, 0]) : [0, 0, 0];
    const s = node.scale ?? [1, 1, 1];
    assert.ok(node.matrix === undefined && node.rotation === undefined, "structure nodes only translate and scale");
    return values.map((v, i) => v * s[i % 3] + t[i % 3]);
}

/** Every mesh node, depth first: `{name, positions, targets}` (its first primitive's, in mm). */
export function meshNodes(bytes) {
    const { json, bin } = readGlb(bytes);
    const out = [];
    const visit = (index) => {
        const node = json.nodes[index];
        if (node.mesh !== undefined) {
            const primitive = json.meshes[node.mesh].primitives[0];
            out.push({
                name: node.name,
                positions: placed(node, vec3s(json, bin, primitive.attributes.POSITION)),
                targets: (primitive.targets ?? []).map((t) => placed(node, vec3s(json, bin, t.POSITION), false)),
                quantization: node.extras?.meshsmooth?.quantization ?? null,
            });
        }
        for (const child of node.children ?? []) visit(child);
    };
    for (const root of json.scenes[json.scene ?? 0].nodes) visit(root);
    return out;
}
