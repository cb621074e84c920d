// Laplace+HC (Vollmer, Mencl, Mueller 1999), one iteration in two Jacobi passes, as
// src/smooth/hc.rs computes it:
//   hc_differences: b_i = mean_N(q) - (alpha o_i + (1 - alpha) q_i)   (gathered = q, updated = b)
//   hc_correct:     q_i <- p_i - (beta b_i + (1 - beta) mean_N(b))     (gathered = b, updated = q)
// where p_i is rebuilt as b_i + alpha o_i + (1 - alpha) q_i. The correction reads q only at the
// vertex it writes, so it updates q in place.

@group(1) @binding(0) var<storage, read> gathered: array<vec4<f32>>;
@group(1) @binding(1) var<storage, read_write> updated: array<vec4<f32>>;

@compute @workgroup_size(WORKGROUP_SIZE)
fn hc_differences(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let i = vertex_index(id, groups);
    if i >= params.vertex_count {
        return;
    }
    var b = vec3<f32>(0.0);
    if !is_isolated(i) {
        let keep = 1.0 - params.alpha;
        let p = ring_mean(i);
        b = p - (params.alpha * original[i].xyz + keep * gathered[i].xyz);
    }
    updated[i] = vec4<f32>(b, 0.0);
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn hc_correct(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let i = vertex_index(id, groups);
    if i >= params.vertex_count || is_isolated(i) {
        return;
    }
    let keep = 1.0 - params.alpha;
    let spread = 1.0 - params.beta;
    let mb = ring_mean(i);
    let bi = gathered[i].xyz;
    let qi = updated[i].xyz;
    let p = bi + params.alpha * original[i].xyz + keep * qi;
    let proposed = p - (params.beta * bi + spread * mb);
    updated[i] = vec4<f32>(constrain(i, qi, proposed), 0.0);
}
