//! The score terms of a smoothed mesh (paper eq. 4), the score S(tau) made of them, and the
//! order in which a search ranks them.

use crate::metrics::{Metrics, Original};
use serde::{Deserialize, Serialize};

/// The quantities the score is made of (paper eq. 4). Equal when every field is, NaN equal to
/// NaN: the terms of a set not measured further ([`Terms::roughened`]) are the same answer.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct Terms {
    /// K/K0: mean |Gaussian curvature| relative to the original mesh.
    pub curvature_ratio: f64,
    /// E: mean local error (mesh units, mm).
    pub mean_error: f64,
    /// |V - V0| / V0; `None` when the mesh is open and its volume means nothing.
    pub volume_change: Option<f64>,
    /// R/R0, the roughness relative to the original's ([`crate::metrics::roughness()`]). Not
    /// part of S: above 1 the filter amplified what it should damp (it is unstable at these
    /// parameters on this mesh), and [`Terms::rank`] puts the set after every one that smooths.
    pub roughness_ratio: f64,
}

/// What a search looks for: the lowest S(tau), among the sets that change the volume by at
/// most `max_volume_change` (a fraction) when one is given. Thin structures (vessels) lose
/// volume to smoothing faster than the score weighs it; an author of a case can hold them to
/// a limit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Goal {
    pub tau: f64,
    pub max_volume_change: Option<f64>,
}

impl From<f64> for Goal {
    fn from(tau: f64) -> Self {
        Goal {
            tau,
            max_volume_change: None,
        }
    }
}

/// Where a measured parameter set stands in a search (lower is better): every set that does
/// not roughen the mesh by its score S, then those that do by their roughness ratio (so a
/// local search that starts among them walks out towards the sets that smooth), then the
/// failed ones (NaN).
#[derive(Clone, Copy, Debug)]
pub struct Rank {
    class: u8,
    /// Never NaN.
    key: f64,
}

impl PartialEq for Terms {
    fn eq(&self, other: &Self) -> bool {
        same(self.curvature_ratio, other.curvature_ratio)
            && same(self.mean_error, other.mean_error)
            && same(self.roughness_ratio, other.roughness_ratio)
            && match (self.volume_change, other.volume_change) {
                (Some(a), Some(b)) => same(a, b),
                (a, b) => a.is_none() && b.is_none(),
            }
    }
}

/// Equal, or both NaN.
pub(crate) fn same(a: f64, b: f64) -> bool {
    a == b || a.is_nan() && b.is_nan()
}

impl PartialEq for Rank {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other).is_eq()
    }
}

impl Eq for Rank {}

impl PartialOrd for Rank {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Rank {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.class
            .cmp(&other.class)
            .then_with(|| score_order(self.key, other.key))
    }
}

impl Terms {
    /// The terms of the unchanged mesh.
    pub const UNCHANGED: Terms = Terms {
        curvature_ratio: 1.0,
        mean_error: 0.0,
        volume_change: Some(0.0),
        roughness_ratio: 1.0,
    };

    /// The terms of a set that left the mesh `roughness_ratio` (> 1) times as rough as the
    /// original: the score's terms are NaN, since measures of a mesh the filter blew up mean
    /// nothing (its curvature falls as it grows, and E/(E+1) saturates), and the evaluators
    /// skip them.
    pub fn roughened(roughness_ratio: f64) -> Terms {
        Terms {
            curvature_ratio: f64::NAN,
            mean_error: f64::NAN,
            volume_change: None,
            roughness_ratio,
        }
    }

    /// Whether the smoothed mesh came out rougher than the original: the filter diverges here.
    pub fn roughens(&self) -> bool {
        self.roughness_ratio > 1.0
    }

    /// Whether the evaluation failed (a lost device): NaN terms that say nothing, not even
    /// the roughness.
    pub fn failed(&self) -> bool {
        self.roughness_ratio.is_nan()
            || !self.roughens() && (self.curvature_ratio.is_nan() || self.mean_error.is_nan())
    }

    /// The set's [`Rank`] for a goal (a `tau`, or a [`Goal`] that also limits the volume
    /// change): the sets within the limit by S, then those past it by their volume change (a
    /// search that starts among them walks towards the limit), then those that roughen the
    /// mesh, then the failed ones.
    pub fn rank(&self, goal: impl Into<Goal>) -> Rank {
        let goal = goal.into();
        let score = self.score(goal.tau);
        let past_limit = match (goal.max_volume_change, self.volume_change) {
            (Some(limit), Some(change)) => change.abs() > limit,
            _ => false,
        };
        if self.failed() || score.is_nan() && !self.roughens() {
            Rank { class: 3, key: 0.0 }
        } else if self.roughens() {
            Rank {
                class: 2,
                key: self.roughness_ratio,
            }
        } else if past_limit {
            Rank {
                class: 1,
                key: self.volume_change.map_or(0.0, f64::abs),
            }
        } else {
            Rank {
                class: 0,
                key: score,
            }
        }
    }

    /// The accuracy half of the score, `0.5 * (E/(E+1) + |V-V0|/V0)`. Without a volume (open
    /// mesh) it is `E/(E+1)` alone, the mean of the terms that exist, as in [`crate::metrics`].
    pub fn accuracy(&self) -> f64 {
        let e = self.mean_error / (self.mean_error + 1.0);
        match self.volume_change {
            Some(v) => 0.5 * (e + v),
            None => e,
        }
    }

    /// `S(tau) = tau * K/K0 + (1 - tau) * accuracy`. Lower is better. NaN terms give NaN, which
    /// every comparison here ranks last.
    pub fn score(&self, tau: f64) -> f64 {
        tau * self.curvature_ratio + (1.0 - tau) * self.accuracy()
    }
}

/// The score terms of a measured mesh whose roughness is `roughness_ratio` times the
/// original's ([`Terms::roughened`] when above 1: what a blown-up mesh measures means nothing).
pub fn terms_of(metrics: &Metrics, roughness_ratio: f64) -> Terms {
    if roughness_ratio > 1.0 {
        return Terms::roughened(roughness_ratio);
    }
    Terms {
        curvature_ratio: metrics.score_terms().curvature_ratio,
        mean_error: metrics.mean_error,
        volume_change: metrics.volume_change.map(f64::abs),
        roughness_ratio,
    }
}

/// The terms of the unchanged mesh (no volume term when it is open): what zero iterations give.
pub fn unchanged_terms(original: &Original) -> Terms {
    Terms {
        volume_change: original.volume().map(|_| 0.0),
        ..Terms::UNCHANGED
    }
}

/// What a failed evaluation answers: NaN terms, which every comparison ranks last.
pub fn failed_terms(count: usize) -> Vec<Terms> {
    vec![
        Terms {
            curvature_ratio: f64::NAN,
            mean_error: f64::NAN,
            volume_change: None,
            roughness_ratio: f64::NAN,
        };
        count
    ]
}

/// Orders scores with NaN last, so a broken measurement never wins.
fn score_order(a: f64, b: f64) -> std::cmp::Ordering {
    match (a.is_nan(), b.is_nan()) {
        (false, false) => a.total_cmp(&b),
        (true, true) => std::cmp::Ordering::Equal,
        (true, false) => std::cmp::Ordering::Greater,
        (false, true) => std::cmp::Ordering::Less,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sets_that_smooth_rank_first_then_the_least_rough_then_failures() {
        let smooths = |s: f64| Terms {
            curvature_ratio: s,
            mean_error: 0.0,
            volume_change: Some(0.0),
            roughness_ratio: 0.3,
        };
        let (good, worse) = (smooths(0.4), smooths(0.9));
        // A blown-up mesh whose score, had it been measured, would beat both.
        let (rough, rougher) = (Terms::roughened(1.5), Terms::roughened(80.0));
        let failed = failed_terms(1)[0];
        let ranks = [good, worse, rough, rougher, failed].map(|t| t.rank(1.0));
        for pair in ranks.windows(2) {
            assert!(pair[0] < pair[1], "{pair:?}");
        }
        assert!(
            !Terms::UNCHANGED.roughens(),
            "the unchanged mesh is as rough as itself"
        );
        assert!(Terms::roughened(1.0 + 1e-9).roughens());
        assert_eq!(smooths(0.4).rank(1.0), good.rank(1.0));
    }

    #[test]
    fn a_volume_limit_puts_the_sets_past_it_after_those_within_by_their_change() {
        let set = |k: f64, dv: f64| Terms {
            curvature_ratio: k,
            mean_error: 0.1,
            volume_change: Some(dv),
            roughness_ratio: 0.3,
        };
        let (strong, mild) = (set(0.1, -0.07), set(0.6, -0.02));
        assert!(
            strong.rank(0.5) < mild.rank(0.5),
            "without a limit S decides"
        );
        let goal = Goal {
            tau: 0.5,
            max_volume_change: Some(0.05),
        };
        let nearer = set(0.05, 0.06);
        let ranks = [mild, nearer, strong, Terms::roughened(1.5)].map(|t| t.rank(goal));
        for pair in ranks.windows(2) {
            assert!(pair[0] < pair[1], "{pair:?}");
        }
        // An open mesh has no volume to hold.
        let open = Terms {
            volume_change: None,
            ..strong
        };
        assert_eq!(open.rank(goal), open.rank(0.5));
    }

    #[test]
    fn score_follows_equation_four() {
        let t = Terms {
            curvature_ratio: 0.4,
            mean_error: 0.25,
            volume_change: Some(0.02),
            roughness_ratio: 0.5,
        };
        let accuracy = 0.5 * (0.25 / 1.25 + 0.02);
        assert!((t.accuracy() - accuracy).abs() < 1e-15);
        assert!((t.score(0.3) - (0.3 * 0.4 + 0.7 * accuracy)).abs() < 1e-15);
        assert_eq!(t.score(1.0), 0.4);
        let open = Terms {
            volume_change: None,
            ..t
        };
        assert!((open.accuracy() - 0.2).abs() < 1e-15);
        assert_eq!(Terms::UNCHANGED.score(0.0), 0.0);
        assert_eq!(Terms::UNCHANGED.score(0.7), 0.7);
    }

    #[test]
    fn nan_scores_rank_last() {
        use std::cmp::Ordering::*;
        assert_eq!(score_order(f64::NAN, 1e9), Greater);
        assert_eq!(score_order(0.1, f64::NAN), Less);
        assert_eq!(score_order(0.1, 0.2), Less);
    }
}
