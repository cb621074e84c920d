//! Uniform Laplace and Taubin lambda/mu: repeated umbrella steps `q += factor * L(q)`.

use rayon::prelude::*;

use super::constraint::Constrain;
use super::rings::{Field, Fields, KernelRings, CHUNK};
use super::{follow_parts, FollowPart, StepObserver};

/// Runs iterations `done + 1 ..= done + more` of the umbrella steps `factors` (Laplace:
/// `[lambda]`; Taubin: `[lambda, mu]`) on `fields` (the result of `done` iterations),
/// reporting after every step and iteration; the positions the observer sees are laid out in
/// `points`. Returns whether `points` holds the last iteration's positions.
pub(crate) fn advance<C: Constrain>(
    rings: KernelRings,
    fields: &mut Fields,
    points: &mut Vec<[f32; 3]>,
    factors: &[f32],
    (done, more): (u32, u32),
    constraint: &C,
    observer: &mut dyn StepObserver,
) -> bool {
    let n = rings.vertex_count();
    let (q, next, _) = fields.with_scratch(0);
    let mut written = false;
    for iteration in done + 1..=done + more {
        written = observer.watches_iteration(iteration);
        for &factor in factors {
            let mut parts = follow_parts(observer, n);
            step(rings, factor, q, next, constraint, &mut parts);
            drop(parts);
            std::mem::swap(q, next);
            if written {
                q.write_points(points);
                observer.after_step(points);
            }
        }
        if written {
            observer.after_iteration(iteration, points);
        }
    }
    written
}

/// One Jacobi umbrella step: `dst_i = src_i + factor * (mean_{N(i)} src - src_i)`, constrained;
/// each chunk then goes to its follower part. Isolated vertices keep their position.
fn step<C: Constrain>(
    rings: KernelRings,
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
            let rows = dst.iter_mut().zip(own).zip(rings.chunk(c, src)).enumerate();
            for (k, ((out, &q), ring)) in rows {
                *out = if ring.is_empty() {
                    q
                } else {
                    let m = rings.mean(ring);
                    let proposed = std::array::from_fn(|k| q[k] + factor * (m[k] - q[k]));
                    constraint.apply4(c * CHUNK + k, q, proposed)
                };
            }
            if let Some(follow) = part {
                follow(dst);
            }
        });
}
