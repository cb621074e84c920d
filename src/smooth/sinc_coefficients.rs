//! Chebyshev coefficients of the windowed-sinc low-pass (Taubin 1996) as VTK's
//! vtkWindowedSincPolyDataFilter chooses them.
//!
//! The filter is `f(k) = sum_{n=0}^{N} c_n T_n(1 - k/2)` over the Laplacian's frequencies
//! `k` in [0, 2], with `c_n = w_n * s_n`:
//! - `s_0 = (theta + sigma) / pi`, `s_n = 2 sin(n (theta + sigma)) / (n pi)`: the ideal low-pass
//!   with cut-off `theta = acos(1 - passband / 2)`, widened by the offset `sigma`;
//! - `w_n`: the Nuttall window (VTK's default) over `n = 0..=N`, falling to zero at `N + 1`;
//! - `sigma`: chosen so that the pass-band edge passes at unit gain, `f(passband) ~ 1`, by the
//!   Newton-like search VTK runs from `sigma = 0` (within 1e-3, at most 500 steps).
//!
//! These choices were settled by measuring VTK 9.7's frequency response on a mesh's Laplacian
//! eigenvectors: this construction reproduces it to 2e-8 (`tests/peers/sinc_reference.py`
//! checks the whole filter against VTK).

use std::f64::consts::PI;

/// Nuttall window terms (a0..a3), the window VTK uses by default.
const NUTTALL: [f64; 4] = [0.355768, 0.487396, 0.144232, 0.012604];
/// The search stops once the pass-band gain is this close to 1.
const GAIN_TOLERANCE: f64 = 1e-3;
const MAX_SEARCH_STEPS: usize = 500;
/// A found sigma is kept only if the gain at frequency 0 is this close to 1.
const DC_TOLERANCE: f64 = 1e-2;

/// The coefficients `c_0..=c_N` for `iterations = N` and `passband` in (0, 2).
///
/// Where VTK's search for `sigma` fails (every `N = 1`, and some passbands for `N <= 4`), or
/// ends at a sigma whose gain at frequency 0 is off by more than 1%, VTK warns and smooths with whatever the search left, which can blow the mesh up or shrink it
/// towards its centre. There we take `sigma = 0` and scale the coefficients to unit gain at
/// `k = 0`, so a rigid translation passes unchanged and the mesh neither grows nor shrinks
/// as a whole.
pub(crate) fn sinc_coefficients(iterations: u32, passband: f32) -> Vec<f64> {
    let n = iterations as usize;
    // Out-of-range passbands (Params::validate refuses them) are clamped rather than turned
    // into NaN by acos.
    let passband = (passband as f64).clamp(1e-9, 2.0);
    let theta = (1.0 - 0.5 * passband).acos();
    let window: Vec<f64> = (0..=n)
        .map(|i| {
            let x = PI * i as f64 / (n + 1) as f64;
            NUTTALL
                .iter()
                .enumerate()
                .map(|(m, a)| a * (m as f64 * x).cos())
                .sum()
        })
        .collect();
    let coefficients = |sigma: f64| -> Vec<f64> {
        window
            .iter()
            .enumerate()
            .map(|(i, w)| {
                let t = theta + sigma;
                w * if i == 0 {
                    t / PI
                } else {
                    2.0 * (i as f64 * t).sin() / (i as f64 * PI)
                }
            })
            .collect()
    };
    // T_i at the pass-band edge x = cos(theta) is cos(i theta).
    let chebyshev_at_edge: Vec<f64> = (0..=n).map(|i| (i as f64 * theta).cos()).collect();
    let at_edge = |c: &[f64]| -> f64 { c.iter().zip(&chebyshev_at_edge).map(|(a, t)| a * t).sum() };

    let mut sigma = 0.0;
    let mut c = coefficients(sigma);
    let mut found = false;
    if n >= 2 {
        for _ in 0..MAX_SEARCH_STEPS {
            let gain = at_edge(&c);
            if (gain - 1.0).abs() < GAIN_TOLERANCE {
                found = true;
                break;
            }
            // The step divides by the series' derivative in x (not in sigma), computed without
            // its top term, exactly as VTK steps: it converges where VTK's does, to its sigma.
            let slope = at_edge(&derivative_series(&c));
            let next = sigma - (gain - 1.0) / slope;
            if !next.is_finite() {
                break;
            }
            sigma = next;
            c = coefficients(sigma);
        }
    }
    // A search that wandered off to a huge sigma can meet the tolerance by accident; the gain at
    // k = 0 (the plain sum, as every T_n(1) = 1) then lies far from 1. Where VTK's search
    // genuinely converges it lies within 1e-3.
    let dc: f64 = c.iter().sum();
    if !found || (dc - 1.0).abs() > DC_TOLERANCE {
        c = coefficients(0.0);
        let dc: f64 = c.iter().sum();
        for x in &mut c {
            *x /= dc;
        }
    }
    c
}

/// Chebyshev series of the x-derivative of `sum c_n T_n(x)`, by the usual backward recurrence
/// `d_k = d_{k+2} + 2 (k + 1) c_{k+1}`, started with `d_N = d_{N-1} = 0` (VTK's start, which
/// leaves out the `c_N` term) and with `d_0` not halved. `c.len() >= 3`.
fn derivative_series(c: &[f64]) -> Vec<f64> {
    let n = c.len() - 1;
    let mut d = vec![0.0; n + 1];
    for k in (0..=n - 2).rev() {
        d[k] = d.get(k + 2).copied().unwrap_or(0.0) + 2.0 * (k + 1) as f64 * c[k + 1];
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    fn response(c: &[f64], k: f64) -> f64 {
        let x = (1.0 - 0.5 * k).clamp(-1.0, 1.0).acos();
        c.iter()
            .enumerate()
            .map(|(i, a)| a * (i as f64 * x).cos())
            .sum()
    }

    #[test]
    fn vtk_default_filter_has_the_measured_offset() {
        // VTK 9.7, 20 iterations, passband 0.1: the fitted response has sigma = 0.4647048,
        // i.e. c_0 = w_0 (theta + sigma) / pi with w_0 = 1.
        let c = sinc_coefficients(20, 0.1);
        let theta = (1.0f64 - 0.05).acos();
        let sigma = c[0] * PI - theta;
        assert!((sigma - 0.4647048).abs() < 1e-6, "sigma {sigma}");
        assert!((response(&c, 0.1) - 1.0).abs() < GAIN_TOLERANCE);
        // A low-pass: near-unit gain at k = 0, strong attenuation well above the pass band.
        assert!((response(&c, 0.0) - 1.0).abs() < 1e-3);
        assert!(response(&c, 1.4).abs() < 0.01);
    }

    #[test]
    fn every_setting_gives_a_finite_low_pass() {
        let passbands = [
            0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 1.5, 1.99,
        ];
        for n in 1..=100 {
            for &pb in &passbands {
                let c = sinc_coefficients(n, pb);
                assert_eq!(c.len(), n as usize + 1);
                assert!(c.iter().all(|x| x.is_finite()), "n {n} pb {pb}");
                let dc = response(&c, 0.0);
                assert!((dc - 1.0).abs() < 2e-3, "n {n} pb {pb}: gain at 0 is {dc}");
            }
        }
    }

    #[test]
    fn failed_search_falls_back_to_unit_gain() {
        // One iteration: there is nothing to search (VTK shrinks the mesh here).
        let c = sinc_coefficients(1, 0.1);
        assert!((c.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        // Two iterations: VTK's search diverges for many passbands (chaotically: which ones
        // depends on the last bit of the passband). Either the search met its tolerance or the
        // fallback holds unit gain; both fallbacks happen on this grid.
        let mut fallbacks = 0;
        for step in 1..200 {
            let pb = step as f32 * 0.01;
            let c = sinc_coefficients(2, pb);
            let dc: f64 = c.iter().sum();
            if (dc - 1.0).abs() < 1e-12 {
                fallbacks += 1;
            } else {
                let theta = (1.0 - 0.5 * pb as f64).acos();
                let edge: f64 = (0..3).map(|i| c[i] * (i as f64 * theta).cos()).sum();
                assert!((edge - 1.0).abs() < GAIN_TOLERANCE, "pb {pb}");
                assert!((dc - 1.0).abs() <= DC_TOLERANCE, "pb {pb}");
            }
        }
        assert!(fallbacks > 0 && fallbacks < 199, "{fallbacks} fallbacks");
    }

    #[test]
    fn derivative_series_differentiates_below_the_top_term() {
        // c = T_0 + T_1 + T_2 + T_3; d/dx without the T_3 term is d/dx (x + 2x^2 - 1) = 1 + 4x,
        // which is d_0 / 2 + 4 T_1 with d_0 = 2 (left unhalved).
        let d = derivative_series(&[1.0, 1.0, 1.0, 1.0]);
        assert_eq!(d, vec![2.0, 4.0, 0.0, 0.0]);
    }
}
