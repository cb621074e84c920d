//! Uniform Laplace and Taubin lambda/mu: repeated umbrella steps `q += factor * L(q)`.

use rayon::prelude::*;

use super::constraint::Constrain;
use super::rings::{xyz, xyz0, Field, Rings, CHUNK};
use super::{follow_parts, FollowPart, StepObserver};

/// Runs iterations `done + 1 ..= done + more` of the umbrella steps `factors` (Laplace:
/// `[lambda]`; Taubin: `[lambda, mu]`) from `start` (the result of `done` iterations; `None`:
/// `original`), reporting after every step and iteration.
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
    // The ping-pong pair, allocated once per run; `points` receives the 3-vectors the observer
    // and the caller see (the start's allocation, reused).
    let mut q = Field::from_points(start.as_deref().unwrap_or(original));
    let mut next = Field::zeros(original.len());
    let mut points = start.unwrap_or_default();
    let n = original.len();
    let mut written = false;
    for iteration in done + 1..=done + more {
        written = observer.watches_iteration(iteration);
        for &factor in factors {
            let mut parts = follow_parts(observer, n);
            step(rings, factor, &q, &mut next, constraint, &mut parts);
            drop(parts);
            std::mem::swap(&mut q, &mut next);
            if written {
                q.write_points(&mut points);
                observer.after_step(&points);
            }
        }
        if written {
            observer.after_iteration(iteration, &points);
        }
    }
    if !written {
        q.write_points(&mut points);
    }
    points
}

/// One Jacobi umbrella step: `dst_i = src_i + factor * (mean_{N(i)} src - src_i)`, constrained;
/// each chunk then goes to its follower part. Isolated vertices keep their position.
fn step<C: Constrain>(
    rings: Rings,
    factor: f32,
    src: &Field,
    dst: &mut Field,
    constraint: &C,
    parts: &mut [Option<FollowPart>],
) {
    assert!(src.vertices().len() == rings.vertex_count());
    assert!(dst.vertices().len() == rings.vertex_count());
    dst.vertices_mut()
        .par_chunks_mut(CHUNK)
        .zip(src.vertices().par_chunks(CHUNK))
        .zip(parts.par_iter_mut())
        .enumerate()
        .for_each(|(c, ((dst, own), part))| {
            let rows = dst.iter_mut().zip(own).zip(rings.chunk(c)).enumerate();
            for (k, ((out, &q), ring)) in rows {
                *out = if ring.is_empty() {
                    q
                } else {
                    let m = rings.mean(ring, src);
                    let proposed = std::array::from_fn(|k| q[k] + factor * (m[k] - q[k]));
                    xyz0(constraint.apply(c * CHUNK + k, xyz(q), xyz(proposed)))
                };
            }
            if let Some(follow) = part {
                follow(dst);
            }
        });
}
