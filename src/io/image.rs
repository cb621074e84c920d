//! The image a segmentation was drawn on (CT or MRI), as a student sees it under the surfaces:
//! one scalar volume in world RAS millimetres, reduced to a size a learning platform can carry.

use super::dicom;
use super::dicom::series::{load_image_series, SeriesError};
use super::intensity::IntensitySink;
use super::label_map::Affine;
use super::{mgh, nifti, nrrd, Format, LoadError};

/// An intensity volume on its (possibly reduced) grid.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageVolume {
    /// Voxels along i, j, k (`i` fastest in `values`).
    pub dims: [usize; 3],
    /// Voxel centres `i, j, k` to world RAS millimetres.
    pub affine: Affine,
    /// Intensities as the file scales them (Hounsfield units for CT), each a reduced cell's
    /// mean.
    pub values: Vec<f32>,
    /// The grid the file declares, before reduction: what is checked against the segmentation.
    pub source_dims: [usize; 3],
    pub source_affine: Affine,
}

/// Reads `name`'s image (NIfTI `.nii`/`.nii.gz`, NRRD `.nrrd` with its data attached, or
/// FreeSurfer `.mgz`/`.mgh`, or a DICOM image of one slice: a series of several is read by
/// [`load_image_series`]), reduced by the smallest whole factor that leaves at most
/// `max_voxels` voxels.
pub fn load_image(bytes: &[u8], name: &str, max_voxels: usize) -> Result<ImageVolume, LoadError> {
    let lower = name.to_ascii_lowercase();
    if lower.ends_with(".dcm") || dicom::seg::is_dicom(bytes) {
        return load_image_series(&[(name, bytes)], max_voxels).map_err(|e| match e {
            SeriesError::File { error, .. } => error,
            SeriesError::Series(detail) => LoadError::Unsupported {
                format: Format::DicomImage,
                detail,
            },
        });
    }
    let sink = |format| move |layout: &_| IntensitySink::new(layout, format, max_voxels);
    let (format, volume) = if lower.ends_with(".nrrd") {
        (Format::Nrrd, nrrd::read(bytes, sink(Format::Nrrd))?.plain())
    } else if lower.ends_with(".nii") || lower.ends_with(".nii.gz") {
        (
            Format::Nifti,
            nifti::read(bytes, sink(Format::Nifti))?.plain(),
        )
    } else if lower.ends_with(".mgz") || lower.ends_with(".mgh") {
        (Format::Mgh, mgh::read(bytes, sink(Format::Mgh))?)
    } else {
        return Err(LoadError::UnknownImageFormat {
            name: name.to_string(),
        });
    };
    let factor = volume.sink.factor();
    let (dims, values) = volume.sink.finish(format)?;
    Ok(ImageVolume {
        dims,
        affine: reduced_affine(&volume.affine, factor),
        values,
        source_dims: volume.layout.dims,
        source_affine: volume.affine,
    })
}

/// The affine of a grid whose cell `I` covers voxels `f I .. f I + f - 1`: its centre lies at
/// voxel index `f I + (f - 1) / 2`.
pub fn reduced_affine(affine: &Affine, factor: usize) -> Affine {
    let f = factor as f64;
    let half = (f - 1.0) / 2.0;
    Affine(affine.0.map(|row| {
        [
            row[0] * f,
            row[1] * f,
            row[2] * f,
            row[3] + half * (row[0] + row[1] + row[2]),
        ]
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reduced_cell_sits_at_the_centre_of_the_voxels_it_covers() {
        let affine = Affine([
            [0.0, -0.8, 0.0, 10.0],
            [1.5, 0.0, 0.0, -3.0],
            [0.0, 0.0, 2.0, 7.0],
        ]);
        let cell = reduced_affine(&affine, 3);
        // Cell (1, 2, 0) covers voxels 3..5, 6..8, 0..2: centre (4, 7, 1).
        let (got, want) = (cell.apply([1.0, 2.0, 0.0]), affine.apply([4.0, 7.0, 1.0]));
        assert!(
            (0..3).all(|a| (got[a] - want[a]).abs() < 1e-12),
            "{got:?} {want:?}"
        );
        assert_eq!(reduced_affine(&affine, 1), affine);
    }
}
