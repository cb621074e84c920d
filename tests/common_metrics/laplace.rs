//! A plain uniform Laplace smoother (`q += lambda L(q)`, Jacobi, boundary vertices along the
//! boundary): a stand-in that lets the measures be tested on moved vertices without the engine.
#![allow(dead_code)]

use meshsmooth::mesh::{Mesh, Topology};
use meshsmooth::smooth::StepObserver;
use rayon::prelude::*;

pub fn laplace(
    mesh: &Mesh,
    topology: &Topology,
    lambda: f32,
    iterations: u32,
    observer: &mut dyn StepObserver,
) -> Vec<[f32; 3]> {
    let (offsets, ring) = topology.smoothing_ring();
    let mut q = mesh.positions.clone();
    let mut next = q.clone();
    for it in 1..=iterations {
        next.par_iter_mut()
            .enumerate()
            .with_min_len(4096)
            .for_each(|(i, out)| {
                let nb = &ring[offsets[i] as usize..offsets[i + 1] as usize];
                if nb.is_empty() {
                    *out = q[i];
                    return;
                }
                let mut avg = [0.0f32; 3];
                for &j in nb {
                    for k in 0..3 {
                        avg[k] += q[j as usize][k];
                    }
                }
                for k in 0..3 {
                    out[k] = q[i][k] + lambda * (avg[k] / nb.len() as f32 - q[i][k]);
                }
            });
        std::mem::swap(&mut q, &mut next);
        observer.after_step(&q);
        observer.after_iteration(it, &q);
    }
    q
}
