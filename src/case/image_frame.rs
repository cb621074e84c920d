//! Whether an image belongs under a case's surfaces, from where it lies against the voxel grids
//! the structures were extracted on. An image with a grid's own voxel steps (the CT the
//! segmentation was drawn on) must share its lattice: a fraction of a voxel off is a wrong image
//! or a reader's wrong convention, refused with the offset. An image on another grid (an MRI at
//! its own resolution beside FreeSurfer's conformed `aseg`, the CT under a segmentation that 3D
//! Slicer oversampled) must cover the structures; the viewer samples it where they lie.

use serde::{Deserialize, Serialize};

use crate::io::{Affine, ImageVolume};

/// A voxel grid some of a case's structures were extracted on, and where they lie on it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StructureGrid {
    /// The first structure on it, named when an image is refused.
    pub structure: String,
    pub grid: Affine,
    /// The box of voxel indices (least, greatest along i, j, k) that the structures' surfaces
    /// span; `None` before any vertex.
    pub extent: Option<[[f64; 3]; 2]>,
}

impl StructureGrid {
    pub fn new(structure: &str, grid: Affine) -> Self {
        StructureGrid {
            structure: structure.to_string(),
            grid,
            extent: None,
        }
    }

    /// Widens the extent to take in `points` (RAS mm).
    pub fn span(&mut self, points: &[[f32; 3]]) {
        for p in points {
            let Some(at) = self.grid.inverse_apply(p.map(f64::from)) else {
                return;
            };
            let [lo, hi] = self.extent.get_or_insert([at, at]);
            for k in 0..3 {
                lo[k] = lo[k].min(at[k]);
                hi[k] = hi[k].max(at[k]);
            }
        }
    }
}

/// Refuses an image that does not belong under the structures on `on` (see the module's
/// comment), with the reason.
pub fn check_frame(image: &ImageVolume, on: &StructureGrid) -> Result<(), String> {
    if same_steps(&image.source_affine, &on.grid) {
        check_lattice(image, &on.grid)
    } else {
        check_cover(image, on)
    }
}

/// Whether two grids step alike along each voxel axis, to a twentieth of the smaller voxel.
fn same_steps(a: &Affine, b: &Affine) -> bool {
    let smallest = (a.spacing().into_iter())
        .chain(b.spacing())
        .fold(f64::INFINITY, f64::min);
    (0..3).all(|c| {
        let d2: f64 = (0..3).map(|r| (a.0[r][c] - b.0[r][c]).powi(2)).sum();
        d2.sqrt() <= 0.05 * smallest
    })
}

/// Refuses an image on another grid than `on`'s that leaves some of its structures' box
/// outside, by more than half a segmentation voxel (surfaces at a field of view's edge).
fn check_cover(image: &ImageVolume, on: &StructureGrid) -> Result<(), String> {
    let Some([lo, hi]) = on.extent else {
        return Ok(());
    };
    let (affine, dims) = (&image.source_affine, image.source_dims);
    let spacing = affine.spacing();
    let grid_spacing = on.grid.spacing();
    let slack = 0.5 * grid_spacing.into_iter().fold(0.0, f64::max);
    let mut beyond = 0.0f64;
    for corner in 0..8 {
        let ijk = std::array::from_fn(|k| if corner >> k & 1 == 0 { lo[k] } else { hi[k] });
        let at = (affine.inverse_apply(on.grid.apply(ijk)))
            .ok_or("the image's affine is not invertible")?;
        for k in 0..3 {
            let out = (-0.5 - at[k]).max(at[k] - (dims[k] as f64 - 0.5));
            beyond = beyond.max(out * spacing[k]);
        }
    }
    if beyond <= slack {
        return Ok(());
    }
    let mm = |s: [f64; 3]| format!("{:.3} x {:.3} x {:.3} mm", s[0], s[1], s[2]);
    Err(format!(
        "the image, on another voxel grid ({} voxels; the segmentation's {}), does not cover \
         the segmentation: its structures reach {beyond:.1} mm beyond the image",
        mm(spacing),
        mm(grid_spacing)
    ))
}

/// Refuses an image on `grid`'s steps whose lattice is not the grid's shifted by whole voxels.
/// It may cover more or less than the segmentation (a CT cropped to the body, a 3D Slicer
/// segmentation cropped to its segments). Names the largest offset found at the image's corners
/// from the grid's nearest voxels.
fn check_lattice(image: &ImageVolume, grid: &Affine) -> Result<(), String> {
    let [di, dj, dk] = image.source_dims.map(|d| d.saturating_sub(1) as f64);
    let corners = [
        [0.0, 0.0, 0.0],
        [di, 0.0, 0.0],
        [0.0, dj, 0.0],
        [0.0, 0.0, dk],
        [di, dj, dk],
    ];
    let smallest = (image.source_affine.spacing().into_iter())
        .chain(grid.spacing())
        .fold(f64::INFINITY, f64::min);
    let tolerance = 0.05 * smallest;
    // Where the image's first voxel falls on the grid, to the nearest whole voxel.
    let shift = (grid.inverse_apply(image.source_affine.apply([0.0; 3])))
        .filter(|at| at.iter().all(|x| x.is_finite()))
        .map_or([0.0; 3], |at| at.map(f64::round));
    let (worst, corner, offset) = (corners.iter())
        .map(|c| {
            let a = image.source_affine.apply(*c);
            let b = grid.apply(std::array::from_fn(|k| c[k] + shift[k]));
            let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
            ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt(), *c, d)
        })
        .fold((0.0, [0.0; 3], [0.0; 3]), |best, x| {
            if x.0 > best.0 {
                x
            } else {
                best
            }
        });
    if worst <= tolerance {
        return Ok(());
    }
    Err(format!(
        "the image does not lie on the segmentation's voxel grid: its voxel ({}, {}, {}) is \
         {worst:.3} mm from the segmentation's (offset {:.3}, {:.3}, {:.3} mm, RAS)",
        corner[0], corner[1], corner[2], offset[0], offset[1], offset[2]
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn volume(dims: [usize; 3], affine: Affine) -> ImageVolume {
        ImageVolume {
            dims,
            affine,
            values: vec![0.0; dims.iter().product()],
            source_dims: dims,
            source_affine: affine,
        }
    }

    /// `grid` with its structures spanning voxels `lo` to `hi`.
    fn spanning(grid: Affine, lo: [f64; 3], hi: [f64; 3]) -> StructureGrid {
        let mut on = StructureGrid::new("liver", grid);
        on.span(&[grid.apply(lo), grid.apply(hi)].map(|p| p.map(|x| x as f32)));
        on
    }

    #[test]
    fn an_image_off_the_segmentation_lattice_is_refused_with_its_offset_a_crop_is_not() {
        let grid = Affine::scaled([1.5, 1.5, 3.0], [-100.0, -80.0, 20.0]);
        let on = spanning(grid, [0.0; 3], [9.0, 9.0, 4.0]);
        let same = volume([10, 10, 5], grid);
        assert_eq!(check_frame(&same, &on), Ok(()));
        let moved = volume(
            [10, 10, 5],
            Affine::scaled([1.5, 1.5, 3.0], [-100.0, -67.5, 20.0]),
        );
        let error = check_frame(&moved, &on).expect_err("moved");
        // 12.5 mm is 8 1/3 voxels: a third of a voxel from the nearest.
        assert!(
            error.starts_with("the image does not lie on") && error.contains("0.500 mm"),
            "{error}"
        );
        assert!(error.contains("offset 0.000, 0.500, 0.000 mm"), "{error}");
        // A crop of the grid (or the grid a crop of the image) lies on it: whole voxels apart.
        let cropped = volume(
            [4, 6, 2],
            Affine::scaled([1.5, 1.5, 3.0], [-97.0, -74.0, 26.0]),
        );
        assert_eq!(check_frame(&cropped, &on), Ok(()));
        assert_eq!(
            check_frame(
                &same,
                &spanning(cropped.source_affine, [0.0; 3], [3.0, 5.0, 1.0])
            ),
            Ok(())
        );
        // Half a voxel off the lattice, it does not.
        let half = volume(
            [4, 6, 2],
            Affine::scaled([1.5, 1.5, 3.0], [-97.75, -74.0, 26.0]),
        );
        let error = check_frame(&half, &on).expect_err("half a voxel");
        assert!(error.contains("0.750 mm"), "{error}");
    }

    #[test]
    fn an_image_on_another_grid_must_cover_the_structures() {
        let grid = Affine::scaled([1.5, 1.5, 3.0], [-100.0, -80.0, 20.0]);
        // Surfaces half a voxel beyond the voxels labelled, from (1, 1, 1) to (8, 8, 3).
        let on = spanning(grid, [0.5; 3], [8.5, 8.5, 3.5]);
        // The same field of view (-100.75 .. -85.75, -80.75 .. -65.75, 18.5 .. 33.5 mm) in
        // finer voxels, and a finer image cropped to the structures, cover them.
        let finer = volume(
            [20, 20, 10],
            Affine::scaled([0.75, 0.75, 1.5], [-100.375, -80.375, 19.25]),
        );
        assert_eq!(check_frame(&finer, &on), Ok(()));
        let cropped = volume(
            [16, 16, 6],
            Affine::scaled([0.75, 0.75, 1.5], [-98.875, -78.875, 22.25]),
        );
        assert_eq!(check_frame(&cropped, &on), Ok(()));
        // Turned a quarter about the superior axis, it covers them too.
        let mut turned = finer.clone();
        turned.source_affine = Affine([
            [0.0, -0.75, 0.0, -85.375],
            [0.75, 0.0, 0.0, -80.375],
            [0.0, 0.0, 1.5, 19.25],
        ]);
        assert_eq!(check_frame(&turned, &on), Ok(()));
        // Cropped 3 mm short of the structures' top, it does not, and says by how much.
        let short = volume(
            [20, 20, 6],
            Affine::scaled([0.75, 0.75, 1.5], [-100.375, -80.375, 19.25]),
        );
        let error = check_frame(&short, &on).expect_err("short");
        assert!(
            error.starts_with("the image, on another voxel grid (0.750 x 0.750 x 1.500 mm voxels; the segmentation's 1.500 x 1.500 x 3.000 mm)")
                && error.ends_with("reach 3.0 mm beyond the image"),
            "{error}"
        );
    }
}
