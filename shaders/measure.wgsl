// One measure pass over a smoothed mesh as metrics::measure_vertices computes it, per vertex:
//   - discrete Gaussian curvature (Meyer et al. 2003) over the vertex's fan at `positions`:
//     K_G = (2 pi - sum of angles) / A_mixed, left out (0) on the boundary, without area or
//     where it is not finite;
//   - the local error (paper section 4.1) of q_i against the fan of its reference r_i on the
//     original mesh: the smallest prism height, else the distance to the fan's edges;
//   - its share of six times the volume: the triangles whose smallest corner index it is;
//   - its roughness term n |mean - p|^2 over the corner after it in each of its n triangles
//     (metrics::roughness: on a closed mesh, its 1-ring).
// Each workgroup then sums its vertices into one `Partial`; the host adds those in f64.
//
// f32 throughout. Angles avoid atan2 (WGSL allows it 4096 ULP) and are summed exactly in
// fixed point, so the angle defect of a nearly flat vertex is not lost to the rounding of a sum
// near 2 pi: what remains is the f32 rounding of the edge vectors' products.

@group(0) @binding(1) var<storage, read> original: array<vec4<f32>>;
// The vertex -> triangle CSR, and for each entry the triangle's other two corners in winding order.
@group(0) @binding(2) var<storage, read> fan_offsets: array<u32>;
@group(0) @binding(3) var<storage, read> fan_corners: array<vec2<u32>>;
// 1 for vertices on a boundary edge.
@group(0) @binding(4) var<storage, read> boundary: array<u32>;
@group(0) @binding(5) var<storage, read> reference: array<u32>;
// Per vertex: (local error, K_G); (0, 0) for vertices no triangle uses.
@group(0) @binding(6) var<storage, read_write> vertex_measures: array<vec2<f32>>;
// One per workgroup, at its linear index.
@group(0) @binding(7) var<storage, read_write> partials: array<Partial>;
// The workgroups this dispatch covers: the pass runs as 1-D parts, each its own dispatch.
@group(0) @binding(8) var<uniform> part: MeasurePart;

// Mirrors `MeasurePart` in src/gpu/layout.rs (16 bytes).
struct MeasurePart {
    first_group: u32,
    group_count: u32,
    pad0: u32,
    pad1: u32,
}

// Mirrors `MeasurePartial` in src/gpu/layout.rs (32 bytes).
struct Partial {
    error_sum: f32,
    error_max: f32,
    curvature_sum: f32,
    // Six times the volume, about the centre.
    volume6: f32,
    error_count: u32,
    curvature_count: u32,
    roughness: f32,
    pad: u32,
}

// Angles in units of 2^-26 rad: pi is 2.1e8 units, so a u32 holds 20 angles of pi before it
// wraps (counted as carries).
const ANGLE_UNITS_PER_RAD: f32 = 67108864.0;
const PI_UNITS: i32 = 210828714;
const HALF_PI_UNITS: i32 = 105414357;
const QUARTER_PI_UNITS: i32 = 52707179;
// 2 pi = (TWO_PI_UNITS + TWO_PI_FRACTION) units.
const TWO_PI_UNITS: i32 = 421657428;
const TWO_PI_FRACTION: f32 = 0.26631308;
const TWO_PI: f32 = 6.2831855;
// tan(pi / 8): above it atan(t) = pi/4 + atan((t - 1) / (t + 1)).
const TAN_EIGHTH_PI: f32 = 0.41421357;
// metrics::curvature's NEGLIGIBLE_ANGLE and metrics::exact_distance's SLIVER_SINE squared.
const NEGLIGIBLE_ANGLE: f32 = 1e-12;
const SLIVER_SINE2: f32 = 1e-16;
// The largest f32, written exactly (a decimal literal rounds past it, which Tint refuses).
const F32_MAX: f32 = 0x1.fffffep+127f;

// atan(s) for |s| <= tan(pi/8), by its Taylor series to s^19: the first term left out is below
// 5e-10 there, under half an f32 ulp of the result.
fn atan_small(s: f32) -> f32 {
    let z = s * s;
    var p = -1.0 / 19.0;
    p = 1.0 / 17.0 + z * p;
    p = -1.0 / 15.0 + z * p;
    p = 1.0 / 13.0 + z * p;
    p = -1.0 / 11.0 + z * p;
    p = 1.0 / 9.0 + z * p;
    p = -1.0 / 7.0 + z * p;
    p = 1.0 / 5.0 + z * p;
    p = -1.0 / 3.0 + z * p;
    return s + s * (z * p);
}

fn to_units(radians: f32) -> i32 {
    return i32(round(radians * ANGLE_UNITS_PER_RAD));
}

// atan(t) in units for t in [0, 1].
fn atan_unit_interval(t: f32) -> i32 {
    if t <= TAN_EIGHTH_PI {
        return to_units(atan_small(t));
    }
    return QUARTER_PI_UNITS + to_units(atan_small((t - 1.0) / (t + 1.0)));
}

// atan2(y, x) in units, y >= 0 (an angle in [0, pi]); as metrics::curvature's AngleSum takes
// it, angles within 1e-12 of 0 or pi count as exactly 0 or pi.
fn angle_units(x: f32, y: f32) -> i32 {
    let ax = abs(x);
    if !(y > NEGLIGIBLE_ANGLE * ax) {
        return select(0, PI_UNITS, x < 0.0);
    }
    var a: i32;
    if ax >= y {
        a = atan_unit_interval(y / ax);
    } else {
        a = HALF_PI_UNITS - atan_unit_interval(ax / y);
    }
    return select(a, PI_UNITS - a, x < 0.0);
}

// 2 pi minus an angle sum of `carries` * 2^32 + `units` units.
fn angle_defect(units: u32, carries: u32) -> f32 {
    if carries == 0u && units < 0x80000000u {
        // Exact in integers; the only rounding is the conversion (none below 0.25 rad).
        let d = TWO_PI_UNITS - i32(units);
        return (f32(d) + TWO_PI_FRACTION) / ANGLE_UNITS_PER_RAD;
    }
    // A fan folded over itself (sums past 32 rad): the defect is large, f32 is enough.
    return TWO_PI - (f32(carries) * 4294967296.0 + f32(units)) / ANGLE_UNITS_PER_RAD;
}

// Squared distance from the point at `d` (relative to a) to the segment from a to a + e.
fn segment_distance2(d: vec3<f32>, e: vec3<f32>) -> f32 {
    let len2 = dot(e, e);
    var t = 0.0;
    if len2 > 0.0 {
        t = clamp(dot(d, e) / len2, 0.0, 1.0);
    }
    let r = d - t * e;
    return dot(r, r);
}

// The prism height of the point at `d` (relative to the reference vertex) over the triangle
// with edges e1, e2 from it, or -1 when the point is outside the prism or the triangle is a
// sliver (as metrics::local_error's prism_height).
fn prism_height(e1: vec3<f32>, e2: vec3<f32>, d: vec3<f32>) -> f32 {
    let m = cross(e1, e2);
    let m2 = dot(m, m);
    let a = dot(cross(d, e2), m);
    let b = dot(cross(e1, d), m);
    let inside = a >= 0.0 && b >= 0.0 && a + b <= m2;
    if inside && m2 > SLIVER_SINE2 * dot(e1, e1) * dot(e2, e2) {
        return abs(dot(d, m)) / sqrt(m2);
    }
    return -1.0;
}

// Local error of q (vertex i's position) against the fan of its reference r on the original.
fn local_error(q: vec3<f32>, r: u32) -> f32 {
    let pr = original[r].xyz;
    let d = q - pr;
    let start = fan_offsets[r];
    let end = fan_offsets[r + 1u];
    var best = F32_MAX;
    var found = false;
    for (var k = start; k < end; k++) {
        let c = fan_corners[k];
        let h = prism_height(original[c.x].xyz - pr, original[c.y].xyz - pr, d);
        if h >= 0.0 {
            best = min(best, h);
            found = true;
        }
    }
    if found {
        return best;
    }
    // The fan's edges: the spokes from r (its 1-ring) and the rims; r itself to start with.
    var best2 = dot(d, d);
    for (var k = start; k < end; k++) {
        let c = fan_corners[k];
        let pj = original[c.x].xyz;
        let pk = original[c.y].xyz;
        best2 = min(best2, segment_distance2(d, pj - pr));
        best2 = min(best2, segment_distance2(d, pk - pr));
        best2 = min(best2, segment_distance2(q - pj, pk - pj));
    }
    return sqrt(best2);
}

fn empty_partial() -> Partial {
    return Partial(0.0, 0.0, 0.0, 0.0, 0u, 0u, 0.0, 0u);
}

// Vertex i's measures: writes its per-vertex entry and returns its share of the sums.
fn measure_vertex(i: u32) -> Partial {
    var s = empty_partial();
    let start = fan_offsets[i];
    let end = fan_offsets[i + 1u];
    if start == end {
        vertex_measures[i] = vec2<f32>(0.0);
        return s;
    }
    let p = positions[i].xyz;
    let centred = p - surface.centre.xyz;
    var units = 0u;
    var carries = 0u;
    var mixed_area = 0.0;
    var ring_sum = vec3<f32>(0.0);
    for (var n = start; n < end; n++) {
        let c = fan_corners[n];
        let pj = positions[c.x].xyz;
        let pk = positions[c.y].xyz;
        ring_sum += pj;
        let u = pj - p;
        let v = pk - p;
        // The third edge straight from the positions, not as v - u: the products below then
        // stay accurate for needles (a tiny edge opposite i), where the CPU's f64 still is.
        let w = pk - pj;
        let m = triangle_normal(u, v, w);
        let twice = sqrt(dot(m, m));
        // Dot products of the two edges leaving each corner (negative: obtuse there).
        let uu = dot(u, u);
        let vv = dot(v, v);
        let dot_i = dot(u, v);
        let dot_j = -dot(u, w);
        let dot_k = dot(v, w);
        let sum = units + u32(angle_units(dot_i, twice));
        carries += select(0u, 1u, sum < units);
        units = sum;
        var voronoi = 0.0;
        if twice > 0.0 {
            voronoi = (uu * dot_k + vv * dot_j) / (8.0 * twice);
        }
        let obtuse_i = dot_i < 0.0;
        let obtuse = obtuse_i || dot_j < 0.0 || dot_k < 0.0;
        let half_area = 0.5 * twice;
        mixed_area += select(voronoi, select(0.25 * half_area, 0.5 * half_area, obtuse_i), obtuse);
        // Each triangle's volume term once: at its smallest corner.
        if i < c.x && i < c.y {
            s.volume6 += dot(centred, m);
        }
    }
    let count = f32(end - start);
    let umbrella = ring_sum * (1.0 / count) - p;
    s.roughness = count * dot(umbrella, umbrella);
    var k_g = 0.0;
    if boundary[i] == 0u && mixed_area > 0.0 {
        let k = angle_defect(units, carries) / mixed_area;
        if abs(k) <= F32_MAX {
            k_g = k;
            s.curvature_sum = abs(k);
            s.curvature_count = 1u;
        }
    }
    let e = local_error(p, reference[i]);
    s.error_sum = e;
    s.error_max = e;
    s.error_count = 1u;
    vertex_measures[i] = vec2<f32>(e, k_g);
    return s;
}

var<workgroup> shared_partials: array<Partial, WORKGROUP_SIZE>;

fn combine(a: Partial, b: Partial) -> Partial {
    return Partial(
        a.error_sum + b.error_sum,
        max(a.error_max, b.error_max),
        a.curvature_sum + b.curvature_sum,
        a.volume6 + b.volume6,
        a.error_count + b.error_count,
        a.curvature_count + b.curvature_count,
        a.roughness + b.roughness,
        0u,
    );
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn measure_vertices(
    @builtin(local_invocation_index) lane: u32,
    @builtin(workgroup_id) local_group: vec3<u32>,
) {
    let group = part.first_group + local_group.x;
    let i = group * WORKGROUP_SIZE + lane;
    var s = empty_partial();
    if i < surface.vertex_count {
        s = measure_vertex(i);
    }
    shared_partials[lane] = s;
    workgroupBarrier();
    // Pairwise (tree) sums: log2(64) roundings deep instead of 63.
    for (var width = WORKGROUP_SIZE / 2u; width > 0u; width /= 2u) {
        if lane < width {
            shared_partials[lane] = combine(shared_partials[lane], shared_partials[lane + width]);
        }
        workgroupBarrier();
    }
    if lane == 0u {
        partials[group] = shared_partials[0];
    }
}
