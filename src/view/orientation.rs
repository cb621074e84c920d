//! Which side a mesh is first shown from.
//!
//! A flat mesh (a vessel's bend, a ring, a skull cap) shows its shape face-on, along its thinnest
//! axis: the bundled bent tube seen from the fixed default direction is a featureless blob,
//! face-on it is the bend it is. A rounder mesh (a head, a hemisphere, a bone end) keeps the
//! anatomical default.

use super::OrbitCamera;
use glam::{DMat3, DVec3, Vec3};

/// Points are flat when their spread (standard deviation) along the thinnest principal axis is
/// below this fraction of the spread along the middle one. Measured: the fsaverage scalp 0.84,
/// the 30x20x12 ellipsoid 0.66, the fsaverage5 pial hemisphere 0.64, the bundled bent tube 0.33,
/// the torus 0.31.
const FLAT: f64 = 0.5;

/// The direction (unit, from the points towards the eye) to show flat points from: their thinnest
/// principal axis, on the side nearer `default`. `None` when the points are not flat, or fewer
/// than 3 are finite.
pub fn face_on_direction(points: &[[f32; 3]], default: Vec3) -> Option<Vec3> {
    let (flatness, axis) = thinnest_axis(points)?;
    if flatness >= FLAT {
        return None;
    }
    Some(if axis.dot(default) < 0.0 { -axis } else { axis })
}

/// The camera a mesh is first shown with: from [`face_on_direction`] when the points are flat,
/// else from the default direction, fitted to the points (what the 3D view does on opening a
/// model; thumbnails use it to frame a mesh the same way).
pub fn first_view(points: &[[f32; 3]]) -> OrbitCamera {
    let mut camera = OrbitCamera::default();
    if let Some(side) = face_on_direction(points, camera.direction()) {
        camera.look_from(side);
    }
    camera.fit_points(points);
    camera
}

/// The points' thinnest principal axis (unit) and its spread relative to the middle axis's
/// (0 for points in a plane, 1 when no axis is thinnest). `None` with fewer than 3 finite
/// points or when they lie on a line or a point.
fn thinnest_axis(points: &[[f32; 3]]) -> Option<(f64, Vec3)> {
    let finite = || {
        points
            .iter()
            .map(|&p| Vec3::from(p).as_dvec3())
            .filter(|p| p.is_finite())
    };
    let count = finite().count();
    if count < 3 {
        return None;
    }
    let mean = finite().sum::<DVec3>() / count as f64;
    let covariance = finite().fold(DMat3::ZERO, |sum, p| {
        let d = p - mean;
        sum + DMat3::from_cols(d * d.x, d * d.y, d * d.z)
    }) / count as f64;
    let (values, vectors) = symmetric_eigen(covariance);
    // Ascending eigenvalues: thinnest, middle, widest.
    let mut order = [0, 1, 2];
    order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    let (thin, middle) = (values[order[0]].max(0.0), values[order[1]]);
    if middle.is_nan() || middle <= 0.0 {
        return None;
    }
    let axis = vectors.col(order[0]).normalize().as_vec3();
    Some(((thin / middle).sqrt(), axis))
}

/// Eigenvalues and eigenvectors (the columns) of a symmetric 3x3 matrix by cyclic Jacobi
/// rotations, which converge quadratically and never produce NaN for finite input.
fn symmetric_eigen(m: DMat3) -> ([f64; 3], DMat3) {
    let (mut a, mut v) = (m, DMat3::IDENTITY);
    let at = |a: &DMat3, row: usize, col: usize| a.col(col)[row];
    for _ in 0..32 {
        let off = at(&a, 0, 1).powi(2) + at(&a, 0, 2).powi(2) + at(&a, 1, 2).powi(2);
        let diagonal = (0..3).map(|k| at(&a, k, k).powi(2)).sum::<f64>();
        if off <= 1e-24 * diagonal.max(f64::MIN_POSITIVE) {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            let apq = at(&a, p, q);
            if apq == 0.0 {
                continue;
            }
            // The rotation in the (p, q) plane that zeroes a[p][q].
            let theta = (at(&a, q, q) - at(&a, p, p)) / (2.0 * apq);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            let mut j = DMat3::IDENTITY;
            j.col_mut(p)[p] = c;
            j.col_mut(q)[q] = c;
            j.col_mut(q)[p] = s;
            j.col_mut(p)[q] = -s;
            a = j.transpose() * a * j;
            v *= j;
        }
    }
    ([at(&a, 0, 0), at(&a, 1, 1), at(&a, 2, 2)], v)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_parallel(a: Vec3, b: Vec3) {
        assert!(a.normalize().dot(b.normalize()) > 0.999, "{a} vs {b}");
    }

    #[test]
    fn eigenvectors_of_a_rotated_diagonal_matrix() {
        let rotation = glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 0.7);
        let r = DMat3::from_quat(rotation);
        let m = r * DMat3::from_diagonal(DVec3::new(9.0, 4.0, 1.0)) * r.transpose();
        let (values, vectors) = symmetric_eigen(m);
        for (value, expected_column) in [(9.0, 0), (4.0, 1), (1.0, 2)] {
            let k = values
                .iter()
                .position(|&v| (v - value).abs() < 1e-9)
                .unwrap_or_else(|| panic!("eigenvalue {value} missing from {values:?}"));
            let found = vectors.col(k);
            let expected = r.col(expected_column);
            assert!(
                found.dot(expected).abs() > 1.0 - 1e-9,
                "{found} vs {expected}"
            );
            assert!((m * found - value * found).length() < 1e-9);
        }
    }

    #[test]
    fn a_flat_disc_is_seen_face_on_from_the_default_side() {
        // A disc of radius 10 and thickness 1 in the plane with normal n.
        let n = Vec3::new(0.3, -0.5, 0.8).normalize();
        let u = n.any_orthonormal_vector();
        let w = n.cross(u);
        let mut points = Vec::new();
        for i in 0..40 {
            for j in 0..5 {
                let a = i as f32 * 0.157;
                let r = 2.0 * j as f32;
                let h = (j as f32 - 2.0) * 0.25;
                points.push((r * a.cos() * u + r * a.sin() * w + h * n).to_array());
            }
        }
        let towards = Vec3::new(0.0, 0.0, 1.0);
        let seen_from = face_on_direction(&points, towards).expect("flat");
        assert_parallel(seen_from, n);
        // The other default side gives the other face.
        let seen_from = face_on_direction(&points, -towards).expect("flat");
        assert_parallel(seen_from, -n);
    }

    #[test]
    fn the_bundled_sample_is_flat_and_seen_face_on() {
        let bytes = include_bytes!("../../tests/data/bent_tube_staircase.ply");
        let mesh = crate::io::load(bytes, "bent_tube_staircase.ply").expect("the sample loads");
        let (flatness, axis) = thinnest_axis(&mesh.positions).expect("an axis");
        assert!(flatness < 0.4, "flatness {flatness}");
        let default = Vec3::new(-0.5, 0.8, 0.3);
        let side = face_on_direction(&mesh.positions, default).expect("face-on");
        assert!(side.dot(default) >= 0.0);
        assert_parallel(side.abs(), axis.abs());
    }

    #[test]
    fn round_or_degenerate_points_keep_the_default() {
        let cube: Vec<[f32; 3]> = (0..27)
            .map(|i| [(i % 3) as f32, ((i / 3) % 3) as f32, (i / 9) as f32])
            .collect();
        assert_eq!(face_on_direction(&cube, Vec3::Y), None);
        assert_eq!(face_on_direction(&[[0.0; 3], [1.0; 3]], Vec3::Y), None);
        assert_eq!(face_on_direction(&[[2.0; 3]; 10], Vec3::Y), None);
        assert_eq!(face_on_direction(&[[f32::NAN; 3]; 10], Vec3::Y), None);
        // A straight line has no thinnest side either (two equal zero spreads).
        let line: Vec<[f32; 3]> = (0..10).map(|i| [i as f32, 0.0, 0.0]).collect();
        assert_eq!(face_on_direction(&line, Vec3::Y), None);
    }
}
