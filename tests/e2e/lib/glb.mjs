// Reading the GLBs the app and the CLI write, without three.js: the chunks, and each mesh
// node's float attributes as stored (our files keep the data's millimetres in the meshes).
import assert from "node:assert/strict";

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

/** A float VEC3 accessor's values, as a plain array of numbers. */
function vec3s(json, bin, index) {
    const accessor = json.accessors[index];
    assert.equal(accessor.componentType, 5126, "a float accessor");
    const view = json.bufferViews[accessor.bufferView];
    const stride = view.byteStride ?? 12;
    const start = (view.byteOffset ?? 0) + (accessor.byteOffset ?? 0);
    const out = [];
    for (let i = 0; i < accessor.count; i++) {
        for (let k = 0; k < 3; k++) out.push(bin.readFloatLE(start + i * stride + 4 * k));
    }
    return out;
}

/** Every mesh node, depth first: `{name, positions, targets}` (its first primitive's). */
export function meshNodes(bytes) {
    const { json, bin } = readGlb(bytes);
    const out = [];
    const visit = (index) => {
        const node = json.nodes[index];
        if (node.mesh !== undefined) {
            const primitive = json.meshes[node.mesh].primitives[0];
            out.push({
                name: node.name,
                positions: vec3s(json, bin, primitive.attributes.POSITION),
                targets: (primitive.targets ?? []).map((t) => vec3s(json, bin, t.POSITION)),
            });
        }
        for (const child of node.children ?? []) visit(child);
    };
    for (const root of json.scenes[json.scene ?? 0].nodes) visit(root);
    return out;
}
