//! Per-vertex smoothing weights painted by the user (ALGORITHMS.md: each step moves a vertex by
//! `w_i` times its filter displacement; 0 locks it). The model's structure keeps them; every
//! change bumps the session's revision (the result is recomputed) and the weights' own
//! version (the GPU engine uploads them once per change).
//!
//! Painting takes the minimum with the brush's profile and erasing the maximum, so dabbing the
//! same spot again in one stroke changes nothing: a stroke never "builds up" with the frame rate.

use super::CaseDocument;

/// What `state()` reports about the weights.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct WeightsSummary {
    /// Vertices with a weight below 1.
    pub painted: usize,
    /// Vertices with weight 0 (they do not move).
    pub locked: usize,
    pub min: f32,
    pub mean: f64,
}

/// What a brush dab does to the weights under it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Dab {
    /// Lowers them: at most `1 - (1 - target) * f`, so `target` 0 locks the centre.
    Paint(f32),
    /// Raises them back towards 1 (free): at least `f`.
    Erase,
}

impl WeightsSummary {
    /// The summary of `weights` ([`CaseDocument::weights`]), or `None` when nothing is painted.
    pub fn of(weights: Option<&[f32]>) -> Option<Self> {
        let w = weights?;
        Some(Self {
            painted: w.iter().filter(|&&x| x < 1.0).count(),
            locked: w.iter().filter(|&&x| x <= 0.0).count(),
            min: w.iter().copied().fold(1.0, f32::min),
            mean: w.iter().map(|&x| x as f64).sum::<f64>() / w.len().max(1) as f64,
        })
    }
}

impl CaseDocument {
    /// The painted weights (one per vertex in [0, 1]), or `None` while every vertex is free.
    pub fn weights(&self) -> Option<&[f32]> {
        self.structure()?.weights.as_deref()
    }

    /// Changes whenever the weights change (paint, erase, clear, a new model).
    pub fn weights_version(&self) -> u64 {
        self.weights_version
    }

    /// Changes the weights under a brush dab: vertex `i` with falloff `f` in [0, 1] (1 at the
    /// brush's centre) as `dab` says. Returns whether anything changed (only then do the
    /// results recompute).
    pub fn dab_weights(&mut self, footprint: &[(u32, f32)], dab: Dab) -> bool {
        match dab {
            Dab::Paint(target) => {
                let target = target.clamp(0.0, 1.0);
                self.edit_weights(footprint, |w, f| w.min(1.0 - (1.0 - target) * f))
            }
            Dab::Erase => self.edit_weights(footprint, |w, f| w.max(f)),
        }
    }

    /// Every vertex free again. Returns whether anything was painted.
    pub fn clear_weights(&mut self) -> bool {
        if self.weights().is_none() {
            return false;
        }
        self.set_weights(None);
        true
    }

    fn edit_weights(&mut self, footprint: &[(u32, f32)], rule: impl Fn(f32, f32) -> f32) -> bool {
        let Some(model) = self.model() else {
            return false;
        };
        let n = model.mesh().vertex_count();
        let kept = &mut self.case.structures[self.current].weights;
        let mut values = kept.take().unwrap_or_else(|| vec![1.0; n]);
        let mut changed = false;
        for &(i, f) in footprint {
            let Some(w) = values.get_mut(i as usize) else {
                continue;
            };
            let f = if f.is_finite() {
                f.clamp(0.0, 1.0)
            } else {
                0.0
            };
            let new = rule(*w, f).clamp(0.0, 1.0);
            if new != *w {
                *w = new;
                changed = true;
            }
        }
        // All free again: no weights at all, so the result is exactly the unweighted one.
        let values = values.iter().any(|&w| w < 1.0).then_some(values);
        if changed {
            self.set_weights(values);
        } else {
            self.case.structures[self.current].weights = values;
        }
        changed
    }

    fn set_weights(&mut self, weights: Option<Vec<f32>>) {
        if let Some(s) = self.structure_mut() {
            s.set_weights(weights);
            self.weights_version += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::session::testing::smooth_cpu;
    use crate::session::ColorField;
    use crate::session::Session;
    use crate::smooth::Filter;

    const SAMPLE: &[u8] = include_bytes!("../../tests/data/bent_tube_staircase.ply");

    fn sample_session() -> Session {
        let mut s = Session::default();
        s.open("bent_tube_staircase.ply", SAMPLE)
            .expect("the sample opens");
        s
    }

    fn smoothed(s: &mut Session) -> Vec<[f32; 3]> {
        smooth_cpu(s);
        s.case().result().expect("a result").positions.clone()
    }

    /// The first `k` vertices at full strength.
    fn dab(k: u32) -> Vec<(u32, f32)> {
        (0..k).map(|i| (i, 1.0)).collect()
    }

    #[test]
    fn locked_vertices_do_not_move_with_any_filter() {
        let mut s = sample_session();
        assert!(s.case_mut().dab_weights(&dab(50), Dab::Paint(0.0)));
        // A half weight on the next ones: they move, but less than unweighted.
        assert!(s
            .case_mut()
            .dab_weights(&[(60, 1.0), (61, 1.0)], Dab::Paint(0.5)));
        let original = s.case().model().unwrap().mesh().positions.clone();
        for filter in Filter::ALL {
            s.case_mut().set_filter(filter);
            let weighted = smoothed(&mut s);
            for i in 0..50 {
                assert_eq!(weighted[i], original[i], "{filter}: vertex {i} moved");
            }
            assert!(
                weighted[60..62] != original[60..62],
                "{filter}: half-weighted vertices move"
            );
            // In frame-sized chunks too (the browser's CPU engine).
            let w = s.case().weights().unwrap().to_vec();
            s.case_mut().clear_weights();
            assert!(s.case_mut().dab_weights(
                &w.iter()
                    .enumerate()
                    .map(|(i, &w)| (i as u32, 1.0 - w))
                    .collect::<Vec<_>>(),
                Dab::Paint(0.0)
            ));
            assert_eq!(s.case().weights().unwrap(), w.as_slice());
            smooth_cpu(&mut s);
            assert_eq!(
                s.case().result().unwrap().positions,
                weighted,
                "{filter}: again"
            );
        }
    }

    #[test]
    fn clearing_restores_the_unweighted_result_exactly() {
        let mut s = sample_session();
        s.case_mut().set_filter(Filter::Taubin);
        let free = smoothed(&mut s);
        let free_metrics = s.case().result().unwrap().metrics.clone();
        let revision = s.case().revision();
        assert!(s.case_mut().dab_weights(&dab(400), Dab::Paint(0.2)));
        assert!(s.case().revision() > revision, "painting recomputes");
        let painted = smoothed(&mut s);
        assert_ne!(painted, free);
        assert!(s.case_mut().clear_weights());
        assert_eq!(s.case().weights(), None);
        assert!(!s.case_mut().clear_weights(), "nothing left to clear");
        assert_eq!(smoothed(&mut s), free);
        assert_eq!(s.case().result().unwrap().metrics, free_metrics);
        // Erasing everything painted is the same as clearing.
        assert!(s.case_mut().dab_weights(&dab(400), Dab::Paint(0.0)));
        assert!(s.case_mut().dab_weights(&dab(400), Dab::Erase));
        assert_eq!(s.case().weights(), None);
        assert_eq!(smoothed(&mut s), free);
    }

    #[test]
    fn a_dab_repeated_changes_nothing_and_keeps_the_results() {
        let mut s = sample_session();
        let footprint = [(3, 1.0), (4, 0.5), (5, 0.0), (6, f32::NAN), (99_999, 1.0)];
        let generation = s.case().weights_version();
        assert!(s.case_mut().dab_weights(&footprint, Dab::Paint(0.0)));
        assert_eq!(s.case().weights_version(), generation + 1);
        let w = s.case().weights().unwrap();
        assert_eq!((w[3], w[4], w[5], w[6]), (0.0, 0.5, 1.0, 1.0));
        smooth_cpu(&mut s);
        let revision = s.case().revision();
        assert!(
            !s.case_mut().dab_weights(&footprint, Dab::Paint(0.0)),
            "the same dab again"
        );
        // A weaker brush does not unlock what is locked.
        assert!(!s.case_mut().dab_weights(&footprint, Dab::Paint(0.7)));
        assert_eq!(s.case().revision(), revision);
        assert!(s.case().result().is_some(), "nothing to recompute");
        // Erasing at half strength raises to at least the falloff.
        assert!(s.case_mut().dab_weights(&[(3, 0.25)], Dab::Erase));
        assert_eq!(s.case().weights().unwrap()[3], 0.25);

        let summary = WeightsSummary::of(s.case().weights()).unwrap();
        assert_eq!((summary.painted, summary.locked), (2, 0));
        assert_eq!(summary.min, 0.25);

        // A new model starts free.
        s.open("again.ply", SAMPLE).unwrap();
        assert_eq!(s.case().weights(), None);
        assert_eq!(WeightsSummary::of(s.case().weights()), None);
        assert!(s.case().weights_version() > generation + 1);
        // Nothing open, nothing to paint.
        assert!(!Session::default()
            .case_mut()
            .dab_weights(&footprint, Dab::Paint(0.0)));
    }

    #[test]
    fn weights_colour_locked_apart_from_free() {
        let mut s = sample_session();
        let (free, legend) = s
            .case()
            .colors(ColorField::Weights)
            .expect("before any result");
        assert_eq!(free.len(), s.case().model().unwrap().mesh().vertex_count());
        assert!(free.iter().all(|c| *c == free[0]));
        assert_eq!((legend.min, legend.max), (0.0, 1.0));
        assert_eq!(legend.ticks[0].label, "0");
        s.case_mut().dab_weights(&dab(1), Dab::Paint(0.0));
        let (painted, _) = s.case().colors(ColorField::Weights).unwrap();
        assert_ne!(painted[0], painted[1]);
        assert_eq!(painted[1], free[1]);
    }
}
