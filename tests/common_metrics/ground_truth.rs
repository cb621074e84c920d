//! Analytic signed distances to the synthetic shapes (a port of ../shared/data/synthetic/
//! ground_truth.py), read from ground_truth.json. Millimetres, negative inside.
#![allow(dead_code)]

use serde::Deserialize;
use std::collections::BTreeMap;
use std::f64::consts::PI;

#[derive(Debug, Deserialize)]
pub struct GroundTruth {
    pub shapes: BTreeMap<String, Shape>,
}

/// The staircase mesh's distance to the analytic surface, as the data set states it.
#[derive(Debug, Deserialize)]
pub struct MeshError {
    pub mean_abs: f64,
    pub rms: f64,
    pub max_abs: f64,
    pub mean_signed: f64,
}

#[derive(Debug, Deserialize)]
pub struct Shape {
    #[serde(rename = "type")]
    pub kind: String,
    pub center: [f64; 3],
    /// Maps local to world: `p = center + rotation q`.
    #[serde(default = "identity")]
    pub rotation: [[f64; 3]; 3],
    pub radius: Option<f64>,
    pub major_radius: Option<f64>,
    pub minor_radius: Option<f64>,
    pub bend_radius: Option<f64>,
    pub tube_radius: Option<f64>,
    pub arc_phi0: Option<f64>,
    pub arc_phi1: Option<f64>,
    pub semi_axes: Option<[f64; 3]>,
    /// Exact volume of the analytic shape.
    pub volume: f64,
    pub mesh_volume: f64,
    pub mc_mesh_error_vs_analytic: MeshError,
}

fn identity() -> [[f64; 3]; 3] {
    [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
}

pub fn load() -> GroundTruth {
    let bytes = crate::data::read("synthetic/ground_truth.json");
    serde_json::from_slice(&bytes).expect("ground_truth.json parses")
}

fn need(v: Option<f64>, what: &str) -> f64 {
    v.unwrap_or_else(|| panic!("shape lacks {what}"))
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

impl Shape {
    /// Local coordinates `R^T (p - c)`.
    fn local(&self, p: [f64; 3]) -> [f64; 3] {
        let d = [
            p[0] - self.center[0],
            p[1] - self.center[1],
            p[2] - self.center[2],
        ];
        let r = &self.rotation;
        [0, 1, 2].map(|j| d[0] * r[0][j] + d[1] * r[1][j] + d[2] * r[2][j])
    }

    /// Signed distance from `p` to the analytic surface (negative inside).
    pub fn signed_distance(&self, p: [f64; 3]) -> f64 {
        let q = self.local(p);
        match self.kind.as_str() {
            "sphere" => norm(q) - need(self.radius, "radius"),
            "torus" => {
                let rho = q[0].hypot(q[1]);
                (rho - need(self.major_radius, "major_radius")).hypot(q[2])
                    - need(self.minor_radius, "minor_radius")
            }
            "arc_tube" => self.arc_tube(q),
            "ellipsoid" => self.ellipsoid(q),
            other => panic!("unknown shape type {other}"),
        }
    }

    /// All points within `tube_radius` of a circular arc in the local xy plane.
    fn arc_tube(&self, q: [f64; 3]) -> f64 {
        let rb = need(self.bend_radius, "bend_radius");
        let r = need(self.tube_radius, "tube_radius");
        let (phi0, phi1) = (
            need(self.arc_phi0, "arc_phi0"),
            need(self.arc_phi1, "arc_phi1"),
        );
        let phi = q[1].atan2(q[0]);
        // numpy's mod takes the divisor's sign: the angle relative to phi0 in [0, 2 pi).
        let rel = (phi - phi0).rem_euclid(2.0 * PI);
        let d = if rel <= phi1 - phi0 {
            (q[0].hypot(q[1]) - rb).hypot(q[2])
        } else {
            let end = |a: f64| norm([q[0] - rb * a.cos(), q[1] - rb * a.sin(), q[2]]);
            end(phi0).min(end(phi1))
        };
        d - r
    }

    /// Exact closest point by bisection on `sum (a_i y_i / (t + a_i^2))^2 = 1`, as the Python does.
    fn ellipsoid(&self, q: [f64; 3]) -> f64 {
        let a = self.semi_axes.expect("ellipsoid lacks semi_axes");
        let a2 = a.map(|x| x * x);
        let f = |t: f64| -> f64 {
            (0..3)
                .map(|i| (a[i] * q[i] / (t + a2[i])).powi(2))
                .sum::<f64>()
                - 1.0
        };
        let a2_min = a2.iter().copied().fold(f64::INFINITY, f64::min);
        let a_max = a.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let mut lo = -a2_min + 1e-12;
        let mut hi = norm(q) * a_max + 1.0;
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if f(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let t = 0.5 * (lo + hi);
        let x = [0, 1, 2].map(|i| a2[i] * q[i] / (t + a2[i]));
        let d = norm([q[0] - x[0], q[1] - x[1], q[2] - x[2]]);
        let inside = (0..3).map(|i| (q[i] / a[i]).powi(2)).sum::<f64>() < 1.0;
        if inside {
            -d
        } else {
            d
        }
    }
}

/// Distance statistics of a point set against a shape.
#[derive(Clone, Copy, Debug)]
pub struct TrueError {
    pub mean_abs: f64,
    pub rms: f64,
    pub max_abs: f64,
    pub mean_signed: f64,
}

pub fn true_error(shape: &Shape, points: &[[f32; 3]]) -> TrueError {
    let (mut abs, mut sq, mut max, mut signed) = (0.0, 0.0, 0.0f64, 0.0);
    for p in points {
        let d = shape.signed_distance(p.map(|x| x as f64));
        abs += d.abs();
        sq += d * d;
        max = max.max(d.abs());
        signed += d;
    }
    let n = points.len().max(1) as f64;
    TrueError {
        mean_abs: abs / n,
        rms: (sq / n).sqrt(),
        max_abs: max,
        mean_signed: signed / n,
    }
}
