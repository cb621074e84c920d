//! The paper's local error (section 4.1): each smoothed vertex keeps a reference vertex on the
//! original mesh that drifts with it during smoothing; at the end its distance is measured to the
//! triangle fan around that reference only, by the prism test with an edge fallback.
//!
//! It measures to part of the original mesh, so it is never below the exact distance to it.

use super::exact_distance::{point_segment_distance2, SLIVER_SINE};
use super::Original;
use crate::mesh::{cross, dot, sub, to_f64};
use crate::smooth::StepObserver;
use rayon::prelude::*;

/// One original triangle's prism, precomputed once. The paper solves `(a, b, c) = P^-1 (q - p_r)`
/// with `P = [e1 e2 n]` from the reference corner `r`; `(a, b)` and `1 - a - b` are then the
/// barycentric coordinates of `q`'s projection and `c` its height over the plane, none of which
/// depends on which corner is the origin. So each triangle stores one frame, at its first corner:
/// `a = g1 . (q - origin)`, `b = g2 . (q - origin)`, `c = n . (q - origin)`.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct PrismFrame {
    /// Unit normal, in f64: the height `|c|` is the reported distance.
    normal: [f64; 3],
    /// The first corner, exactly as in the original positions.
    origin: [f32; 3],
    /// Rows of `P^-1` for the in-plane coordinates; f32 suffices to classify inside or outside.
    g1: [f32; 3],
    g2: [f32; 3],
    /// False for degenerate and sliver triangles (`P` is not invertible): only their edges count.
    valid: bool,
}

impl PrismFrame {
    fn new(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> Self {
        let (a64, b64, c64) = (to_f64(a), to_f64(b), to_f64(c));
        let e1 = sub(b64, a64);
        let e2 = sub(c64, a64);
        let m = cross(e1, e2);
        let len = dot(m, m).sqrt();
        let scale = (dot(e1, e1) * dot(e2, e2)).sqrt();
        if !(len > SLIVER_SINE * scale && len.is_finite()) {
            return Self::default();
        }
        let n = [m[0] / len, m[1] / len, m[2] / len];
        // Dual basis of (e1, e2) in the plane: g1 . e1 = 1, g1 . e2 = 0 and so on.
        let g1 = cross(e2, n).map(|x| (x / len) as f32);
        let g2 = cross(n, e1).map(|x| (x / len) as f32);
        let valid = g1.iter().chain(&g2).all(|x| x.is_finite());
        Self {
            normal: n,
            origin: a,
            g1,
            g2,
            valid,
        }
    }

    /// Height of `q` over the triangle's plane when `q` lies in its prism. The height is taken from
    /// the reference corner `pr`, as in the paper, so a vertex sitting on it measures exactly 0.
    #[inline]
    fn height_inside(&self, q: [f64; 3], pr: [f64; 3]) -> Option<f64> {
        if !self.valid {
            return None;
        }
        let d = sub(q, to_f64(self.origin));
        let a = dot(to_f64(self.g1), d);
        let b = dot(to_f64(self.g2), d);
        (a >= 0.0 && b >= 0.0 && a + b <= 1.0).then(|| dot(self.normal, sub(q, pr)).abs())
    }
}

/// Prism frames of every triangle of the original mesh.
pub(crate) fn prism_frames(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<PrismFrame> {
    triangles
        .par_iter()
        .with_min_len(4096)
        .map(|t| {
            PrismFrame::new(
                positions[t[0] as usize],
                positions[t[1] as usize],
                positions[t[2] as usize],
            )
        })
        .collect()
}

/// Local error of a smoothed vertex at `q` whose reference vertex on the original mesh is `r`:
/// the smallest prism height over the triangles around `r`, else the distance to the fan's edges
/// (spokes from `r` and the rim opposite it), which covers its vertices.
#[inline]
pub(crate) fn vertex_local_error(original: &Original, q: [f32; 3], r: usize) -> f64 {
    let q = to_f64(q);
    let topology = original.topology();
    let fan = topology.triangles_of(r);
    let frames = original.frames();
    let positions = &original.mesh().positions;
    let pr = to_f64(positions[r]);
    let mut best = f64::INFINITY;
    for &t in fan {
        if let Some(h) = frames[t as usize].height_inside(q, pr) {
            best = best.min(h);
        }
    }
    if best.is_finite() {
        return best;
    }
    let triangles = &original.mesh().triangles;
    let d = sub(q, pr);
    // The reference vertex itself: all there is for a vertex no triangle uses.
    let mut best2 = dot(d, d);
    for &j in topology.neighbors_of(r) {
        best2 = best2.min(point_segment_distance2(q, pr, to_f64(positions[j as usize])));
    }
    for &t in fan {
        let tri = triangles[t as usize];
        let rim = if tri[0] as usize == r {
            (tri[1], tri[2])
        } else if tri[1] as usize == r {
            (tri[2], tri[0])
        } else {
            (tri[0], tri[1])
        };
        best2 = best2.min(point_segment_distance2(
            q,
            to_f64(positions[rim.0 as usize]),
            to_f64(positions[rim.1 as usize]),
        ));
    }
    best2.sqrt()
}

/// The drifting reference neighbourhood: after every smoothing step, each vertex's reference moves
/// to whichever of the reference and its 1-ring on the original mesh is closest to the vertex's
/// current position (one hop per step). Use it as the smoothing run's [`StepObserver`].
#[derive(Clone, Debug)]
pub struct DriftingReference<'a> {
    original: &'a Original,
    reference: Vec<u32>,
}

impl<'a> DriftingReference<'a> {
    /// Every vertex starts at itself.
    pub fn new(original: &'a Original) -> Self {
        Self {
            original,
            reference: identity(original.mesh().vertex_count()),
        }
    }

    /// Back to the start, for a new smoothing run from the original positions.
    pub fn reset(&mut self) {
        for (i, r) in self.reference.iter_mut().enumerate() {
            *r = i as u32;
        }
    }

    /// One drift step for the positions `positions` (one per vertex of the original mesh).
    pub fn update(&mut self, positions: &[[f32; 3]]) {
        assert_eq!(
            positions.len(),
            self.reference.len(),
            "positions must belong to the original mesh"
        );
        let original = self.original.mesh();
        let topology = self.original.topology();
        self.reference
            .par_iter_mut()
            .zip(positions.par_iter())
            .with_min_len(2048)
            .for_each(|(r, q)| {
                let d2 = |p: [f32; 3]| {
                    let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
                    d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
                };
                // Ties keep the current reference, so a vertex that did not move stays put.
                let mut best = *r;
                let mut best_d2 = d2(original.positions[best as usize]);
                for &j in topology.neighbors_of(*r as usize) {
                    let dj = d2(original.positions[j as usize]);
                    if dj < best_d2 {
                        best = j;
                        best_d2 = dj;
                    }
                }
                *r = best;
            });
    }

    /// The current reference vertex of every vertex.
    pub fn reference(&self) -> &[u32] {
        &self.reference
    }

    pub fn into_reference(self) -> Vec<u32> {
        self.reference
    }
}

impl StepObserver for DriftingReference<'_> {
    fn after_step(&mut self, positions: &[[f32; 3]]) {
        self.update(positions);
    }
}

/// `0, 1, ..., n - 1`: every vertex its own reference (nothing has drifted).
pub fn identity(n: usize) -> Vec<u32> {
    (0..n as u32).collect()
}
