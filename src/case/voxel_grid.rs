//! A label map's staircase lies on its voxel grid: each vertex at the midpoint of a voxel edge
//! (marching cubes at the binary mask's level 0.5). A quantized file moves it by less than a
//! quarter voxel, so the reader puts it back exactly where extraction placed it, and a reopened
//! case smooths from the same original.

use crate::io::Affine;

/// `points` moved to their nearest edge midpoints of `grid` (computed as extraction computes
/// them), when every point lies within `tolerance` mm of its midpoint; else `None`, and the
/// points are not a staircase of this grid.
pub fn on_grid(points: &[[f32; 3]], grid: &Affine, tolerance: f64) -> Option<Vec<[f32; 3]>> {
    points
        .iter()
        .map(|p| {
            let index = grid.inverse_apply(p.map(f64::from))?;
            // Two whole coordinates and a half one: the nearest multiples of a half.
            let snapped = index.map(|v| (2.0 * v).round() / 2.0);
            let halves = snapped.iter().filter(|v| v.fract() != 0.0).count();
            // Extraction's index is f32 (whole coordinates minus one, plus a half), then
            // placed in f64 and rounded once.
            let q = grid
                .apply(snapped.map(|v| f64::from(v as f32)))
                .map(|c| c as f32);
            let moved = (0..3)
                .map(|k| (f64::from(q[k]) - f64::from(p[k])).powi(2))
                .sum::<f64>()
                .sqrt();
            (halves == 1 && moved <= tolerance).then_some(q)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn oblique() -> Affine {
        let (c, s) = (0.8f64, 0.6f64);
        Affine([
            [0.7 * c, -0.7 * s, 0.0, -120.25],
            [0.7 * s, 0.7 * c, 0.0, 33.5],
            [0.0, 0.0, -2.5, 410.0],
        ])
    }

    #[test]
    fn a_staircase_moved_within_a_tenth_of_a_voxel_snaps_back_exactly() {
        let grid = oblique();
        let exact: Vec<[f32; 3]> = [[3.5, 4.0, 7.0], [10.0, 0.5, 2.0], [0.0, 1.0, 11.5]]
            .iter()
            .map(|i| grid.apply(*i).map(|c| c as f32))
            .collect();
        let moved: Vec<[f32; 3]> = (exact.iter())
            .map(|p| [p[0] + 0.04, p[1] - 0.03, p[2] + 0.05])
            .collect();
        assert_eq!(on_grid(&moved, &grid, 0.1), Some(exact.clone()));
        // Farther than the stated tolerance: not this grid's staircase.
        assert_eq!(on_grid(&moved, &grid, 0.01), None);
    }

    #[test]
    fn points_that_are_not_edge_midpoints_stay_as_read() {
        let grid = oblique();
        // A voxel's centre (three whole coordinates) and a face centre (two halves).
        for index in [[3.0, 4.0, 7.0], [3.5, 4.5, 7.0]] {
            let p = [grid.apply(index).map(|c| c as f32)];
            assert_eq!(on_grid(&p, &grid, 0.5), None);
        }
    }
}
