//! The paper's local error (section 4.1): each smoothed vertex keeps a reference vertex on the
//! original mesh that drifts with it during smoothing ([`super::drift`]); at the end its distance
//! is measured to the triangle fan around that reference only, by the prism test with an edge
//! fallback.
//!
//! It measures to part of the original mesh, so it is never below the exact distance to it.

use super::exact_distance::SLIVER_SINE;
use super::prism_rows::ROW;
use super::Original;
use crate::mesh::{cross32, dot32, sub32};

/// Local errors of the vertices `vertices` whose fan on the original is not empty, in order, to
/// `each(i, e)`; `reference` holds every vertex's reference.
pub(crate) fn local_errors(
    original: &Original,
    positions: &[[f32; 3]],
    reference: &[u32],
    vertices: std::ops::Range<usize>,
    each: impl FnMut(usize, f64),
) {
    #[cfg(target_arch = "x86_64")]
    if super::wide::available() {
        // SAFETY: the processor has the features `vertex_local_error2_wide` is built with.
        let wide = |o: &Original, q, r| unsafe { vertex_local_error2_wide(o, q, r) };
        return local_errors_with(original, positions, reference, vertices, each, wide);
    }
    local_errors_with(
        original,
        positions,
        reference,
        vertices,
        each,
        vertex_local_error2,
    );
}

/// [`local_errors`] with the per-vertex kernel `error2` ([`vertex_local_error2`] or its wide
/// build).
#[inline(always)]
fn local_errors_with(
    original: &Original,
    positions: &[[f32; 3]],
    reference: &[u32],
    vertices: std::ops::Range<usize>,
    mut each: impl FnMut(usize, f64),
    error2: impl Fn(&Original, [f32; 3], usize) -> f32,
) {
    let topology = original.topology();
    // A run of squared errors first, then their roots: the root's latency at the end of every
    // vertex would otherwise hold up the next one. (A vertex no triangle uses gets a number
    // too, the distance to itself, which is dropped.)
    const RUN: usize = 64;
    let mut squared = [0.0f32; RUN];
    let mut start = vertices.start;
    while start < vertices.end {
        let run = start..(start + RUN).min(vertices.end);
        for (i, s) in run.clone().zip(&mut squared) {
            *s = error2(original, positions[i], reference[i] as usize);
        }
        for (i, &s) in run.clone().zip(&squared) {
            if !topology.triangles_of(i).is_empty() {
                each(i, f64::from(s.sqrt()));
            }
        }
        start = run.end;
    }
}

/// Local error of a smoothed vertex at `q` whose reference vertex on the original mesh is `r`
/// (see [`vertex_local_error2`]).
pub(crate) fn vertex_local_error(original: &Original, q: [f32; 3], r: usize) -> f64 {
    f64::from(vertex_local_error2(original, q, r).sqrt())
}

/// The square of the local error of a smoothed vertex at `q` whose reference vertex on the
/// original mesh is `r`: the smallest prism height over the triangles around `r`, else the
/// distance to the fan's edges (spokes from `r` and the rim opposite it), which cover its
/// vertices.
///
/// All in f32 on edges taken from `r`, so the rounding is a few ulps of the distances
/// themselves, far below that of the f32 positions at their coordinates. A fan with a rim row
/// is one fixed loop of [`ROW`] pairs, which the processor runs as vectors.
// A call per vertex: inlined into the loop over the vertices, the same code ran half as fast.
#[inline(never)]
fn vertex_local_error2(original: &Original, q: [f32; 3], r: usize) -> f32 {
    vertex_local_error2_kernel(original, q, r)
}

/// [`vertex_local_error2`] on AVX-512 (see [`super::wide`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq,avx2,fma")]
#[inline(never)]
fn vertex_local_error2_wide(original: &Original, q: [f32; 3], r: usize) -> f32 {
    vertex_local_error2_kernel(original, q, r)
}

/// The body of [`vertex_local_error2`], for its builds.
#[inline(always)]
fn vertex_local_error2_kernel(original: &Original, q: [f32; 3], r: usize) -> f32 {
    let positions = &original.mesh().positions;
    let pr = positions[r];
    let d = sub32(q, pr);
    let Some(row) = original.prism_row(r) else {
        return fan_local_error2(original, r, d);
    };
    // Coordinate by coordinate, slot by slot: the first edges, and the second (the next slot's).
    // Plain loops over the fixed row rather than `array::from_fn`, whose closures the compiler
    // leaves as calls once the kernel has two builds.
    let mut e1 = [[0.0f32; ROW]; 3];
    for (t, &j) in row.iter().enumerate() {
        let p = positions[j as usize];
        for c in 0..3 {
            e1[c][t] = p[c] - pr[c];
        }
    }
    let mut e2 = [[0.0f32; ROW]; 3];
    for c in 0..3 {
        for t in 0..ROW {
            e2[c][t] = e1[c][(t + 1) % ROW];
        }
    }
    let lane = |e: &[[f32; ROW]; 3], t: usize| [e[0][t], e[1][t], e[2][t]];
    let mut height2 = [0.0f32; ROW];
    for (t, h) in height2.iter_mut().enumerate() {
        *h = prism_height2(lane(&e1, t), lane(&e2, t), d);
    }
    let mut best2 = smallest(height2);
    if !best2.is_finite() {
        // In no prism. Pads name `r` itself, so their segments are spokes or the point `r`.
        let mut edge2 = [0.0f32; ROW];
        for (t, e) in edge2.iter_mut().enumerate() {
            let (a, b) = (lane(&e1, t), lane(&e2, t));
            *e = min(
                segment_distance2([0.0; 3], a, d),
                segment_distance2(a, b, d),
            );
        }
        best2 = min(smallest(edge2), dot32(d, d));
    }
    best2
}

/// [`vertex_local_error2`] for a fan without a rim row, from its lists of corners and
/// neighbours.
#[cold]
fn fan_local_error2(original: &Original, r: usize, d: [f32; 3]) -> f32 {
    let positions = &original.mesh().positions;
    let pr = positions[r];
    let edge = |j: u32| sub32(positions[j as usize], pr);
    let fan = original.fan_corners(r);
    let mut best2 = fan
        .iter()
        .map(|&[j, k]| prism_height2(edge(j), edge(k), d))
        .fold(f32::INFINITY, f32::min);
    if !best2.is_finite() {
        best2 = dot32(d, d);
        for &j in original.topology().neighbors_of(r) {
            best2 = best2.min(segment_distance2([0.0; 3], edge(j), d));
        }
        for &[j, k] in fan {
            best2 = best2.min(segment_distance2(edge(j), edge(k), d));
        }
    }
    best2
}

/// The smallest of `values`, which hold no NaN, by halves (a short chain of the processor's
/// minimum instruction; `f32::min` must also look for NaNs).
#[inline(always)]
fn smallest(values: [f32; ROW]) -> f32 {
    const { assert!(ROW == 8, "halves of four") };
    let half: [f32; 4] = std::array::from_fn(|k| min(values[k], values[k + 4]));
    min(min(half[0], half[2]), min(half[1], half[3]))
}

/// `a` or `b`, whichever is smaller, for values that hold no NaN.
#[inline(always)]
fn min(a: f32, b: f32) -> f32 {
    if b < a {
        b
    } else {
        a
    }
}

/// The squared distance from `p` to the segment from `a` to `b` (a point if they meet).
#[inline(always)]
fn segment_distance2(a: [f32; 3], b: [f32; 3], p: [f32; 3]) -> f32 {
    let ab = sub32(b, a);
    let ap = sub32(p, a);
    let length2 = dot32(ab, ab);
    // Written so that a NaN (a segment of length 0) comes out as 0.
    let along = dot32(ap, ab) / length2;
    let along = if along > 0.0 { along } else { 0.0 };
    let along = if along < 1.0 { along } else { 1.0 };
    let x = [
        ap[0] - along * ab[0],
        ap[1] - along * ab[1],
        ap[2] - along * ab[2],
    ];
    dot32(x, x)
}

/// The paper's prism test, `(a, b, c) = P^-1 d` with `P = [e1 e2 n]`, `e1`, `e2` the triangle's
/// edges from the reference vertex and `d = q - p_r`. By Cramer's rule with `m = e1 x e2`
/// (`n = m / |m|`): `a = (d x e2).m / |m|^2`, `b = (e1 x d).m / |m|^2`, `c = d.m / |m|`, so the
/// inside test needs no division. Returns `c^2` when `a, b >= 0` and `a + b <= 1`, else
/// infinity. A degenerate or sliver triangle (`P` not safely invertible) has no prism; its edges
/// still count. Selects rather than branches, so a row of pairs runs as vectors.
#[inline(always)]
fn prism_height2(e1: [f32; 3], e2: [f32; 3], d: [f32; 3]) -> f32 {
    let m = cross32(e1, e2);
    let m2 = dot32(m, m);
    let a = dot32(cross32(d, e2), m);
    let b = dot32(cross32(e1, d), m);
    let inside = (a >= 0.0) & (b >= 0.0) & (a + b <= m2);
    const SLIVER2: f32 = (SLIVER_SINE * SLIVER_SINE) as f32;
    let solid = m2 > SLIVER2 * dot32(e1, e1) * dot32(e2, e2);
    let c = dot32(d, m);
    let h2 = c * (c / m2);
    if inside & solid {
        h2
    } else {
        f32::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::fixtures::{double_cone, grid, tetrahedron};
    use crate::mesh::Topology;

    /// Points near and far from `p`: inside some prisms, and in none.
    fn around(p: [f32; 3]) -> impl Iterator<Item = [f32; 3]> {
        let offsets = [
            [0.0, 0.0, 0.0],
            [0.05, 0.02, 0.3],
            [0.2, -0.1, -0.25],
            [-0.3, 0.35, 0.1],
            [0.6, 0.1, -0.05],
            [2.0, 1.0, 0.5],
            [-1.5, 0.2, -2.0],
            [0.0, 0.0, 3.0],
        ];
        offsets
            .into_iter()
            .map(move |o| [p[0] + o[0], p[1] + o[1], p[2] + o[2]])
    }

    #[test]
    fn rim_rows_measure_what_the_lists_of_corners_do() {
        for (mesh, rowless) in [(tetrahedron(), 0), (grid(5, 4), 0), (double_cone(10), 3)] {
            let topology = Topology::build(&mesh);
            let original = Original::new(&mesh, &topology);
            let mut without = 0;
            for (r, &p) in mesh.positions.iter().enumerate() {
                if original.prism_row(r).is_none() {
                    without += 1;
                    continue;
                }
                for q in around(p) {
                    let by_row = vertex_local_error(&original, q, r);
                    let by_list = f64::from(fan_local_error2(&original, r, sub32(q, p)).sqrt());
                    // Prism heights are the same numbers; an edge may be walked the other way.
                    assert!(
                        (by_row - by_list).abs() <= 1e-6 * by_list.max(1.0),
                        "vertex {r} at {q:?}: {by_row} by its row, {by_list} by its list"
                    );
                }
            }
            assert_eq!(without, rowless, "vertices read from their list of corners");
        }
    }

    #[test]
    fn the_error_is_the_distance_to_the_nearest_part_of_the_fan() {
        // The tetrahedron's corner 0 at the origin; its fan: the faces x = 0, y = 0 and z = 0.
        let mesh = tetrahedron();
        let topology = Topology::build(&mesh);
        let original = Original::new(&mesh, &topology);
        // Over all three faces (inside each prism): the height over the nearest, x = 0.
        let e = vertex_local_error(&original, [0.2, 0.3, 0.25], 0);
        assert!((e - 0.2).abs() < 1e-7, "{e}");
        // Off every prism, beyond corner 1: the distance to corner 1, the fan's nearest point.
        let e = vertex_local_error(&original, [2.0, -0.5, -0.5], 0);
        assert!((e - 1.5f64.sqrt()).abs() < 1e-7, "{e}");
    }
}
