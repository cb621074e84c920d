//! Windowed sinc (Taubin 1996) as VTK's vtkWindowedSincPolyDataFilter computes it: the filtered
//! positions are `f(K) x` with `f` the Chebyshev series of `sinc_coefficients`, evaluated by the
//! three-term recurrence
//!
//! `T_0 x = x`, `T_1 x = (x + mean_N x) / 2`, `T_{k+1} x = T_k x + mean_N(T_k x) - T_{k-1} x`
//!
//! (from `T_{k+1} = 2 (I + L/2) T_k - T_{k-1}`), accumulating `c_k T_k x` term by term.
//!
//! Coordinates are normalised first, as VTK's NormalizeCoordinates does: moved so the bounding
//! box's centre is the origin and scaled to the unit cube, then mapped back. The scale cancels
//! exactly in a linear filter, so only the centring is done; it matters because the series'
//! gain at frequency 0 is 1 only to within 1e-3, and it keeps f32 precision where the mesh lies
//! far from the origin. The accumulated sum is kept in the original coordinates
//! (`centre + sum c_k T_k (x - centre)`), so it is the running estimate as it stands.
//!
//! Weights and the displacement bound act on the final estimate, never inside the recurrence
//! (which must see the unconstrained `T_k x` to stay a polynomial in `L`): the result is
//! `o_i + w_i (estimate_i - o_i)`, pulled back onto the ball of radius `d_max` around `o_i`.
//!
//! The running sums between terms are not meshes (the first is roughly the mesh scaled by 0.3
//! about its centre), so observers are not shown them: a reference drifting along them walks
//! far away and may not find its way back. Observers see the result once per degree instead,
//! so the drifting reference of the local error takes as many hops towards it as the filter
//! has steps.

use rayon::prelude::*;

use super::constraint::Constrain;
use super::rings::{xyz0, Field, KernelRings, CHUNK};
use super::sinc_coefficients::sinc_coefficients;
use super::{follow_parts, StepObserver};
use crate::mesh::bounding_box;

/// Runs the windowed-sinc filter of degree `iterations` (one neighbour pass per degree).
/// Reports the result `iterations` times as a step and once as iteration `iterations`.
pub(crate) fn run<C: Constrain>(
    rings: KernelRings,
    original: &[[f32; 3]],
    passband: f32,
    iterations: u32,
    constraint: &C,
    observer: &mut dyn StepObserver,
) -> Vec<[f32; 3]> {
    let Some(mut terms) = ChebyshevSeries::start(rings, original, passband, iterations) else {
        return original.to_vec();
    };
    while !terms.advance(rings, u32::MAX) {}
    let result = terms.finish(original, constraint);
    let watching = observer.watches_iteration(iterations);
    for _ in 0..iterations {
        follow_points(observer, &result);
        if watching {
            observer.after_step(&result);
        }
    }
    if watching {
        observer.after_iteration(iterations, &result);
    }
    result
}

/// Hands `positions` to the observer's follower, if it has one, for a step no pass of which
/// could take them in.
fn follow_points(observer: &mut dyn StepObserver, positions: &[[f32; 3]]) {
    let parts = follow_parts(observer, positions.len());
    if parts.iter().all(Option::is_none) {
        return;
    }
    parts
        .into_par_iter()
        .zip(positions.par_chunks(CHUNK))
        .for_each(|(part, points)| {
            if let Some(mut follow) = part {
                let mut lanes = [[0.0f32; 4]; CHUNK];
                for (l, &p) in lanes.iter_mut().zip(points) {
                    *l = xyz0(p);
                }
                follow(&lanes[..points.len()]);
            }
        });
}

/// The recurrence under way: the terms so far summed into the estimate. Advancing it a few
/// terms at a time gives the same result, bit for bit, as running it through.
pub(crate) struct ChebyshevSeries {
    /// The series' coefficients, `c_0 ..= c_iterations`.
    c: Vec<f32>,
    /// The highest term summed so far.
    k: usize,
    /// T_{k-1} x and T_k x (centred), and the estimate; allocated once for the whole run.
    previous: Field,
    current: Field,
    estimate: Vec<[f32; 3]>,
}

impl ChebyshevSeries {
    /// The first two terms; `None` when nothing moves (no iterations, or no vertices).
    pub(crate) fn start(
        rings: KernelRings,
        original: &[[f32; 3]],
        passband: f32,
        iterations: u32,
    ) -> Option<Self> {
        let n = original.len();
        let (lo, hi) = bounding_box(original).filter(|_| iterations > 0)?;
        assert!(n == rings.vertex_count());
        let centre: [f32; 3] =
            std::array::from_fn(|k| ((lo[k] as f64 + hi[k] as f64) * 0.5) as f32);
        let c: Vec<f32> = sinc_coefficients(iterations, passband)
            .into_iter()
            .map(|x| x as f32)
            .collect();
        let mut t = Self {
            k: 1,
            previous: Field::from_points_about(original, centre),
            current: Field::zeros(n),
            estimate: vec![[0.0f32; 3]; n],
            c,
        };
        first_term(
            rings,
            original,
            centre,
            [t.c[0], t.c[1]],
            &t.previous,
            &mut t.current,
            &mut t.estimate,
        );
        Some(t)
    }

    /// Sums up to `more` further terms; returns whether every term is summed.
    pub(crate) fn advance(&mut self, rings: KernelRings, more: u32) -> bool {
        let last = self.c.len() - 1;
        let end = last.min(self.k.saturating_add(more as usize));
        while self.k < end {
            self.k += 1;
            // `previous` becomes T_{k+1} x in place, then the pair swaps roles.
            next_term(
                rings,
                self.c[self.k],
                &self.current,
                &mut self.previous,
                &mut self.estimate,
            );
            std::mem::swap(&mut self.previous, &mut self.current);
        }
        self.k == last
    }

    /// The estimate through the weights and the bound, once every term is summed.
    pub(crate) fn finish<C: Constrain>(
        self,
        original: &[[f32; 3]],
        constraint: &C,
    ) -> Vec<[f32; 3]> {
        constrain(original, self.estimate, constraint)
    }
}

/// From `z0 = x - centre`: `current = T_1 z0`, `estimate = centre + c0 z0 + c1 T_1 z0`.
/// Isolated vertices stay at `original`.
fn first_term(
    rings: KernelRings,
    original: &[[f32; 3]],
    centre: [f32; 3],
    [c0, c1]: [f32; 2],
    z0: &Field,
    current: &mut Field,
    estimate: &mut [[f32; 3]],
) {
    current
        .vertices_mut()
        .par_chunks_mut(CHUNK)
        .zip(estimate.par_chunks_mut(CHUNK))
        .zip(
            z0.vertices()
                .par_chunks(CHUNK)
                .zip(original.par_chunks(CHUNK)),
        )
        .enumerate()
        .for_each(|(c, ((t1, e), (own, orig)))| {
            let rows = t1.iter_mut().zip(e.iter_mut()).zip(own.iter().zip(orig));
            for (((t1, e), (&z, &o)), ring) in rows.zip(rings.chunk(c, z0)) {
                if ring.is_empty() {
                    *t1 = z;
                    *e = o;
                    continue;
                }
                let m = rings.mean(ring);
                *t1 = std::array::from_fn(|k| 0.5 * (z[k] + m[k]));
                *e = std::array::from_fn(|k| centre[k] + c0 * z[k] + c1 * t1[k]);
            }
        });
}

/// Overwrites `previous` (T_{k-1} x) with T_{k+1} x and adds `ck` times it to the estimate.
fn next_term(
    rings: KernelRings,
    ck: f32,
    current: &Field,
    previous: &mut Field,
    estimate: &mut [[f32; 3]],
) {
    previous
        .vertices_mut()
        .par_chunks_mut(CHUNK)
        .zip(estimate.par_chunks_mut(CHUNK))
        .zip(current.vertices().par_chunks(CHUNK))
        .enumerate()
        .for_each(|(c, ((t, e), own))| {
            let rows = t
                .iter_mut()
                .zip(e.iter_mut())
                .zip(own)
                .zip(rings.chunk(c, current));
            for (((t, e), &tk), ring) in rows {
                if ring.is_empty() {
                    // L = 0 there: every T_k x equals x, and the estimate stays the original.
                    *t = tk;
                    continue;
                }
                let m = rings.mean(ring);
                for k in 0..4 {
                    t[k] = tk[k] + m[k] - t[k];
                }
                for k in 0..3 {
                    e[k] += ck * t[k];
                }
            }
        });
}

/// The estimate through the weights and the bound, when there are any.
fn constrain<C: Constrain>(
    original: &[[f32; 3]],
    mut estimate: Vec<[f32; 3]>,
    constraint: &C,
) -> Vec<[f32; 3]> {
    if C::IS_FREE {
        return estimate;
    }
    estimate
        .par_chunks_mut(CHUNK)
        .zip(original.par_chunks(CHUNK))
        .enumerate()
        .for_each(|(c, (est, orig))| {
            for (k, (e, &o)) in est.iter_mut().zip(orig).enumerate() {
                *e = constraint.apply(c * CHUNK + k, o, *e);
            }
        });
    estimate
}
