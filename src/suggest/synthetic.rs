//! Synthetic evaluators with known minima, for testing the search logic without smoothing.

use super::space::{GridPoint, ParamSpace};
use super::{is_cumulative, Evaluator, Terms};
use crate::smooth::{Filter, Params};

/// Evaluates a function of the parameters, checking the evaluator contract and counting work.
pub struct FnEvaluator<F: FnMut(&Params) -> Terms> {
    f: F,
    /// Smoothing runs asked for.
    pub runs: usize,
    /// Iterations those runs would have smoothed.
    pub iterations_run: u64,
    /// Every parameter set measured.
    pub seen: Vec<Params>,
}

impl<F: FnMut(&Params) -> Terms> FnEvaluator<F> {
    pub fn new(f: F) -> Self {
        Self {
            f,
            runs: 0,
            iterations_run: 0,
            seen: Vec::new(),
        }
    }
}

impl<F: FnMut(&Params) -> Terms> Evaluator for FnEvaluator<F> {
    fn measure(&mut self, params: &Params, at: &[u32]) -> Option<Vec<Terms>> {
        assert!(!at.is_empty());
        assert!(at.windows(2).all(|w| w[0] < w[1]), "unsorted {at:?}");
        if !is_cumulative(params.filter) {
            assert_eq!(at.len(), 1, "sinc measured along one run");
        }
        self.runs += 1;
        self.iterations_run += u64::from(*at.last().unwrap_or(&0));
        Some(
            at.iter()
                .map(|&k| {
                    let mut p = *params;
                    p.iterations = k;
                    self.seen.push(p);
                    (self.f)(&p)
                })
                .collect(),
        )
    }
}

/// Answers each request only on its `delay + 1`-th asking, like an evaluator that spreads its
/// runs over frames; checks that the task asks again for the same run meanwhile.
pub struct Slow<E> {
    pub inner: E,
    delay: usize,
    asked: Option<(Params, Vec<u32>, usize)>,
}

impl<E> Slow<E> {
    pub fn new(inner: E, delay: usize) -> Self {
        Self {
            inner,
            delay,
            asked: None,
        }
    }
}

impl<E> Slow<E> {
    /// Whether this asking of `(params, at)` is answered.
    fn answers(&mut self, params: &Params, at: &[u32]) -> bool {
        let times = match &self.asked {
            Some((p, a, n)) => {
                assert_eq!((p, a.as_slice()), (params, at), "asked for another run");
                n + 1
            }
            None => 1,
        };
        if times <= self.delay {
            self.asked = Some((*params, at.to_vec(), times));
            return false;
        }
        self.asked = None;
        true
    }
}

impl<E: Evaluator> Evaluator for Slow<E> {
    fn measure(&mut self, params: &Params, at: &[u32]) -> Option<Vec<Terms>> {
        if !self.answers(params, at) {
            return None;
        }
        self.inner.measure(params, at)
    }

    fn measure_bounds(&mut self, params: &Params, at: &[u32]) -> Option<Vec<(Terms, bool)>> {
        if !self.answers(params, at) {
            return None;
        }
        self.inner.measure_bounds(params, at)
    }
}

/// Answers bounds without the mean error where it is not 0 (and counts the full measures),
/// like the CPU engine's evaluator.
pub struct Bounding<E> {
    pub inner: E,
    /// Parameter sets measured fully.
    pub full: usize,
}

impl<E> Bounding<E> {
    pub fn new(inner: E) -> Self {
        Self { inner, full: 0 }
    }
}

impl<E: Evaluator> Evaluator for Bounding<E> {
    fn measure(&mut self, params: &Params, at: &[u32]) -> Option<Vec<Terms>> {
        let terms = self.inner.measure(params, at)?;
        self.full += terms.len();
        Some(terms)
    }

    fn measure_bounds(&mut self, params: &Params, at: &[u32]) -> Option<Vec<(Terms, bool)>> {
        let terms = self.inner.measure(params, at)?;
        let bound = |t: Terms| Terms {
            mean_error: 0.0,
            ..t
        };
        Some(
            terms
                .into_iter()
                .map(|t| (bound(t), t.mean_error == 0.0))
                .collect(),
        )
    }
}

/// K/K0 = 1 + squared grid distance to `centre` (in grid steps), no error: the minimum of S is
/// at `centre` for every tau > 0.
pub fn bowl(space: &ParamSpace, centre: GridPoint) -> impl FnMut(&Params) -> Terms {
    let space = space.clone();
    move |p| {
        let at = space.point_of(p).unwrap_or(GridPoint([99; 3]));
        let d2: f64 = (0..space.dims())
            .map(|k| (at.0[k] as f64 - centre.0[k] as f64).powi(2))
            .sum();
        Terms {
            curvature_ratio: 1.0 + 0.01 * d2,
            mean_error: 0.0,
            volume_change: Some(0.0),
            roughness_ratio: 0.5,
        }
    }
}

/// Two basins, `f = min(d2(a) + depth_a, d2(b) + depth_b)`: two local minima, the deeper one global.
pub fn two_basins(
    space: &ParamSpace,
    a: GridPoint,
    depth_a: f64,
    b: GridPoint,
    depth_b: f64,
) -> impl FnMut(&Params) -> Terms {
    let mut fa = bowl(space, a);
    let mut fb = bowl(space, b);
    move |p| {
        let ta = fa(p).curvature_ratio + depth_a;
        let tb = fb(p).curvature_ratio + depth_b;
        Terms {
            curvature_ratio: ta.min(tb),
            mean_error: 0.0,
            volume_change: Some(0.0),
            roughness_ratio: 0.5,
        }
    }
}

/// A plausible smoothing response: strength grows with iterations and the smoothing weights,
/// curvature falls, error and volume change grow; zero iterations leave the mesh unchanged.
pub fn smoothing_model(filter: Filter) -> impl FnMut(&Params) -> Terms {
    move |p| {
        let it = p.iterations as f64;
        let s = match filter {
            Filter::Laplace => p.lambda as f64 * it / 10.0,
            Filter::Taubin => {
                let passband = 1.0 / p.lambda as f64 + 1.0 / p.mu as f64;
                p.lambda as f64 * it / 10.0 * (1.0 - passband).max(0.05)
            }
            Filter::Hc => (1.0 - p.alpha as f64) * (1.0 - p.beta as f64) * it / 5.0,
            Filter::Sinc => (1.0 - (p.passband as f64).sqrt()) * it.min(30.0) / 6.0,
        };
        if it == 0.0 {
            return Terms::UNCHANGED;
        }
        Terms {
            curvature_ratio: 0.2 + 0.8 * (-s).exp(),
            mean_error: 0.05 * s,
            volume_change: Some(0.01 * s * (1.0 + 0.1 * s)),
            roughness_ratio: (-s).exp(),
        }
    }
}
