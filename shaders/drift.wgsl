// The drifting reference (ALGORITHMS.md, local error step 1) as metrics::DriftingReference
// computes it: after every smoothing step each vertex's reference r_i moves to whichever of r_i
// and its 1-ring on the original mesh is closest to q_i, ties keeping the earlier candidate
// (r_i first, then the ring in ascending order). Squared distances in f32, summed in the CPU's
// order, so only candidates whose distances differ by rounding can be chosen differently.

@group(0) @binding(1) var<storage, read> original: array<vec4<f32>>;
// The full 1-ring of the original mesh as CSR (not the boundary-restricted smoothing ring).
@group(0) @binding(2) var<storage, read> ring_offsets: array<u32>;
@group(0) @binding(3) var<storage, read> ring: array<u32>;
// Per vertex, (0.49 * shortest edge)^2: a point that close is nearer to it than to any neighbour.
@group(0) @binding(4) var<storage, read> stay_radius2: array<f32>;
@group(0) @binding(5) var<storage, read_write> reference: array<u32>;

fn distance2(q: vec3<f32>, p: vec3<f32>) -> f32 {
    let d = q - p;
    return d.x * d.x + d.y * d.y + d.z * d.z;
}

// Every vertex its own reference: the start of a run.
@compute @workgroup_size(WORKGROUP_SIZE)
fn reference_reset(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let i = vertex_index(id, groups);
    if i < surface.vertex_count {
        reference[i] = i;
    }
}

// One drift step towards `positions` (the step's result). Each vertex reads and writes only its
// own reference, so the update is in place.
@compute @workgroup_size(WORKGROUP_SIZE)
fn reference_drift(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let i = vertex_index(id, groups);
    if i >= surface.vertex_count {
        return;
    }
    let q = positions[i].xyz;
    let r = reference[i];
    var best = r;
    var best_d2 = distance2(q, original[r].xyz);
    if best_d2 <= stay_radius2[r] {
        return;
    }
    let end = ring_offsets[r + 1u];
    for (var k = ring_offsets[r]; k < end; k++) {
        let j = ring[k];
        let dj = distance2(q, original[j].xyz);
        if dj < best_d2 {
            best = j;
            best_d2 = dj;
        }
    }
    reference[i] = best;
}
