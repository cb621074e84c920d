//! Laplace+HC after Vollmer, Mencl and Mueller (1999), one iteration in two Jacobi passes:
//!
//! 1. `p_i = mean_{N(i)} q`, `b_i = p_i - (alpha o_i + (1 - alpha) q_i)`
//! 2. `q_i <- p_i - (beta b_i + (1 - beta) mean_{N(i)} b)`
//!
//! Pass 2 rebuilds `p_i` as `b_i + alpha o_i + (1 - alpha) q_i` instead of storing it, which
//! saves a buffer and its traffic; and since it reads `q` only at the vertex it writes, it
//! updates `q` in place.

use rayon::prelude::*;

use super::constraint::Constrain;
use super::rings::{ring_mean, Rings, CHUNK};
use super::StepObserver;

/// Runs HC iterations `done + 1 ..= done + more` from `start` (the original positions, or the
/// result of `done` iterations); one step (and report) per iteration.
#[allow(clippy::too_many_arguments)]
pub(crate) fn run<C: Constrain>(
    rings: Rings,
    original: &[[f32; 3]],
    start: Vec<[f32; 3]>,
    alpha: f32,
    beta: f32,
    (done, more): (u32, u32),
    constraint: &C,
    observer: &mut dyn StepObserver,
) -> Vec<[f32; 3]> {
    let mut q = start;
    if more == 0 {
        return q;
    }
    let n = q.len();
    assert!(n == rings.vertex_count());
    let mut b = vec![[0.0f32; 3]; n];
    for iteration in done + 1..=done + more {
        differences(rings, original, &q, &mut b, alpha);
        correct(rings, original, &b, &mut q, alpha, beta, constraint);
        observer.after_step(&q);
        observer.after_iteration(iteration, &q);
    }
    q
}

/// Pass 1: `b_i = mean_{N(i)} q - (alpha o_i + (1 - alpha) q_i)`; 0 for isolated vertices
/// (no ring reads them).
fn differences(
    rings: Rings,
    original: &[[f32; 3]],
    q: &[[f32; 3]],
    b: &mut [[f32; 3]],
    alpha: f32,
) {
    let keep = 1.0 - alpha;
    b.par_chunks_mut(CHUNK)
        .zip(q.par_chunks(CHUNK).zip(original.par_chunks(CHUNK)))
        .enumerate()
        .for_each(|(c, (b, (own, orig)))| {
            let rows = b.iter_mut().zip(own.iter().zip(orig)).zip(rings.chunk(c));
            for ((bi, (&qi, &oi)), ring) in rows {
                *bi = if ring.is_empty() {
                    [0.0; 3]
                } else {
                    let p = ring_mean(ring, q);
                    std::array::from_fn(|k| p[k] - (alpha * oi[k] + keep * qi[k]))
                };
            }
        });
}

/// Pass 2: `q_i <- p_i - (beta b_i + (1 - beta) mean_{N(i)} b)`, constrained, in place.
fn correct<C: Constrain>(
    rings: Rings,
    original: &[[f32; 3]],
    b: &[[f32; 3]],
    q: &mut [[f32; 3]],
    alpha: f32,
    beta: f32,
    constraint: &C,
) {
    let keep = 1.0 - alpha;
    let spread = 1.0 - beta;
    q.par_chunks_mut(CHUNK)
        .zip(b.par_chunks(CHUNK).zip(original.par_chunks(CHUNK)))
        .enumerate()
        .for_each(|(c, (q, (own_b, orig)))| {
            let rows = q.iter_mut().zip(own_b.iter().zip(orig)).zip(rings.chunk(c));
            for (k, ((qi, (&bi, &oi)), ring)) in rows.enumerate() {
                let i = c * CHUNK + k;
                if ring.is_empty() {
                    continue;
                }
                let mb = ring_mean(ring, b);
                let proposed = std::array::from_fn(|k| {
                    let p = bi[k] + alpha * oi[k] + keep * qi[k];
                    p - (beta * bi[k] + spread * mb[k])
                });
                *qi = constraint.apply(i, *qi, proposed);
            }
        });
}
