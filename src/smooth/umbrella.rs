//! Uniform Laplace and Taubin lambda/mu: repeated umbrella steps `q += factor * L(q)`.

use rayon::prelude::*;

use super::constraint::Constrain;
use super::rings::{ring_mean, Rings, CHUNK};
use super::StepObserver;

/// Runs iterations `done + 1 ..= done + more` of the umbrella steps `factors` (Laplace:
/// `[lambda]`; Taubin: `[lambda, mu]`) from `start` (the result of `done` iterations; `None`:
/// `original`, read in place rather than copied), reporting after every step and iteration.
pub(crate) fn run<C: Constrain>(
    rings: Rings,
    original: &[[f32; 3]],
    start: Option<Vec<[f32; 3]>>,
    factors: &[f32],
    (done, more): (u32, u32),
    constraint: &C,
    observer: &mut dyn StepObserver,
) -> Vec<[f32; 3]> {
    if more == 0 || factors.is_empty() {
        return start.unwrap_or_else(|| original.to_vec());
    }
    let n = original.len();
    // The ping-pong pair, allocated once per run. Without a `start`, `q` stays empty until the
    // first step, which reads the original.
    let mut next = vec![[0.0f32; 3]; n];
    let mut q = start.unwrap_or_default();
    for iteration in done + 1..=done + more {
        for &factor in factors {
            let src = if q.len() == n { &q[..] } else { original };
            step(rings, factor, src, &mut next, constraint);
            if q.len() != n {
                q = vec![[0.0f32; 3]; n];
            }
            std::mem::swap(&mut q, &mut next);
            observer.after_step(&q);
        }
        observer.after_iteration(iteration, &q);
    }
    q
}

/// One Jacobi umbrella step: `dst_i = src_i + factor * (mean_{N(i)} src - src_i)`, constrained.
/// Isolated vertices keep their position.
fn step<C: Constrain>(
    rings: Rings,
    factor: f32,
    src: &[[f32; 3]],
    dst: &mut [[f32; 3]],
    constraint: &C,
) {
    assert!(src.len() == rings.vertex_count() && dst.len() == src.len());
    dst.par_chunks_mut(CHUNK)
        .zip(src.par_chunks(CHUNK))
        .enumerate()
        .for_each(|(c, (dst, own))| {
            let rows = dst.iter_mut().zip(own).zip(rings.chunk(c)).enumerate();
            for (k, ((out, &q), ring)) in rows {
                let i = c * CHUNK + k;
                *out = if ring.is_empty() {
                    q
                } else {
                    let m = ring_mean(ring, src);
                    let proposed = std::array::from_fn(|k| q[k] + factor * (m[k] - q[k]));
                    constraint.apply(i, q, proposed)
                };
            }
        });
}
