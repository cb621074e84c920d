// Windowed sinc (Taubin 1996) as src/smooth/sinc.rs computes it: the Chebyshev recurrence
//   T_0 x = x,  T_1 x = (x + mean_N x) / 2,  T_{k+1} x = T_k x + mean_N(T_k x) - T_{k-1} x
// on positions centred on the bounding box's centre, accumulating the running estimate
// centre + sum c_k T_k x. The recurrence runs unconstrained; weights and the bound act on the
// final estimate's displacement from the original (sinc_finish).

@group(1) @binding(0) var<storage, read> gathered: array<vec4<f32>>;
// T_{k-1} x, overwritten in place with T_{k+1} x (each vertex reads only its own entry).
@group(1) @binding(1) var<storage, read_write> previous: array<vec4<f32>>;
@group(1) @binding(2) var<storage, read_write> estimate: array<vec4<f32>>;
// Written by the first term only: T_1 x.
@group(1) @binding(3) var<storage, read_write> first_current: array<vec4<f32>>;

// The first two terms, with gathered = original: previous = x - centre, first_current =
// T_1 (x - centre), estimate = centre + c0 T_0 + c1 T_1. Isolated vertices stay put.
@compute @workgroup_size(WORKGROUP_SIZE)
fn sinc_first(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let i = vertex_index(id, groups);
    if i >= params.vertex_count {
        return;
    }
    let centre = params.centre.xyz;
    let o = original[i].xyz;
    let z0 = o - centre;
    previous[i] = vec4<f32>(z0, 0.0);
    if is_isolated(i) {
        first_current[i] = vec4<f32>(z0, 0.0);
        estimate[i] = vec4<f32>(o, 0.0);
        return;
    }
    let m = ring_mean(i);
    let t1 = 0.5 * (z0 + (m - centre));
    first_current[i] = vec4<f32>(t1, 0.0);
    estimate[i] = vec4<f32>(centre + params.c0 * z0 + params.c1 * t1, 0.0);
}

// One further term, with gathered = T_k x: previous <- T_{k+1} x, estimate += c_k T_{k+1} x
// (c_k in params.factor).
@compute @workgroup_size(WORKGROUP_SIZE)
fn sinc_term(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let i = vertex_index(id, groups);
    if i >= params.vertex_count {
        return;
    }
    let tk = gathered[i].xyz;
    if is_isolated(i) {
        // L = 0 there: every T_k x equals x, and the estimate stays the original.
        previous[i] = vec4<f32>(tk, 0.0);
        return;
    }
    let m = ring_mean(i);
    let t = tk + m - previous[i].xyz;
    previous[i] = vec4<f32>(t, 0.0);
    estimate[i] = vec4<f32>(estimate[i].xyz + params.factor * t, 0.0);
}

// Weights and the bound on the estimate's displacement from the original, in place.
@compute @workgroup_size(WORKGROUP_SIZE)
fn sinc_finish(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let i = vertex_index(id, groups);
    if i >= params.vertex_count {
        return;
    }
    let e = constrain(i, original[i].xyz, estimate[i].xyz);
    estimate[i] = vec4<f32>(e, 0.0);
}
