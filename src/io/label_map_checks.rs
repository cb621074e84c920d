//! What both label-map parsers check before they allocate or place a grid: the voxel layout a
//! header declares (bounded in bytes and layers), the raw bytes behind it, the affine and the
//! voxel sizes.

use super::label_map::Affine;
use super::{Format, LoadError, Location};

/// The most voxel data (and the most label codes) a label map may hold.
pub(super) const MAX_VOXEL_BYTES: u64 = 4 << 30;

/// The most layers a label map may hold (3D Slicer writes one per group of overlapping segments;
/// older files one per segment). Each layer costs a few small buffers beyond its codes.
pub(super) const MAX_LAYERS: usize = 1024;

/// Voxel sample types both formats share.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Sample {
    U8,
    I8,
    U16,
    I16,
    U32,
    I32,
    F32,
    F64,
}

impl Sample {
    pub(super) fn size(self) -> usize {
        match self {
            Sample::U8 | Sample::I8 => 1,
            Sample::U16 | Sample::I16 => 2,
            Sample::U32 | Sample::I32 | Sample::F32 => 4,
            Sample::F64 => 8,
        }
    }

    pub(super) fn is_float(self) -> bool {
        matches!(self, Sample::F32 | Sample::F64)
    }

    fn name(self) -> &'static str {
        match self {
            Sample::U8 => "uint8",
            Sample::I8 => "int8",
            Sample::U16 => "uint16",
            Sample::I16 => "int16",
            Sample::U32 => "uint32",
            Sample::I32 => "int32",
            Sample::F32 => "float32",
            Sample::F64 => "float64",
        }
    }
}

/// One voxel sample as stored: an integer exactly, or a real number.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Value {
    Int(i64),
    Real(f64),
}

impl Value {
    /// The value after a file's scaling (`value * slope + inter`).
    #[inline]
    pub(super) fn scaled(self, slope: f64, inter: f64) -> f64 {
        match self {
            Value::Int(v) => v as f64 * slope + inter,
            Value::Real(v) => v * slope + inter,
        }
    }
}

/// Calls `f` with each whole sample of `bytes` (a trailing part sample is left alone), the
/// sample type and byte order chosen once per call rather than once per voxel.
#[inline]
pub(super) fn for_each_sample<E>(
    bytes: &[u8],
    sample: Sample,
    big_endian: bool,
    mut f: impl FnMut(Value) -> Result<(), E>,
) -> Result<(), E> {
    macro_rules! run {
        ($t:ty, $n:literal, $wrap:expr) => {{
            let (samples, _) = bytes.as_chunks::<$n>();
            for s in samples {
                let v = if big_endian {
                    <$t>::from_be_bytes(*s)
                } else {
                    <$t>::from_le_bytes(*s)
                };
                f($wrap(v))?;
            }
        }};
    }
    match sample {
        Sample::U8 => run!(u8, 1, |v| Value::Int(i64::from(v))),
        Sample::I8 => run!(i8, 1, |v| Value::Int(i64::from(v))),
        Sample::U16 => run!(u16, 2, |v| Value::Int(i64::from(v))),
        Sample::I16 => run!(i16, 2, |v| Value::Int(i64::from(v))),
        Sample::U32 => run!(u32, 4, |v| Value::Int(i64::from(v))),
        Sample::I32 => run!(i32, 4, |v| Value::Int(i64::from(v))),
        Sample::F32 => run!(f32, 4, |v| Value::Real(f64::from(v))),
        Sample::F64 => run!(f64, 8, Value::Real),
    }
    Ok(())
}

/// How a file lays out its voxel values: the grid, the layers and the encoding of each value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct VoxelLayout {
    pub dims: [usize; 3],
    pub layers: usize,
    /// Layers interleaved voxel by voxel (NRRD's list axis first) rather than one after another.
    pub interleaved: bool,
    pub sample: Sample,
    pub big_endian: bool,
    /// `value * slope + inter` (NIfTI's scaling; 1 and 0 elsewhere).
    pub slope: f64,
    pub inter: f64,
}

impl VoxelLayout {
    /// Bytes of voxel data the layout declares, after refusing one past [`MAX_VOXEL_BYTES`] of
    /// data or of codes.
    pub(super) fn data_bytes(&self, format: Format) -> Result<u64, LoadError> {
        if self.layers > MAX_LAYERS {
            return Err(LoadError::Unsupported {
                format,
                detail: format!(
                    "{} layers: a label map may hold at most {MAX_LAYERS}",
                    self.layers
                ),
            });
        }
        let [i, j, k] = self.dims.map(|d| d as u128);
        let elements = i * j * k * self.layers as u128;
        let bytes = elements * self.sample.size() as u128;
        if bytes.max(elements * 2) > u128::from(MAX_VOXEL_BYTES) {
            return Err(LoadError::Unsupported {
                format,
                detail: format!(
                    "{i} x {j} x {k} voxels x {} layer(s) of {}: {bytes} bytes of voxel data, \
                     more than the 4 GiB limit",
                    self.layers,
                    self.sample.name()
                ),
            });
        }
        Ok(bytes as u64)
    }

    pub(super) fn voxel_count(&self) -> usize {
        self.dims.iter().product()
    }
}

/// Refuses data bytes that the raw bytes after the header cannot hold.
pub(super) fn check_raw(declared: u64, available: usize, format: Format) -> Result<(), LoadError> {
    if declared > available as u64 {
        return Err(LoadError::CountTooLarge {
            format,
            what: "bytes of voxel data",
            claimed: declared,
            possible: available as u64,
        });
    }
    Ok(())
}

/// Checks an affine the grid will be placed by: finite, positive voxel sizes, not singular.
/// `source` names the header fields it came from, `location` where they are.
pub(super) fn check_affine(
    affine: &Affine,
    format: Format,
    location: Location,
    source: &str,
) -> Result<(), LoadError> {
    let error = |detail: String| LoadError::Syntax {
        format,
        location,
        detail: format!("{source}: {detail}"),
    };
    if let Some(v) = affine.0.iter().flatten().find(|v| !v.is_finite()) {
        return Err(error(format!("{v} is not a finite number")));
    }
    let spacing = affine.spacing();
    if let Some(axis) = spacing.iter().position(|&s| !(s > 0.0 && s.is_finite())) {
        return Err(error(format!("the voxel size along axis {axis} is 0")));
    }
    let det = affine.determinant();
    let volume: f64 = spacing.iter().product();
    if !det.is_finite() || det.abs() <= 1e-6 * volume {
        return Err(error(format!(
            "the affine is singular (determinant {det:.3e} for voxel sizes {spacing:?}): its \
             voxel axes are parallel"
        )));
    }
    Ok(())
}

/// Checks a voxel size read from a header field (NIfTI's pixdim, NRRD's spacings).
pub(super) fn check_spacing(
    value: f64,
    format: Format,
    location: Location,
    field: &str,
) -> Result<f64, LoadError> {
    if value > 0.0 && value.is_finite() {
        return Ok(value);
    }
    Err(LoadError::Syntax {
        format,
        location,
        detail: format!("{field}: voxel size {value} must be positive and finite"),
    })
}
