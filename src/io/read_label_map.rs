//! Label maps in: NIfTI-1 and NIfTI-2 (`.nii`, `.nii.gz`), NRRD (`.nrrd`, 3D Slicer's
//! `.seg.nrrd`), FreeSurfer's MGH (`.mgh`, `.mgz`) and DICOM SEG (`.dcm`) into a [`LabelMap`]; colour tables that
//! name the labels are in `color_table`.
//!
//! Both formats are parsed here by hand rather than with the `nifti` crate: that crate reads
//! NIfTI-1 only and allocates the volume from the header's dims before anything can bound them.
//! Here every size is checked against the bytes (for gzip: against the most deflate can expand
//! to) before a buffer is made, gzip is inflated under a hard limit, and voxels are decoded chunk
//! by chunk straight into two-byte label codes, so a large volume never sits in memory both as
//! raw voxels and as codes.
//!
//! Values become labels when they are whole numbers (after NIfTI's `scl_slope`/`scl_inter`); an
//! image with other values (a probability map, a float mask) is read as a mask instead: value 1
//! where the voxel is at least the level, background elsewhere and at NaN.

use super::dicom;
use super::label_map::{LabelMap, LabelMapOptions};
use super::{mgh, nifti, nrrd, Format, LoadError};

/// Whether a file name is a label map this module reads (`.nii`, `.nii.gz`, `.nrrd` including
/// `.seg.nrrd`, `.mgh`, `.mgz`, DICOM SEG's `.dcm`, and detached `.nhdr` headers, which are refused with a reason),
/// ignoring case.
pub fn is_label_map(name: &str) -> bool {
    label_format_of(name).is_some()
}

pub(super) fn label_format_of(name: &str) -> Option<Format> {
    let lower = name.to_ascii_lowercase();
    if lower.ends_with(".nii") || lower.ends_with(".nii.gz") {
        Some(Format::Nifti)
    } else if lower.ends_with(".nrrd") || lower.ends_with(".nhdr") {
        Some(Format::Nrrd)
    } else if lower.ends_with(".mgh") || lower.ends_with(".mgz") {
        Some(Format::Mgh)
    } else if lower.ends_with(".dcm") {
        Some(Format::DicomSeg)
    } else {
        None
    }
}

/// Reads a label map, choosing the parser by the file name (or, for other names, by the bytes:
/// `NRRD` magic, gzip, or a NIfTI header size). A gzip-compressed `.nii` is read as `.nii.gz`.
pub fn load_label_map(
    bytes: &[u8],
    name: &str,
    options: &LabelMapOptions,
) -> Result<LabelMap, LoadError> {
    let format = match label_format_of(name) {
        Some(format) => format,
        None => sniff(bytes, name)?,
    };
    if bytes.is_empty() {
        return Err(LoadError::Empty { format });
    }
    if let Some(level) = options.level.filter(|l| !l.is_finite()) {
        return Err(LoadError::Unsupported {
            format,
            detail: format!("the mask level {level} is not a finite number"),
        });
    }
    match format {
        Format::Nrrd => nrrd::parse(bytes, options),
        Format::Mgh => mgh::parse(bytes, options),
        Format::DicomSeg => dicom::seg::parse(bytes, options),
        _ => nifti::parse(bytes, options),
    }
}

/// The label-map format of a file whose name does not say (an uncompressed MGH by its version,
/// 1, big-endian; gzip is taken for NIfTI).
fn sniff(bytes: &[u8], name: &str) -> Result<Format, LoadError> {
    let size = |big: bool| {
        let b = <[u8; 4]>::try_from(bytes.get(..4)?).ok()?;
        Some(if big {
            i32::from_be_bytes(b)
        } else {
            i32::from_le_bytes(b)
        })
    };
    let nifti_size = |s: Option<i32>| matches!(s, Some(348 | 540));
    if bytes.starts_with(b"NRRD") {
        Ok(Format::Nrrd)
    } else if dicom::seg::is_dicom(bytes) {
        Ok(Format::DicomSeg)
    } else if bytes.starts_with(&[0, 0, 0, 1]) {
        Ok(Format::Mgh)
    } else if super::gzip::is_gzip(bytes) || nifti_size(size(false)) || nifti_size(size(true)) {
        Ok(Format::Nifti)
    } else if let Some(format) = Format::from_name(name) {
        Err(LoadError::Unsupported {
            format,
            detail: format!("'{name}' is a mesh, not a label map: open it as a mesh"),
        })
    } else {
        Err(LoadError::UnknownFormat {
            name: name.to_string(),
        })
    }
}
