//! The paper's quality score (eq. 4): `S = tau K/K0 + (1 - tau) 0.5 (E/(E+1) + |V - V0|/V0)`.
//! Lower is better; `tau` in [0, 1] trades smoothness (1) against accuracy (0).

use serde::Serialize;

/// The two halves of the score, so a score can be had for any `tau` without measuring again.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ScoreTerms {
    /// `K / K0`. 1 when the original has no curvature (`K0 = 0`): there is nothing to reduce,
    /// so the smoothness term then has no say.
    pub curvature_ratio: f64,
    /// `0.5 (E/(E+1) + |V - V0|/|V0|)`, the mean of the accuracy terms. Where the volume is
    /// undefined (open mesh) or `V0 = 0`, the volume term is dropped and this is `E/(E+1)` alone:
    /// the mean of the terms that exist, so `tau` keeps its balance between the two halves.
    pub accuracy: f64,
}

impl ScoreTerms {
    /// `curvature`, `curvature0`: K and K0; `mean_error`: E (mesh units);
    /// `volume`, `volume0`: V and V0 where defined.
    pub fn new(
        curvature: f64,
        curvature0: f64,
        mean_error: f64,
        volume: Option<f64>,
        volume0: Option<f64>,
    ) -> Self {
        let curvature_ratio = if curvature0 > 0.0 {
            curvature / curvature0
        } else {
            1.0
        };
        let error_term = mean_error / (mean_error + 1.0);
        let accuracy = match (volume, volume0) {
            (Some(v), Some(v0)) if v0 != 0.0 => 0.5 * (error_term + ((v - v0) / v0).abs()),
            _ => error_term,
        };
        Self {
            curvature_ratio,
            accuracy,
        }
    }

    /// `S(tau) = tau * curvature_ratio + (1 - tau) * accuracy`.
    pub fn score(&self, tau: f64) -> f64 {
        tau * self.curvature_ratio + (1.0 - tau) * self.accuracy
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_formula() {
        let t = ScoreTerms::new(2.0, 4.0, 1.0, Some(90.0), Some(100.0));
        assert_eq!(t.curvature_ratio, 0.5);
        assert!((t.accuracy - 0.5 * (0.5 + 0.1)).abs() < 1e-15);
        assert_eq!(t.score(1.0), 0.5);
        assert!((t.score(0.0) - 0.3).abs() < 1e-15);
        assert!((t.score(0.5) - 0.4).abs() < 1e-15);
    }

    #[test]
    fn undefined_volume_and_flat_original() {
        let t = ScoreTerms::new(0.0, 0.0, 3.0, None, None);
        assert_eq!(t.curvature_ratio, 1.0);
        assert_eq!(t.accuracy, 0.75);
        let t = ScoreTerms::new(1.0, 1.0, 0.0, Some(1.0), Some(0.0));
        assert_eq!(t.accuracy, 0.0);
    }

    #[test]
    fn untouched_mesh_scores_tau() {
        let t = ScoreTerms::new(5.0, 5.0, 0.0, Some(7.0), Some(7.0));
        for tau in [0.0, 0.25, 1.0] {
            assert_eq!(t.score(tau), tau);
        }
    }
}
