// Uniform Laplace and Taubin: one Jacobi umbrella step `q += factor * L(q)` (factor = lambda or
// mu), from `gathered` into `moved`. Isolated vertices keep their position.

@group(1) @binding(0) var<storage, read> gathered: array<vec4<f32>>;
@group(1) @binding(1) var<storage, read_write> moved: array<vec4<f32>>;

@compute @workgroup_size(WORKGROUP_SIZE)
fn umbrella_step(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let i = vertex_index(id, groups);
    if i >= params.vertex_count {
        return;
    }
    let q = gathered[i].xyz;
    var out = q;
    if !is_isolated(i) {
        let m = ring_mean(i);
        out = constrain(i, q, q + params.factor * (m - q));
    }
    moved[i] = vec4<f32>(out, 0.0);
}
