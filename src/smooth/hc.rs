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
use super::rings::{xyz, xyz0, Field, Rings, CHUNK};
use super::{follow_parts, FollowPart, StepObserver};

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
    if more == 0 {
        return start;
    }
    let n = start.len();
    assert!(n == rings.vertex_count() && original.len() == n);
    let mut q = Field::from_points(&start);
    // `points` receives the 3-vectors the observer and the caller see.
    let mut points = start;
    let mut b = Field::zeros(n);
    let mut written = false;
    for iteration in done + 1..=done + more {
        differences(rings, original, &q, &mut b, alpha);
        let mut parts = follow_parts(observer, n);
        correct(
            rings,
            original,
            &b,
            &mut q,
            (alpha, beta),
            constraint,
            &mut parts,
        );
        drop(parts);
        written = observer.watches_iteration(iteration);
        if written {
            q.write_points(&mut points);
            observer.after_step(&points);
            observer.after_iteration(iteration, &points);
        }
    }
    if !written {
        q.write_points(&mut points);
    }
    points
}

/// Pass 1: `b_i = mean_{N(i)} q - (alpha o_i + (1 - alpha) q_i)`; 0 for isolated vertices
/// (no ring reads them).
fn differences(rings: Rings, original: &[[f32; 3]], q: &Field, b: &mut Field, alpha: f32) {
    let keep = 1.0 - alpha;
    b.vertices_mut()
        .par_chunks_mut(CHUNK)
        .zip(
            q.vertices()
                .par_chunks(CHUNK)
                .zip(original.par_chunks(CHUNK)),
        )
        .enumerate()
        .for_each(|(c, (b, (own, orig)))| {
            let rows = b.iter_mut().zip(own.iter().zip(orig)).zip(rings.chunk(c));
            for ((bi, (&qi, &oi)), ring) in rows {
                *bi = if ring.is_empty() {
                    [0.0; 4]
                } else {
                    let p = rings.mean(ring, q);
                    let oi = xyz0(oi);
                    std::array::from_fn(|k| p[k] - (alpha * oi[k] + keep * qi[k]))
                };
            }
        });
}

/// Pass 2: `q_i <- p_i - (beta b_i + (1 - beta) mean_{N(i)} b)`, constrained, in place; each
/// chunk then goes to its follower part.
fn correct<C: Constrain>(
    rings: Rings,
    original: &[[f32; 3]],
    b: &Field,
    q: &mut Field,
    (alpha, beta): (f32, f32),
    constraint: &C,
    parts: &mut [Option<FollowPart>],
) {
    let keep = 1.0 - alpha;
    let spread = 1.0 - beta;
    q.vertices_mut()
        .par_chunks_mut(CHUNK)
        .zip(
            b.vertices()
                .par_chunks(CHUNK)
                .zip(original.par_chunks(CHUNK)),
        )
        .zip(parts.par_iter_mut())
        .enumerate()
        .for_each(|(c, ((q, (own_b, orig)), part))| {
            let rows = q.iter_mut().zip(own_b.iter().zip(orig)).zip(rings.chunk(c));
            for (k, ((qi, (&bi, &oi)), ring)) in rows.enumerate() {
                if ring.is_empty() {
                    continue;
                }
                let mb = rings.mean(ring, b);
                let oi = xyz0(oi);
                let proposed: [f32; 4] = std::array::from_fn(|k| {
                    let p = bi[k] + alpha * oi[k] + keep * qi[k];
                    p - (beta * bi[k] + spread * mb[k])
                });
                *qi = xyz0(constraint.apply(c * CHUNK + k, xyz(*qi), xyz(proposed)));
            }
            if let Some(follow) = part {
                follow(q);
            }
        });
}
