// Shared by every smoothing kernel and prepended to each one (WGSL has no includes): the step
// parameters, the mesh bind group (group 0), the vertex index of a 2-D dispatch, the neighbour
// mean and the per-vertex weights and displacement bound. Mirrors src/smooth (the CPU
// reference), operation for operation, so both round alike.
//
// Every kernel declares `gathered` (group 1, binding 0): the positions whose ring mean it takes.

// One step's parameters; mirrors `StepParams` in src/gpu/layout.rs (48 bytes).
struct StepParams {
    vertex_count: u32,
    // HAS_WEIGHTS | HAS_BOUND
    flags: u32,
    // The displacement bound d_max, when HAS_BOUND is set.
    bound: f32,
    // lambda or mu (umbrella steps); c_k (windowed-sinc terms after the first).
    factor: f32,
    // HC's alpha and beta.
    alpha: f32,
    beta: f32,
    // The first two windowed-sinc coefficients.
    c0: f32,
    c1: f32,
    // Windowed sinc's centring (the bounding box's centre); w unused.
    centre: vec4<f32>,
}

const HAS_WEIGHTS: u32 = 1u;
const HAS_BOUND: u32 = 2u;
// Must equal WORKGROUP_SIZE in src/gpu/layout.rs (a test checks it).
const WORKGROUP_SIZE: u32 = 64u;

@group(0) @binding(0) var<uniform> params: StepParams;
// The smoothing ring as CSR: vertex i's neighbours are neighbors[offsets[i] .. offsets[i + 1]].
@group(0) @binding(1) var<storage, read> offsets: array<u32>;
@group(0) @binding(2) var<storage, read> neighbors: array<u32>;
@group(0) @binding(3) var<storage, read> original: array<vec4<f32>>;
// In [0, 1], sanitised on upload (NaN -> 0).
@group(0) @binding(4) var<storage, read> weights: array<f32>;

// Past 65,535 workgroups per dimension the dispatch is 2-D: rows of `groups.x` workgroups.
fn vertex_index(id: vec3<u32>, groups: vec3<u32>) -> u32 {
    return id.x + id.y * groups.x * WORKGROUP_SIZE;
}

fn is_isolated(i: u32) -> bool {
    return offsets[i] == offsets[i + 1u];
}

// Mean of `gathered` over vertex i's (non-empty) ring. Neighbours alternate between two sums
// exactly as the CPU's ring_mean does, so the rounding matches.
fn ring_mean(i: u32) -> vec3<f32> {
    let start = offsets[i];
    let end = offsets[i + 1u];
    var even = vec3<f32>(0.0);
    var odd = vec3<f32>(0.0);
    var k = start;
    while k + 1u < end {
        even += gathered[neighbors[k]].xyz;
        odd += gathered[neighbors[k + 1u]].xyz;
        k += 2u;
    }
    if k < end {
        even += gathered[neighbors[k]].xyz;
    }
    let inv = 1.0 / f32(end - start);
    return (even + odd) * inv;
}

// Where vertex i goes when its filter proposes `proposed` from `current`: the weight scales the
// move, then the vertex is pulled back onto the ball of radius d_max around its original.
fn constrain(i: u32, current: vec3<f32>, proposed: vec3<f32>) -> vec3<f32> {
    var p = proposed;
    if (params.flags & HAS_WEIGHTS) != 0u {
        let w = weights[i];
        p = current + w * (p - current);
    }
    if (params.flags & HAS_BOUND) != 0u {
        let o = original[i].xyz;
        let d = p - o;
        let len2 = d.x * d.x + d.y * d.y + d.z * d.z;
        if len2 > params.bound * params.bound {
            p = o + d * (params.bound / sqrt(len2));
        }
    }
    return p;
}
