//! The image under the surfaces: the CT or MRI a segmentation was drawn on, carried in the case
//! as a student needs it (8-bit after a window the author chose), on the segmentation's own
//! world frame (`image_frame` checks it belongs there when it is added).

use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

use std::sync::Arc;

use super::file_name;
use super::image_frame::{check_frame, StructureGrid};
use crate::io::{load_image, load_image_series, Affine, ImageVolume};

/// The voxels an image is reduced to by default: what a phone's browser takes with the case.
pub const DEFAULT_IMAGE_VOXELS: usize = 16 << 20;

/// How intensities map to grey: `center - width / 2` is black, `center + width / 2` white.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Window {
    pub center: f32,
    pub width: f32,
}

/// The windows radiologists read with (CT in Hounsfield units; Radiopaedia's "Windowing (CT)"
/// article), and an automatic one for MRI, whose intensities have no fixed scale.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WindowPreset {
    CtSoftTissue,
    CtBone,
    CtLung,
    CtBrain,
    /// From the 1st to the 99th percentile of the image's intensities.
    MriAuto,
}

impl WindowPreset {
    pub const ALL: [WindowPreset; 5] = [
        WindowPreset::CtSoftTissue,
        WindowPreset::CtBone,
        WindowPreset::CtLung,
        WindowPreset::CtBrain,
        WindowPreset::MriAuto,
    ];

    pub fn name(self) -> &'static str {
        match self {
            WindowPreset::CtSoftTissue => "ct-soft-tissue",
            WindowPreset::CtBone => "ct-bone",
            WindowPreset::CtLung => "ct-lung",
            WindowPreset::CtBrain => "ct-brain",
            WindowPreset::MriAuto => "mri-auto",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }

    /// The window this preset gives `values`.
    pub fn window(self, values: &[f32]) -> Window {
        let fixed = |center: f32, width: f32| Window { center, width };
        match self {
            WindowPreset::CtSoftTissue => fixed(40.0, 400.0),
            WindowPreset::CtBone => fixed(400.0, 1800.0),
            WindowPreset::CtLung => fixed(-600.0, 1500.0),
            WindowPreset::CtBrain => fixed(40.0, 80.0),
            WindowPreset::MriAuto => {
                let (low, high) = percentiles(values, 0.01, 0.99);
                fixed((low + high) / 2.0, (high - low).max(f32::EPSILON))
            }
        }
    }
}

/// The image as the case carries it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CaseImage {
    /// The file it came from (its name only, never its header).
    pub source: String,
    /// Voxels along i, j, k (`i` fastest).
    pub dims: [usize; 3],
    /// Voxel centres to world RAS millimetres (the structures' frame).
    pub affine: Affine,
    /// Grey levels, 0 black to 255 white.
    pub voxels: Vec<u8>,
    /// The preset's name and the window the grey levels were made with.
    pub preset: String,
    pub window: Window,
}

impl CaseImage {
    /// `image` in grey levels after `preset`'s window.
    pub fn new(image: &ImageVolume, source: &str, preset: WindowPreset) -> Self {
        let window = preset.window(&image.values);
        let low = window.center - window.width / 2.0;
        let voxels = (image.values.iter())
            .map(|&v| (((v - low) / window.width).clamp(0.0, 1.0) * 255.0).round() as u8)
            .collect();
        CaseImage {
            source: source.to_string(),
            dims: image.dims,
            affine: image.affine,
            voxels,
            preset: preset.name().to_string(),
            window,
        }
    }

    /// The grey level at `world` (RAS mm), trilinear between voxel centres; `None` outside
    /// the image.
    pub fn sample(&self, world: [f64; 3]) -> Option<f32> {
        let p = self.affine.inverse_apply(world)?;
        let inside = (0..3).all(|a| p[a] >= -0.5 && p[a] <= self.dims[a] as f64 - 0.5);
        if !inside {
            return None;
        }
        let at = |i: usize, j: usize, k: usize| {
            self.voxels[(k * self.dims[1] + j) * self.dims[0] + i] as f64
        };
        let mut lo = [0usize; 3];
        let mut t = [0f64; 3];
        for a in 0..3 {
            let c = p[a].clamp(0.0, (self.dims[a] - 1) as f64);
            lo[a] = (c.floor() as usize).min(self.dims[a].saturating_sub(2));
            t[a] = c - lo[a] as f64;
        }
        let hi = |a: usize| (lo[a] + 1).min(self.dims[a] - 1);
        let mut sum = 0.0;
        for (di, wi) in [(lo[0], 1.0 - t[0]), (hi(0), t[0])] {
            for (dj, wj) in [(lo[1], 1.0 - t[1]), (hi(1), t[1])] {
                for (dk, wk) in [(lo[2], 1.0 - t[2]), (hi(2), t[2])] {
                    sum += wi * wj * wk * at(di, dj, dk);
                }
            }
        }
        Some(sum as f32)
    }

    /// Bytes the image adds to a case glTF.
    pub fn bytes(&self) -> usize {
        self.voxels.len()
    }

    /// What the case glTF's scene record says of the image; its voxels are buffer view
    /// `view`.
    pub fn record(&self, view: usize) -> Value {
        json!({
            "bufferView": view,
            "source": self.source,
            "dims": self.dims,
            "affine": self.affine.0,
            "preset": self.preset,
            "window": self.window,
        })
    }

    /// The image a case glTF's record describes, its voxels read from the view it names.
    pub fn from_record(record: &Value, voxels: Vec<u8>) -> Result<Self, String> {
        #[derive(Deserialize)]
        struct Record {
            source: String,
            dims: [usize; 3],
            affine: [[f64; 4]; 3],
            preset: String,
            window: Window,
        }
        let r = Record::deserialize(record).map_err(|e| e.to_string())?;
        let count = (r.dims.iter()).try_fold(1usize, |n, &d| n.checked_mul(d));
        if count != Some(voxels.len()) {
            return Err(format!(
                "{} x {} x {} voxels, but its buffer view holds {} bytes",
                r.dims[0],
                r.dims[1],
                r.dims[2],
                voxels.len()
            ));
        }
        let affine = Affine(r.affine);
        let finite = affine.0.iter().flatten().all(|v| v.is_finite());
        if !finite || affine.inverse_apply([0.0; 3]).is_none() {
            return Err("its affine is not an invertible, finite matrix".into());
        }
        if !(r.window.center.is_finite() && r.window.width.is_finite() && r.window.width > 0.0) {
            return Err("its window is not a finite centre and a positive width".into());
        }
        Ok(CaseImage {
            source: r.source,
            dims: r.dims,
            affine,
            voxels,
            preset: r.preset,
            window: r.window,
        })
    }
}

impl CaseImage {
    /// Reads the image `name`: one file (NIfTI, NRRD, MGH or a DICOM slice) or the slices of a
    /// DICOM series, `files` (name, bytes), `name` then their folder. Reduced to at most
    /// `max_voxels` and windowed by `preset`, after checking that it lies on each of `grids`: the
    /// grids a case's structures were extracted on, each with a structure's name
    /// ([`super::Case::image_grids`]). A refusal's reason leaves `name` to be named by the
    /// caller, and names the slice at fault, if one is.
    pub fn read(
        files: &[(&str, &[u8])],
        name: &str,
        preset: WindowPreset,
        max_voxels: usize,
        grids: &[StructureGrid],
    ) -> Result<Self, String> {
        if grids.is_empty() {
            return Err(
                "the case has no structure from a label map, so there is no segmentation grid \
                 to place the image on"
                    .to_string(),
            );
        }
        let image = match files {
            [(file, bytes)] => load_image(bytes, file, max_voxels).map_err(|e| e.to_string()),
            _ => load_image_series(files, max_voxels).map_err(|e| e.to_string()),
        }?;
        Self::placed(&image, name, preset, grids)
    }

    fn placed(
        image: &ImageVolume,
        name: &str,
        preset: WindowPreset,
        grids: &[StructureGrid],
    ) -> Result<Self, String> {
        for on in grids {
            check_frame(image, on).map_err(|e| match grids.len() {
                1 => e,
                _ => format!("{e}; the grid is {}'s", on.structure),
            })?;
        }
        Ok(CaseImage::new(image, file_name(name), preset))
    }
}

impl super::Case {
    /// Each distinct grid the structures were extracted on, with the first structure on it and
    /// where they all lie (a case may join label maps on different grids: an image must fit
    /// each).
    pub fn image_grids(&self) -> Vec<StructureGrid> {
        let mut grids: Vec<StructureGrid> = Vec::new();
        for s in &self.structures {
            let Some(grid) = s.grid else {
                continue;
            };
            let at = match grids.iter().position(|g| g.grid == grid) {
                Some(at) => at,
                None => {
                    grids.push(StructureGrid::new(&s.name, grid));
                    grids.len() - 1
                }
            };
            grids[at].span(&s.original.positions);
        }
        grids
    }

    /// Adds the image read from `files`: one file, or the slices of a DICOM series, named
    /// `name` ([`CaseImage::read`] on the case's grids), in place of the one it had. The case is
    /// unchanged when it is refused.
    pub fn add_image(
        &mut self,
        files: &[(&str, &[u8])],
        name: &str,
        preset: WindowPreset,
        max_voxels: usize,
    ) -> Result<(), String> {
        let image = CaseImage::read(files, name, preset, max_voxels, &self.image_grids())?;
        self.image = Some(Arc::new(image));
        Ok(())
    }
}

/// The values at two quantiles (`low < high` in [0, 1]), ignoring non-finite ones; two
/// selections in linear time rather than a sort.
fn percentiles(values: &[f32], low: f64, high: f64) -> (f32, f32) {
    let mut finite: Vec<f32> = values.iter().copied().filter(|v| v.is_finite()).collect();
    if finite.is_empty() {
        return (0.0, 1.0);
    }
    let rank = |q: f64| ((finite.len() - 1) as f64 * q).round() as usize;
    let (lo, hi) = (rank(low), rank(high));
    let (_, &mut at_hi, _) = finite.select_nth_unstable_by(hi, f32::total_cmp);
    // After the first selection everything below `hi` is no greater than its value.
    let (_, &mut at_lo, _) = finite[..=hi].select_nth_unstable_by(lo, f32::total_cmp);
    (at_lo, at_hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn volume(dims: [usize; 3], affine: Affine, values: Vec<f32>) -> ImageVolume {
        ImageVolume {
            dims,
            affine,
            values,
            source_dims: dims,
            source_affine: affine,
        }
    }

    #[test]
    fn the_window_maps_its_ends_to_black_and_white() {
        let image = volume(
            [4, 1, 1],
            Affine::scaled([1.0; 3], [0.0; 3]),
            vec![-1000.0, -160.0, 40.0, 240.0],
        );
        let grey = CaseImage::new(&image, "ct.nii.gz", WindowPreset::CtSoftTissue);
        assert_eq!(grey.voxels, vec![0, 0, 128, 255]);
        assert_eq!(grey.preset, "ct-soft-tissue");
        let auto = CaseImage::new(&image, "t1.nii", WindowPreset::MriAuto);
        assert_eq!((auto.voxels[0], auto.voxels[3]), (0, 255));
    }

    #[test]
    fn percentiles_are_the_sorted_values_at_their_ranks_without_non_finite_ones() {
        let mut values: Vec<f32> = (0..1000).map(|v| ((v * 7919) % 1000) as f32).collect();
        values.extend([f32::NAN, f32::INFINITY, f32::NEG_INFINITY]);
        assert_eq!(percentiles(&values, 0.01, 0.99), (10.0, 989.0));
        assert_eq!(percentiles(&values, 0.0, 1.0), (0.0, 999.0));
        assert_eq!(percentiles(&[f32::NAN], 0.01, 0.99), (0.0, 1.0));
        assert_eq!(percentiles(&[5.0], 0.01, 0.99), (5.0, 5.0));
    }

    #[test]
    fn samples_are_trilinear_between_voxel_centres_and_none_outside() {
        let image = volume(
            [2, 1, 1],
            Affine::scaled([2.0, 1.0, 1.0], [10.0, 0.0, 0.0]),
            vec![0.0, 1.0],
        );
        let mut grey = CaseImage::new(&image, "x.nii", WindowPreset::MriAuto);
        grey.voxels = vec![0, 200];
        assert_eq!(grey.sample([11.0, 0.0, 0.0]), Some(100.0));
        assert_eq!(grey.sample([9.5, 0.0, 0.0]), Some(0.0));
        assert_eq!(grey.sample([8.0, 0.0, 0.0]), None);
        assert_eq!(grey.sample([12.0, 0.0, 2.0]), None);
    }
}
