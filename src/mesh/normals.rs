//! Area-weighted vertex normals.

use super::{cross, sub, to_f64};

/// Unit vertex normals weighted by incident triangle area (the unnormalised cross product).
/// Vertices with no incident area get `[0, 0, 0]` rather than NaN.
pub fn vertex_normals(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<[f32; 3]> {
    let mut acc = vec![[0.0f64; 3]; positions.len()];
    for t in triangles {
        let a = to_f64(positions[t[0] as usize]);
        let b = to_f64(positions[t[1] as usize]);
        let c = to_f64(positions[t[2] as usize]);
        let n = cross(sub(b, a), sub(c, a));
        for &v in t {
            let s = &mut acc[v as usize];
            s[0] += n[0];
            s[1] += n[1];
            s[2] += n[2];
        }
    }
    acc.iter()
        .map(|n| {
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if len > 0.0 && len.is_finite() {
                [
                    (n[0] / len) as f32,
                    (n[1] / len) as f32,
                    (n[2] / len) as f32,
                ]
            } else {
                [0.0; 3]
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_quad_points_up_and_isolated_vertex_is_zero() {
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [5.0; 3],
        ];
        let n = vertex_normals(&p, &[[0, 1, 2], [0, 2, 3]]);
        for v in &n[..4] {
            assert_eq!(*v, [0.0, 0.0, 1.0]);
        }
        assert_eq!(n[4], [0.0; 3]);
    }
}
