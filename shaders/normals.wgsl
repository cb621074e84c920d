// Area-weighted unit vertex normals as mesh::vertex_normals computes them: the sum of the
// unnormalised cross products of the incident triangles, in ascending triangle order, then
// normalised; [0, 0, 0] where the sum vanishes. Each triangle's product is taken from the vertex
// itself, (p_j - p_i) x (p_k - p_i) with (i, j, k) in winding order (from its two shorter
// edges): the same vector as the CPU's (b - a) x (c - a).

// The vertex -> triangle CSR, and for each entry the triangle's other two corners in winding order.
@group(0) @binding(1) var<storage, read> fan_offsets: array<u32>;
@group(0) @binding(2) var<storage, read> fan_corners: array<vec2<u32>>;
@group(0) @binding(3) var<storage, read_write> normals: array<vec4<f32>>;

@compute @workgroup_size(WORKGROUP_SIZE)
fn vertex_normals(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let i = vertex_index(id, groups);
    if i >= surface.vertex_count {
        return;
    }
    let p = positions[i].xyz;
    var sum = vec3<f32>(0.0);
    let end = fan_offsets[i + 1u];
    for (var k = fan_offsets[i]; k < end; k++) {
        let c = fan_corners[k];
        let pj = positions[c.x].xyz;
        let pk = positions[c.y].xyz;
        sum += triangle_normal(pj - p, pk - p, pk - pj);
    }
    // Scaled by the largest component first, so the length neither overflows nor underflows.
    let largest = max(abs(sum.x), max(abs(sum.y), abs(sum.z)));
    var n = vec3<f32>(0.0);
    // Finite: at most the largest f32 (written exactly; a decimal literal rounds past it).
    if largest > 0.0 && largest <= 0x1.fffffep+127f {
        let s = sum / largest;
        n = s / sqrt(dot(s, s));
    }
    normals[i] = vec4<f32>(n, 0.0);
}
