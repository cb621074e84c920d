//! FreeSurfer MGH (`.mgh`) and its gzip form MGZ (`.mgz`) label volumes (`aseg.mgz`,
//! `aparc+aseg.mgz`) and images (`T1.mgz`), read as nibabel reads them: a big-endian header of fixed fields, the voxels
//! from byte 284 with the first index fastest, then a footer (scan parameters, tags) that a label
//! map does not need and is not read.
//!
//! By hand rather than with a crate, for the reasons the NIfTI reader gives: sizes checked
//! against the bytes before anything is allocated, gzip under a hard limit, voxels decoded
//! straight into label codes. The labels are named by FreeSurfer's colour table
//! ([`super::freesurfer_lut`]), below any table the author gives.

use super::freesurfer_lut;
use super::gzip::{self, Inflater};
use super::label_map::{Affine, LabelMap, LabelMapOptions, Segment};
use super::label_map_checks::{check_affine, check_raw, Sample, VoxelLayout};
use super::voxels::{self, Feed, Streamed, VoxelSink};
use super::{Format, LoadError, Location};

const FORMAT: Format = Format::Mgh;

/// Where the voxels start (`DATA_OFFSET` in nibabel and FreeSurfer).
const DATA_OFFSET: usize = 284;
/// The header fields read here end at this byte (`Pxyz_c` is the last).
const FIELDS_END: usize = 90;

pub(super) fn parse(bytes: &[u8], options: &LabelMapOptions) -> Result<LabelMap, LoadError> {
    finish(read(bytes, |layout| {
        VoxelSink::new(layout, options, FORMAT)
    })?)
}

/// Reads an MGH/MGZ file's header, then streams its voxels into the sink `make` builds for
/// their layout (label codes, or an image's intensities: FreeSurfer's `T1.mgz` lies on the
/// grid of its `aseg.mgz`).
pub(super) fn read<S: Feed>(
    bytes: &[u8],
    make: impl FnOnce(&VoxelLayout) -> Result<S, LoadError>,
) -> Result<Streamed<S>, LoadError> {
    if gzip::is_gzip(bytes) {
        read_gzip(bytes, make)
    } else {
        read_raw(bytes, make)
    }
}

fn read_raw<S: Feed>(
    bytes: &[u8],
    make: impl FnOnce(&VoxelLayout) -> Result<S, LoadError>,
) -> Result<Streamed<S>, LoadError> {
    let header = Header::parse(bytes)?;
    let layout = header.layout()?;
    let affine = header.affine()?;
    let data_bytes = layout.data_bytes(FORMAT)?;
    let data = bytes.get(DATA_OFFSET..).unwrap_or_default();
    check_raw(data_bytes, data.len(), FORMAT)?;
    let mut sink = make(&layout)?;
    // What follows the voxels is the footer.
    sink.feed(&data[..data_bytes as usize])?;
    Ok(Streamed {
        layout,
        affine,
        sink,
        meta: (),
    })
}

/// `.mgz`: the header inflated first, then the voxels stream from the same inflater into the
/// sink; the stream is read no further than the voxels (the footer is not needed).
fn read_gzip<S: Feed>(
    bytes: &[u8],
    make: impl FnOnce(&VoxelLayout) -> Result<S, LoadError>,
) -> Result<Streamed<S>, LoadError> {
    let mut inflater = Inflater::new(bytes, FORMAT);
    let mut head = [0u8; DATA_OFFSET];
    let got = inflater.read_up_to(&mut head)?;
    let header = Header::parse(&head[..got])?;
    let layout = header.layout()?;
    let affine = header.affine()?;
    let data_bytes = layout.data_bytes(FORMAT)?;
    let total = DATA_OFFSET as u64 + data_bytes;
    inflater.check_ratio(total, "inflated bytes")?;
    if got < DATA_OFFSET {
        return Err(inflater.truncated());
    }
    inflater.expect_total(total);
    let mut sink = make(&layout)?;
    voxels::feed_from_gzip(&mut inflater, &mut sink, data_bytes)?;
    Ok(Streamed {
        layout,
        affine,
        sink,
        meta: (),
    })
}

fn finish(volume: Streamed<VoxelSink>) -> Result<LabelMap, LoadError> {
    let Streamed {
        layout,
        affine,
        sink,
        ..
    } = volume;
    let layers = sink.finish()?;
    let values = layers.first().map_or(&[][..], |l| &l.values[..]);
    let conventional = (values.iter().skip(1))
        .filter_map(|&value| {
            let (name, rgb) = freesurfer_lut::entry(value)?;
            Some(Segment {
                layer: 0,
                value,
                name: name.to_string(),
                color: Some(rgb.map(|c| f32::from(c) / 255.0)),
                codes: None,
            })
        })
        .collect();
    Ok(LabelMap {
        dims: layout.dims,
        affine,
        layers,
        segments: Vec::new(),
        conventional,
    })
}

/// The header fields a label map needs.
struct Header {
    dims: [i32; 4],
    kind: i32,
    good_ras: i16,
    delta: [f32; 3],
    /// Row `i`: the RAS direction of voxel axis `i` (the file stores the matrix transposed).
    mdc: [[f32; 3]; 3],
    center: [f32; 3],
}

impl Header {
    fn parse(bytes: &[u8]) -> Result<Header, LoadError> {
        if bytes.len() < FIELDS_END {
            return Err(LoadError::Truncated {
                format: FORMAT,
                offset: bytes.len(),
                detail: format!("an MGH header holds {FIELDS_END} bytes of fields"),
            });
        }
        let at = |i: usize| [bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]];
        let int = |i: usize| i32::from_be_bytes(at(i));
        let real = |i: usize| f32::from_be_bytes(at(i));
        let version = int(0);
        if version != 1 {
            return Err(LoadError::BadMagic {
                format: FORMAT,
                detail: format!("version {version} at byte 0; an MGH file says 1"),
            });
        }
        Ok(Header {
            dims: std::array::from_fn(|d| int(4 + 4 * d)),
            kind: int(20),
            good_ras: i16::from_be_bytes([bytes[28], bytes[29]]),
            delta: std::array::from_fn(|d| real(30 + 4 * d)),
            mdc: std::array::from_fn(|r| std::array::from_fn(|c| real(42 + 12 * r + 4 * c))),
            center: std::array::from_fn(|d| real(78 + 4 * d)),
        })
    }

    fn layout(&self) -> Result<VoxelLayout, LoadError> {
        let mut dims = [0usize; 4];
        for (d, &n) in self.dims.iter().enumerate() {
            if n < 1 {
                return Err(syntax(
                    4 + 4 * d,
                    format!("dims[{d}] = {n}: every dimension needs at least 1 voxel"),
                ));
            }
            dims[d] = n as usize;
        }
        if dims[3] > 1 {
            return Err(LoadError::Unsupported {
                format: FORMAT,
                detail: format!(
                    "the file holds {} frames; a label map must hold one",
                    dims[3]
                ),
            });
        }
        Ok(VoxelLayout {
            dims: [dims[0], dims[1], dims[2]],
            layers: 1,
            interleaved: false,
            sample: sample_of(self.kind)?,
            big_endian: true,
            slope: 1.0,
            inter: 0.0,
        })
    }

    /// Voxel to RAS as nibabel's `get_affine`: the axes' directions scaled by the voxel sizes,
    /// placed so that voxel `dims / 2` lands on the centre `Pxyz_c`. Without `goodRASFlag`
    /// FreeSurfer's default: 1 mm coronal slices (LIA) centred on the origin.
    fn affine(&self) -> Result<Affine, LoadError> {
        let (delta, mdc, center) = if self.good_ras > 0 {
            let widen = |v: [f32; 3]| v.map(f64::from);
            (widen(self.delta), self.mdc.map(widen), widen(self.center))
        } else {
            let lia = [[-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]];
            ([1.0; 3], lia, [0.0; 3])
        };
        let half = self.dims.map(|n| f64::from(n) / 2.0);
        let mut m = [[0.0; 4]; 3];
        for r in 0..3 {
            for c in 0..3 {
                m[r][c] = mdc[c][r] * delta[c];
            }
            m[r][3] = center[r] - (0..3).map(|c| m[r][c] * half[c]).sum::<f64>();
        }
        let affine = Affine(m);
        let source = "delta, Mdc and Pxyz_c";
        check_affine(&affine, FORMAT, Location::Byte(30), source)?;
        Ok(affine)
    }
}

fn sample_of(kind: i32) -> Result<Sample, LoadError> {
    Ok(match kind {
        0 => Sample::U8,
        1 => Sample::I32,
        3 => Sample::F32,
        4 => Sample::I16,
        10 => Sample::U16,
        _ => {
            return Err(LoadError::Unsupported {
                format: FORMAT,
                detail: format!(
                    "data type {kind} is not supported: a label map needs uchar (0), int (1), \
                     float (3), short (4) or ushort (10) voxels"
                ),
            })
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
