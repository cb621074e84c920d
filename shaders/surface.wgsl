// Shared by the kernels that look at the surface instead of smoothing it (the drifting reference,
// vertex normals, the measures) and prepended to each: the per-mesh constants (group 0,
// binding 0; each kernel adds the mesh arrays it reads to group 0) and the positions it looks at
// (group 1: a run's result or the original). Mirrors src/metrics and src/mesh/normals.rs.

// Per-mesh constants; mirrors `SurfaceParams` in src/gpu/layout.rs (32 bytes).
struct SurfaceParams {
    vertex_count: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
    // The original bounding box's centre (w unused). The volume is summed about it: the same
    // number on a closed mesh, with terms that stay small in f32.
    centre: vec4<f32>,
}

// Must equal WORKGROUP_SIZE in src/gpu/layout.rs (a test checks it).
const WORKGROUP_SIZE: u32 = 64u;

@group(0) @binding(0) var<uniform> surface: SurfaceParams;
// The positions looked at, vec4 per vertex (w = 0).
@group(1) @binding(0) var<storage, read> positions: array<vec4<f32>>;

// Past 65,535 workgroups per dimension the dispatch is 2-D: rows of `groups.x` workgroups.
fn vertex_index(id: vec3<u32>, groups: vec3<u32>) -> u32 {
    return id.x + id.y * groups.x * WORKGROUP_SIZE;
}

// The unnormalised normal (p_j - p_i) x (p_k - p_i) of a triangle (i, j, k) in winding order,
// given its edges u = p_j - p_i, v = p_k - p_i and w = p_k - p_j (each subtracted from the
// positions directly). It equals u x w and v x w too; the pair of shorter edges is taken, so a
// needle's normal is not lost to the cancellation between its two long edges.
fn triangle_normal(u: vec3<f32>, v: vec3<f32>, w: vec3<f32>) -> vec3<f32> {
    let uu = dot(u, u);
    let vv = dot(v, v);
    let ww = dot(w, w);
    if ww >= uu && ww >= vv {
        return cross(u, v);
    }
    if uu >= vv {
        return cross(v, w);
    }
    return cross(u, w);
}
