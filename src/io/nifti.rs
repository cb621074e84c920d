//! NIfTI-1 (348-byte header) and NIfTI-2 (540-byte header) label maps and images, single-file `.nii` and
//! `.nii.gz`, in either byte order (told by `sizeof_hdr`).
//!
//! The grid goes to world RAS millimetres as nibabel places it: the sform when `sform_code > 0`,
//! else the qform when `qform_code > 0`, else `diag(pixdim)` (the standard's "method 1"). Label
//! names come from a label-table header extension where there is one ([`nifti_names`]).

use super::gzip::{self, Inflater};
use super::label_map::LabelMapOptions;
use super::label_map::{Affine, LabelMap};
use super::label_map_checks::{check_affine, check_raw, check_spacing, Sample, VoxelLayout};
use super::nifti_names;
use super::voxels::{self, Feed, Streamed, VoxelSink};
use super::{Format, LoadError, Location};

const FORMAT: Format = Format::Nifti;

pub(super) fn parse(bytes: &[u8], options: &LabelMapOptions) -> Result<LabelMap, LoadError> {
    let volume = read(bytes, |layout| VoxelSink::new(layout, options, FORMAT))?;
    let segments = match volume.meta.bytes.len() <= nifti_names::MAX_EXTENSION_BYTES {
        true => nifti_names::label_names(&volume.meta.bytes, volume.meta.big_endian),
        false => Vec::new(),
    };
    Ok(LabelMap {
        dims: volume.layout.dims,
        affine: volume.affine,
        layers: volume.sink.finish()?,
        segments,
        conventional: Vec::new(),
    })
}

/// What a NIfTI file carries beside its voxels.
pub(super) struct Extensions {
    /// The header extensions' bytes (empty when past [`nifti_names::MAX_EXTENSION_BYTES`]).
    pub bytes: Vec<u8>,
    pub big_endian: bool,
}

type Volume<S> = Streamed<S, Extensions>;

/// Reads a NIfTI file's header, then streams its voxels into the sink `make` builds for
/// their layout (label codes, or an image's intensities).
pub(super) fn read<S: Feed>(
    bytes: &[u8],
    make: impl FnOnce(&VoxelLayout) -> Result<S, LoadError>,
) -> Result<Volume<S>, LoadError> {
    if gzip::is_gzip(bytes) {
        read_gzip(bytes, make)
    } else {
        read_raw(bytes, make)
    }
}

fn read_raw<S: Feed>(
    bytes: &[u8],
    make: impl FnOnce(&VoxelLayout) -> Result<S, LoadError>,
) -> Result<Volume<S>, LoadError> {
    let header = Header::parse(bytes)?;
    let layout = header.layout()?;
    let affine = header.affine()?;
    let data_bytes = layout.data_bytes(FORMAT)?;
    let start = header.vox_offset;
    let data = bytes.get(start..).ok_or_else(|| LoadError::Truncated {
        format: FORMAT,
        offset: bytes.len(),
        detail: format!("the voxel data starts at byte {start} (vox_offset), past the end"),
    })?;
    check_raw(data_bytes, data.len(), FORMAT)?;
    let mut sink = make(&layout)?;
    sink.feed(&data[..data_bytes as usize])?;
    let extensions = bytes.get(header.offsets.size..start).unwrap_or_default();
    Ok(Streamed {
        layout,
        affine,
        sink,
        meta: Extensions {
            bytes: match extensions.len() <= nifti_names::MAX_EXTENSION_BYTES {
                true => extensions.to_vec(),
                false => Vec::new(),
            },
            big_endian: header.big_endian,
        },
    })
}

/// `.nii.gz`: the header is inflated first, then the voxels stream from the same inflater
/// straight into the sink, never more than the header declares (plus one byte to notice
/// excess).
fn read_gzip<S: Feed>(
    bytes: &[u8],
    make: impl FnOnce(&VoxelLayout) -> Result<S, LoadError>,
) -> Result<Volume<S>, LoadError> {
    let mut inflater = Inflater::new(bytes, FORMAT);
    let mut head = [0u8; V2.size];
    let got = inflater.read_up_to(&mut head)?;
    let header = Header::parse(&head[..got])?;
    let layout = header.layout()?;
    let affine = header.affine()?;
    let data_bytes = layout.data_bytes(FORMAT)?;
    let start = header.vox_offset;
    let total = start as u64 + data_bytes;
    inflater.check_ratio(total, "inflated bytes")?;
    inflater.expect_total(total);
    if got as u64 > total {
        return Err(inflater.too_long());
    }
    let mut sink = make(&layout)?;
    let in_head = head.get(start..got).unwrap_or_default();
    sink.feed(in_head)?;
    let size = header.offsets.size;
    let mut extensions = head.get(size..start.min(got)).unwrap_or_default().to_vec();
    if start > got {
        if start - size <= nifti_names::MAX_EXTENSION_BYTES {
            let mut rest = vec![0; start - got];
            inflater.read_exact(&mut rest)?;
            extensions.extend(rest);
        } else {
            extensions.clear();
            inflater.skip((start - got) as u64)?;
        }
    }
    voxels::decode_gzip(inflater, &mut sink, data_bytes - in_head.len() as u64)?;
    Ok(Streamed {
        layout,
        affine,
        sink,
        meta: Extensions {
            bytes: extensions,
            big_endian: header.big_endian,
        },
    })
}

/// Where the fields this reader needs sit in each version's header, and how wide they are.
struct Offsets {
    version: u8,
    size: usize,
    dim: usize,
    datatype: usize,
    pixdim: usize,
    vox_offset: usize,
    scl: usize,
    qform_code: usize,
    sform_code: usize,
    quatern: usize,
    srow: usize,
    /// NIfTI-2: 64-bit dims, doubles and 32-bit codes instead of 16-bit dims, floats and codes.
    wide: bool,
}

const V1: Offsets = Offsets {
    version: 1,
    size: 348,
    dim: 40,
    datatype: 70,
    pixdim: 76,
    vox_offset: 108,
    scl: 112,
    qform_code: 252,
    sform_code: 254,
    quatern: 256,
    srow: 280,
    wide: false,
};

const V2: Offsets = Offsets {
    version: 2,
    size: 540,
    dim: 16,
    datatype: 12,
    pixdim: 104,
    vox_offset: 168,
    scl: 176,
    qform_code: 344,
    sform_code: 348,
    quatern: 352,
    srow: 400,
    wide: true,
};

/// Reads fixed-position header fields in the file's byte order.
struct Fields<'a> {
    bytes: &'a [u8],
    big: bool,
    wide: bool,
}

impl Fields<'_> {
    /// The bytes at `at` (zeros past the end, which `Header::parse` has ruled out).
    fn raw<const N: usize>(&self, at: usize) -> [u8; N] {
        let mut out = [0u8; N];
        if let Some(b) = self.bytes.get(at..at + N) {
            out.copy_from_slice(b);
        }
        out
    }

    fn i16(&self, at: usize) -> i16 {
        let b = self.raw(at);
        if self.big {
            i16::from_be_bytes(b)
        } else {
            i16::from_le_bytes(b)
        }
    }

    fn i32(&self, at: usize) -> i32 {
        let b = self.raw(at);
        if self.big {
            i32::from_be_bytes(b)
        } else {
            i32::from_le_bytes(b)
        }
    }

    fn i64(&self, at: usize) -> i64 {
        let b = self.raw(at);
        if self.big {
            i64::from_be_bytes(b)
        } else {
            i64::from_le_bytes(b)
        }
    }

    fn f64(&self, at: usize) -> f64 {
        let b = self.raw(at);
        if self.big {
            f64::from_be_bytes(b)
        } else {
            f64::from_le_bytes(b)
        }
    }

    /// A float field: f32 in NIfTI-1, widened through its shortest decimal form so that a
    /// spacing written as 0.78 reads as 0.78 (as the same grid's NRRD gives it), not
    /// 0.7799999713897705; f64 in NIfTI-2.
    fn real(&self, at: usize) -> f64 {
        if self.wide {
            return self.f64(at);
        }
        let b = self.raw(at);
        let x = if self.big {
            f32::from_be_bytes(b)
        } else {
            f32::from_le_bytes(b)
        };
        if x.is_finite() {
            x.to_string().parse().unwrap_or(f64::from(x))
        } else {
            f64::from(x)
        }
    }

    fn reals<const N: usize>(&self, at: usize) -> [f64; N] {
        let step = if self.wide { 8 } else { 4 };
        std::array::from_fn(|i| self.real(at + i * step))
    }

    /// A dim entry: i16 in NIfTI-1, i64 in NIfTI-2.
    fn dim(&self, at: usize) -> i64 {
        if self.wide {
            self.i64(at)
        } else {
            i64::from(self.i16(at))
        }
    }

    /// An xform code: i16 in NIfTI-1, i32 in NIfTI-2.
    fn code(&self, at: usize) -> i32 {
        if self.wide {
            self.i32(at)
        } else {
            i32::from(self.i16(at))
        }
    }
}

/// The header fields a label map needs.
struct Header {
    offsets: &'static Offsets,
    big_endian: bool,
    dim: [i64; 8],
    datatype: i16,
    pixdim: [f64; 8],
    /// Where the voxels start (validated: whole, at or after the header).
    vox_offset: usize,
    slope: f64,
    inter: f64,
    qform_code: i32,
    sform_code: i32,
    /// quatern_b, c, d, qoffset_x, y, z.
    quatern: [f64; 6],
    srow: [[f64; 4]; 3],
}

impl Header {
    fn parse(bytes: &[u8]) -> Result<Header, LoadError> {
        let (offsets, big) = version_of(bytes)?;
        if bytes.len() < offsets.size {
            return Err(LoadError::Truncated {
                format: FORMAT,
                offset: bytes.len(),
                detail: format!(
                    "the NIfTI-{} header needs {} bytes",
                    offsets.version, offsets.size
                ),
            });
        }
        check_magic(bytes, offsets)?;
        let f = Fields {
            bytes,
            big,
            wide: offsets.wide,
        };
        let step = if offsets.wide { 8 } else { 2 };
        let srow = |r: usize| f.reals(offsets.srow + r * 4 * if offsets.wide { 8 } else { 4 });
        Ok(Header {
            offsets,
            big_endian: big,
            dim: std::array::from_fn(|i| f.dim(offsets.dim + i * step)),
            datatype: f.i16(offsets.datatype),
            pixdim: f.reals(offsets.pixdim),
            vox_offset: vox_offset(&f, offsets)?,
            slope: f.real(offsets.scl),
            inter: f.real(offsets.scl + if offsets.wide { 8 } else { 4 }),
            qform_code: f.code(offsets.qform_code),
            sform_code: f.code(offsets.sform_code),
            quatern: f.reals(offsets.quatern),
            srow: [srow(0), srow(1), srow(2)],
        })
    }

    fn layout(&self) -> Result<VoxelLayout, LoadError> {
        let o = self.offsets;
        let step = if o.wide { 8 } else { 2 };
        let rank = self.dim[0];
        if !(1..=7).contains(&rank) {
            return Err(syntax(
                o.dim,
                format!("dim[0] = {rank}: the number of dimensions must be 1 to 7"),
            ));
        }
        let mut dims = [1usize; 7];
        for d in 1..=rank as usize {
            let n = self.dim[d];
            if n < 1 {
                let detail = format!("dim[{d}] = {n}: every dimension needs at least 1 voxel");
                return Err(syntax(o.dim + d * step, detail));
            }
            dims[d - 1] = usize::try_from(n).map_err(|_| LoadError::Unsupported {
                format: FORMAT,
                detail: format!("dim[{d}] = {n} voxels: more than this machine can address"),
            })?;
        }
        if dims[3] > 1 {
            return Err(unsupported(format!(
                "the file holds {} volumes (dim[4]); a label map must hold one",
                dims[3]
            )));
        }
        if let Some(d) = (5..=7).find(|&d| dims[d - 1] > 1) {
            return Err(unsupported(format!(
                "dim[{d}] = {}: voxels with several values (vectors, colours) are not supported",
                dims[d - 1]
            )));
        }
        let (slope, inter) = if self.slope == 0.0 || !self.slope.is_finite() {
            (1.0, 0.0)
        } else if self.inter.is_finite() {
            (self.slope, self.inter)
        } else {
            (self.slope, 0.0)
        };
        Ok(VoxelLayout {
            dims: [dims[0], dims[1], dims[2]],
            layers: 1,
            interleaved: false,
            sample: sample_of(self.datatype)?,
            big_endian: self.big_endian,
            slope,
            inter,
        })
    }

    fn affine(&self) -> Result<Affine, LoadError> {
        let o = self.offsets;
        if self.sform_code > 0 {
            let affine = Affine(self.srow);
            check_affine(
                &affine,
                FORMAT,
                Location::Byte(o.srow),
                "sform (srow_x/y/z)",
            )?;
            return Ok(affine);
        }
        let width = if o.wide { 8 } else { 4 };
        let mut spacing = [0.0; 3];
        for (axis, s) in spacing.iter_mut().enumerate() {
            let at = o.pixdim + (axis + 1) * width;
            let field = format!("pixdim[{}]", axis + 1);
            *s = check_spacing(self.pixdim[axis + 1], FORMAT, Location::Byte(at), &field)?;
        }
        let (affine, at, source) = if self.qform_code > 0 {
            (
                self.qform(spacing),
                o.quatern,
                "qform (quatern_b/c/d, pixdim)",
            )
        } else {
            (
                Affine::scaled(spacing, [0.0; 3]),
                o.pixdim,
                "pixdim (no sform or qform)",
            )
        };
        check_affine(&affine, FORMAT, Location::Byte(at), source)?;
        Ok(affine)
    }

    /// The qform as the NIfTI reference library builds it: a unit quaternion (b, c, d with
    /// a = sqrt(1 - b² - c² - d²); a 180° turn when that is about 0), the voxel sizes, the
    /// handedness qfac from pixdim[0] (negative flips k; 0 counts as 1), and the offsets.
    fn qform(&self, spacing: [f64; 3]) -> Affine {
        let [b, c, d, x, y, z] = self.quatern;
        let rest = 1.0 - (b * b + c * c + d * d);
        let (a, b, c, d) = if rest < 1e-7 {
            let n = 1.0 / (b * b + c * c + d * d).sqrt();
            (0.0, b * n, c * n, d * n)
        } else {
            (rest.sqrt(), b, c, d)
        };
        let qfac = if self.pixdim[0] < 0.0 { -1.0 } else { 1.0 };
        let [dx, dy, dz] = [spacing[0], spacing[1], spacing[2] * qfac];
        Affine([
            [
                (a * a + b * b - c * c - d * d) * dx,
                2.0 * (b * c - a * d) * dy,
                2.0 * (b * d + a * c) * dz,
                x,
            ],
            [
                2.0 * (b * c + a * d) * dx,
                (a * a + c * c - b * b - d * d) * dy,
                2.0 * (c * d - a * b) * dz,
                y,
            ],
            [
                2.0 * (b * d - a * c) * dx,
                2.0 * (c * d + a * b) * dy,
                (a * a + d * d - c * c - b * b) * dz,
                z,
            ],
        ])
    }
}

/// The version and byte order, told by `sizeof_hdr` (348 or 540, read either way round).
fn version_of(bytes: &[u8]) -> Result<(&'static Offsets, bool), LoadError> {
    let Some(first) = bytes.get(..4) else {
        return Err(LoadError::Truncated {
            format: FORMAT,
            offset: bytes.len(),
            detail: "a NIfTI header starts with its 4-byte size".into(),
        });
    };
    let b = [first[0], first[1], first[2], first[3]];
    let (little, big) = (i32::from_le_bytes(b), i32::from_be_bytes(b));
    match (little, big) {
        (348, _) => Ok((&V1, false)),
        (540, _) => Ok((&V2, false)),
        (_, 348) => Ok((&V1, true)),
        (_, 540) => Ok((&V2, true)),
        _ => Err(LoadError::BadMagic {
            format: FORMAT,
            detail: format!(
                "sizeof_hdr is {little}, not 348 (NIfTI-1) or 540 (NIfTI-2), in either byte order"
            ),
        }),
    }
}

fn check_magic(bytes: &[u8], o: &Offsets) -> Result<(), LoadError> {
    let (at, single, pair): (usize, &[u8], &[u8]) = if o.wide {
        (4, b"n+2\0\r\n\x1a\n", b"ni2\0\r\n\x1a\n")
    } else {
        (344, b"n+1\0", b"ni1\0")
    };
    let magic = bytes.get(at..at + single.len()).unwrap_or_default();
    if magic == single {
        return Ok(());
    }
    if magic == pair {
        return Err(unsupported(format!(
            "a NIfTI-{} header/image pair (.hdr + .img): only single-file .nii and .nii.gz are \
             read; save it as .nii",
            o.version
        )));
    }
    Err(LoadError::BadMagic {
        format: FORMAT,
        detail: format!(
            "no 'n+{}' magic at byte {at} (found {:?}; an Analyze 7.5 header?)",
            o.version,
            String::from_utf8_lossy(magic)
        ),
    })
}

fn vox_offset(f: &Fields<'_>, o: &Offsets) -> Result<usize, LoadError> {
    let value = if o.wide {
        f.i64(o.vox_offset) as f64
    } else {
        f.real(o.vox_offset)
    };
    let whole = value.is_finite() && value.fract() == 0.0;
    if whole && value >= o.size as f64 && value <= u32::MAX as f64 {
        return Ok(value as usize);
    }
    Err(syntax(
        o.vox_offset,
        format!(
            "vox_offset {value}: the voxel data must start at a whole byte at or after the \
             {}-byte header",
            o.size
        ),
    ))
}

fn sample_of(datatype: i16) -> Result<Sample, LoadError> {
    Ok(match datatype {
        2 => Sample::U8,
        4 => Sample::I16,
        8 => Sample::I32,
        16 => Sample::F32,
        64 => Sample::F64,
        256 => Sample::I8,
        512 => Sample::U16,
        768 => Sample::U32,
        _ => {
            let name = match datatype {
                0 => "unknown",
                1 => "binary",
                32 => "complex64",
                128 => "RGB24",
                1024 => "int64",
                1280 => "uint64",
                1536 => "float128",
                1792 => "complex128",
                2048 => "complex256",
                2304 => "RGBA32",
                _ => "not a NIfTI datatype",
            };
            return Err(unsupported(format!(
                "datatype {datatype} ({name}) is not supported: a label map needs uint8, int8, \
                 uint16, int16, uint32, int32, float32 or float64 voxels"
            )));
        }
    })
}

fn syntax(at: usize, detail: String) -> LoadError {
    LoadError::Syntax {
        format: FORMAT,
        location: Location::Byte(at),
        detail,
    }
}

fn unsupported(detail: String) -> LoadError {
    LoadError::Unsupported {
        format: FORMAT,
        detail,
    }
}
