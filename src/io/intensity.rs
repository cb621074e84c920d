//! An image's voxel bytes into intensities, reduced on the fly: each cell of a coarser grid
//! (a whole factor along every axis) gathers the mean of the voxels it covers, so a whole-body
//! CT never costs more memory than the reduced image a student is given.

use std::convert::Infallible;

use super::label_map_checks::{for_each_sample, VoxelLayout};
use super::voxels::Feed;
use super::{Format, LoadError};

/// A grid's values summed into the cells of a coarser grid, a whole `factor` along every axis,
/// in the order a file stores them (`i` fastest); each cell ends as the mean of what it covers.
pub struct BlockMeans {
    dims: [usize; 3],
    factor: usize,
    reduced: [usize; 3],
    sums: Vec<f32>,
    /// The next voxel's `i, j, k`.
    at: [usize; 3],
}

impl BlockMeans {
    /// `None` when the reduced grid's memory cannot be had.
    pub fn new(dims: [usize; 3], factor: usize) -> Option<Self> {
        let factor = factor.max(1);
        let reduced = dims.map(|d| d.div_ceil(factor));
        let cells = reduced.iter().product::<usize>();
        let mut sums = Vec::new();
        sums.try_reserve_exact(cells).ok()?;
        sums.resize(cells, 0.0);
        Some(Self {
            dims,
            factor,
            reduced,
            sums,
            at: [0; 3],
        })
    }

    /// Adds the next voxel's value; not-a-number voxels (outside a resampled field of view)
    /// count as 0, and values past the grid's end are ignored.
    #[inline]
    pub fn push(&mut self, value: f32) {
        let [i, j, k] = self.at;
        let dims = self.dims;
        if k >= dims[2] {
            return;
        }
        let f = self.factor;
        let cell = (k / f * self.reduced[1] + j / f) * self.reduced[0] + i / f;
        self.sums[cell] += if value.is_finite() { value } else { 0.0 };
        self.at = if i + 1 < dims[0] {
            [i + 1, j, k]
        } else if j + 1 < dims[1] {
            [0, j + 1, k]
        } else {
            [0, 0, k + 1]
        };
    }

    /// How many voxels have come.
    pub fn pushed(&self) -> usize {
        let [i, j, k] = self.at;
        (k * self.dims[1] + j) * self.dims[0] + i
    }

    /// The reduced grid's size and its cells' means.
    pub fn finish(self) -> ([usize; 3], Vec<f32>) {
        let (f, dims, reduced) = (self.factor, self.dims, self.reduced);
        // Cells at the far ends may cover fewer voxels than `factor` along an axis.
        let covered = |axis: usize, cell: usize| (dims[axis] - cell * f).min(f) as f32;
        let mut sums = self.sums;
        for k in 0..reduced[2] {
            for j in 0..reduced[1] {
                let row = (k * reduced[1] + j) * reduced[0];
                let jk = covered(1, j) * covered(2, k);
                for i in 0..reduced[0] {
                    sums[row + i] /= covered(0, i) * jk;
                }
            }
        }
        (reduced, sums)
    }
}

/// Decodes one volume's samples (after the file's scaling) into [`BlockMeans`].
pub(super) struct IntensitySink {
    layout: VoxelLayout,
    means: BlockMeans,
    /// The start of a sample split between two chunks.
    pending: Vec<u8>,
}

impl IntensitySink {
    /// Refuses what is not one scalar volume; reduces by the smallest factor that leaves at
    /// most `max_voxels` cells.
    pub(super) fn new(
        layout: &VoxelLayout,
        format: Format,
        max_voxels: usize,
    ) -> Result<Self, LoadError> {
        if layout.layers != 1 {
            return Err(LoadError::Unsupported {
                format,
                detail: format!(
                    "the image holds {} volumes or components; meshsmooth shows one scalar \
                     volume",
                    layout.layers
                ),
            });
        }
        let factor = reduction_factor(layout.dims, max_voxels);
        let means = BlockMeans::new(layout.dims, factor).ok_or_else(|| {
            let cells: usize = layout.dims.map(|d| d.div_ceil(factor)).iter().product();
            LoadError::Unsupported {
                format,
                detail: format!("cannot allocate {} bytes for the image", cells * 4),
            }
        })?;
        Ok(Self {
            layout: *layout,
            means,
            pending: Vec::new(),
        })
    }

    /// Scales the samples fed from now on by `slope` and `inter` instead (each slice of a DICOM
    /// series has its own).
    pub(super) fn rescale(&mut self, slope: f64, inter: f64) {
        self.layout.slope = slope;
        self.layout.inter = inter;
    }

    /// The factor the grid is reduced by along each axis.
    pub(super) fn factor(&self) -> usize {
        self.means.factor
    }

    /// The reduced grid's size and its cells' mean intensities, once every voxel has come.
    pub(super) fn finish(self, format: Format) -> Result<([usize; 3], Vec<f32>), LoadError> {
        let (read, voxels) = (self.means.pushed(), self.layout.voxel_count());
        if read < voxels {
            return Err(LoadError::Truncated {
                format,
                offset: 0,
                detail: format!("the voxel data ends after {read} of {voxels} voxels"),
            });
        }
        Ok(self.means.finish())
    }

    fn decode(&mut self, bytes: &[u8]) {
        let VoxelLayout {
            sample,
            big_endian,
            slope,
            inter,
            ..
        } = self.layout;
        let decoded = for_each_sample(bytes, sample, big_endian, |v| {
            self.means.push(v.scaled(slope, inter) as f32);
            Ok::<(), Infallible>(())
        });
        let Ok(()) = decoded;
    }
}

impl Feed for IntensitySink {
    fn feed(&mut self, mut bytes: &[u8]) -> Result<(), LoadError> {
        let size = self.layout.sample.size();
        if !self.pending.is_empty() {
            let take = (size - self.pending.len()).min(bytes.len());
            self.pending.extend_from_slice(&bytes[..take]);
            bytes = &bytes[take..];
            if self.pending.len() < size {
                return Ok(());
            }
            let sample = std::mem::take(&mut self.pending);
            self.decode(&sample);
        }
        let whole = bytes.len() / size * size;
        self.decode(&bytes[..whole]);
        self.pending.extend_from_slice(&bytes[whole..]);
        Ok(())
    }
}

/// The smallest whole factor that leaves at most `max_voxels` cells (at least one cell).
fn reduction_factor(dims: [usize; 3], max_voxels: usize) -> usize {
    let cells = |f: usize| dims.iter().map(|d| d.div_ceil(f) as u128).product::<u128>();
    let longest = dims.iter().copied().max().unwrap_or(1).max(1);
    (1..=longest)
        .find(|&f| cells(f) <= max_voxels.max(1) as u128)
        .unwrap_or(longest)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::label_map_checks::Sample;

    fn layout(dims: [usize; 3], sample: Sample) -> VoxelLayout {
        VoxelLayout {
            dims,
            layers: 1,
            interleaved: false,
            sample,
            big_endian: false,
            slope: 2.0,
            inter: -10.0,
        }
    }

    #[test]
    fn cells_hold_the_mean_of_the_scaled_voxels_they_cover_even_at_the_ends() {
        // 3 x 2 x 1 voxels of i16 0..6, reduced by 2: cells [0,1,3,4] and [2,5].
        let mut sink =
            IntensitySink::new(&layout([3, 2, 1], Sample::I16), Format::Nifti, 2).expect("sink");
        assert_eq!(sink.factor(), 2);
        let bytes: Vec<u8> = (0i16..6).flat_map(|v| v.to_le_bytes()).collect();
        // Split inside a sample, as gzip chunks may.
        sink.feed(&bytes[..3]).expect("feed");
        sink.feed(&bytes[3..]).expect("feed");
        let (dims, values) = sink.finish(Format::Nifti).expect("finish");
        assert_eq!(dims, [2, 1, 1]);
        let scaled = |v: f32| v * 2.0 - 10.0;
        assert_eq!(values, vec![scaled(2.0), scaled(3.5)]);
    }

    #[test]
    fn a_short_volume_or_several_volumes_are_refused() {
        let mut sink =
            IntensitySink::new(&layout([2, 2, 2], Sample::U8), Format::Nifti, 100).expect("sink");
        sink.feed(&[1, 2, 3]).expect("feed");
        let short = sink.finish(Format::Nifti).expect_err("short");
        assert!(short.to_string().contains("3 of 8 voxels"), "{short}");
        let four_d = VoxelLayout {
            layers: 3,
            ..layout([2, 2, 2], Sample::U8)
        };
        let error = IntensitySink::new(&four_d, Format::Nifti, 100)
            .err()
            .expect("refused");
        assert!(error.to_string().contains("3 volumes"), "{error}");
    }

    #[test]
    fn the_factor_is_the_smallest_that_fits() {
        assert_eq!(reduction_factor([512, 512, 900], 16 << 20), 3);
        assert_eq!(reduction_factor([10, 10, 10], 1000), 1);
        assert_eq!(reduction_factor([10, 10, 10], 999), 2);
        assert_eq!(reduction_factor([7, 1, 1], 0), 7);
    }
}
