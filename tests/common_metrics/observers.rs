//! Step observers the tests run alongside the smoothing engine.
#![allow(dead_code)]

use meshsmooth::mesh::{Mesh, Topology};
use meshsmooth::metrics::DriftingReference;
use meshsmooth::smooth::StepObserver;

/// The definition, written plainly: the reference moves to the closest of itself and its 1-ring
/// (ties keep the reference, then the first neighbour).
pub struct PlainDrift<'a> {
    pub mesh: &'a Mesh,
    pub topology: &'a Topology,
    pub reference: Vec<u32>,
}

impl PlainDrift<'_> {
    pub fn update(&mut self, q: &[[f32; 3]]) {
        for (i, r) in self.reference.iter_mut().enumerate() {
            let d2 = |j: u32| -> f32 {
                let p = self.mesh.positions[j as usize];
                (0..3).map(|k| (q[i][k] - p[k]) * (q[i][k] - p[k])).sum()
            };
            let mut best = *r;
            for &j in self.topology.neighbors_of(*r as usize) {
                if d2(j) < d2(best) {
                    best = j;
                }
            }
            *r = best;
        }
    }
}

/// Runs the drift and the plain definition side by side and compares them after every step.
pub struct BothDrifts<'a> {
    pub fast: DriftingReference<'a>,
    pub plain: PlainDrift<'a>,
    pub steps: u32,
    pub moved: usize,
}

impl StepObserver for BothDrifts<'_> {
    fn after_step(&mut self, positions: &[[f32; 3]]) {
        self.fast.update(positions);
        self.plain.update(positions);
        assert_eq!(
            self.fast.reference(),
            &self.plain.reference[..],
            "step {}",
            self.steps
        );
        self.steps += 1;
        self.moved = (0..positions.len())
            .filter(|&i| self.plain.reference[i] != i as u32)
            .count();
    }
}

/// Keeps the drifting reference going and takes a snapshot at one iteration on the way.
pub struct Snapshot<'a> {
    pub drift: DriftingReference<'a>,
    pub at: u32,
    pub taken: Option<(Vec<[f32; 3]>, Vec<u32>)>,
}

impl StepObserver for Snapshot<'_> {
    fn after_step(&mut self, positions: &[[f32; 3]]) {
        self.drift.update(positions);
    }
    fn after_iteration(&mut self, iteration: u32, positions: &[[f32; 3]]) {
        if iteration == self.at {
            self.taken = Some((positions.to_vec(), self.drift.reference().to_vec()));
        }
    }
}
