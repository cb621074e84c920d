//! Per-vertex weights and the displacement bound: where a vertex may actually go once its filter
//! has proposed a position.
//!
//! The kernels are generic over [`Constrain`], so the common unconstrained run compiles to a loop
//! that reads neither weights nor original positions.

use super::rings::{xyz, xyz0};

/// Maps a filter's proposed position of vertex `i` to the position it takes.
pub(crate) trait Constrain: Sync {
    /// True when `apply` always returns `proposed` (lets a filter skip a constrained copy).
    const IS_FREE: bool = false;
    /// [`Self::apply`] on the kernels' four-lane entries (the fourth lane 0, and kept 0). The
    /// kernels keep all four lanes: were the fourth dropped, the compiler would gather three
    /// lanes of each neighbour, as a two-lane and a one-lane load with scalar adds.
    fn apply4(&self, i: usize, current: [f32; 4], proposed: [f32; 4]) -> [f32; 4];

    /// `current` is where the vertex is, `proposed` where the filter would put it.
    #[inline(always)]
    fn apply(&self, i: usize, current: [f32; 3], proposed: [f32; 3]) -> [f32; 3] {
        xyz(self.apply4(i, xyz0(current), xyz0(proposed)))
    }
}

/// No weights, no bound: the filter's position as proposed.
pub(crate) struct Free;

impl Constrain for Free {
    const IS_FREE: bool = true;
    #[inline(always)]
    fn apply4(&self, _i: usize, _current: [f32; 4], proposed: [f32; 4]) -> [f32; 4] {
        proposed
    }
}

/// Weights scale each step's displacement; then the bound pulls the vertex back onto the ball
/// of radius `d_max` around its original position (exactly, up to the f32 rounding of the
/// coordinates: a few ulps of their magnitude).
pub(crate) struct Limits<'a> {
    weights: Option<&'a [f32]>,
    bound: Option<(f32, &'a [[f32; 3]])>,
}

impl<'a> Limits<'a> {
    /// `None` when nothing constrains the run. Weights of the wrong length are a caller bug: they
    /// trip a debug assertion and are ignored in release builds rather than indexed out of range.
    /// A bound that is NaN or negative locks every vertex (radius 0); an infinite one is no bound.
    pub(crate) fn new(
        weights: Option<&'a [f32]>,
        max_displacement: Option<f32>,
        original: &'a [[f32; 3]],
    ) -> Option<Self> {
        let weights = weights.filter(|w| {
            debug_assert_eq!(w.len(), original.len(), "one weight per vertex");
            w.len() == original.len()
        });
        let bound = max_displacement
            .map(|d| d.max(0.0))
            .filter(|d| d.is_finite())
            .map(|d| (d, original));
        (weights.is_some() || bound.is_some()).then_some(Self { weights, bound })
    }
}

impl Constrain for Limits<'_> {
    #[inline(always)]
    fn apply4(&self, i: usize, current: [f32; 4], proposed: [f32; 4]) -> [f32; 4] {
        let mut p = proposed;
        if let Some(w) = self.weights {
            // Written so that a NaN weight counts as 0 (locked) instead of spreading NaN.
            // Selects, not `f32::min`, which wasm calls a function for.
            let w = if w[i] > 1.0 {
                1.0
            } else if w[i] > 0.0 {
                w[i]
            } else {
                0.0
            };
            p = std::array::from_fn(|k| current[k] + w * (p[k] - current[k]));
        }
        if let Some((d_max, original)) = self.bound {
            let o = xyz0(original[i]);
            let d: [f32; 4] = std::array::from_fn(|k| p[k] - o[k]);
            let len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            if len2 > d_max * d_max {
                let s = d_max / len2.sqrt();
                p = std::array::from_fn(|k| o[k] + d[k] * s);
            }
        }
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weight_scales_the_step_and_zero_locks() {
        let o = [[0.0; 3]; 2];
        let w = [0.25, 0.0];
        let l = Limits::new(Some(&w), None, &o).expect("weights given");
        assert_eq!(
            l.apply(0, [1.0, 0.0, 0.0], [5.0, 4.0, 0.0]),
            [2.0, 1.0, 0.0]
        );
        assert_eq!(
            l.apply(1, [1.0, 0.0, 0.0], [5.0, 4.0, 0.0]),
            [1.0, 0.0, 0.0]
        );
    }

    #[test]
    fn bound_projects_onto_the_ball_around_the_original() {
        let o = [[1.0, 1.0, 1.0]];
        let l = Limits::new(None, Some(0.5), &o).expect("bound given");
        let p = l.apply(0, [1.0; 3], [1.0, 4.0, 1.0]);
        assert!((p[1] - 1.5).abs() < 1e-6 && p[0] == 1.0 && p[2] == 1.0);
        // Inside the ball nothing changes.
        assert_eq!(l.apply(0, [1.0; 3], [1.2, 1.0, 1.0]), [1.2, 1.0, 1.0]);
    }

    #[test]
    fn odd_inputs_stay_finite() {
        let o = [[0.0; 3]];
        assert!(Limits::new(None, None, &o).is_none());
        assert!(Limits::new(None, Some(f32::INFINITY), &o).is_none());
        let w = [f32::NAN];
        let l = Limits::new(Some(&w), Some(f32::NAN), &o).expect("weights given");
        assert_eq!(l.apply(0, [0.0; 3], [3.0, 0.0, 0.0]), [0.0; 3]);
    }
}
