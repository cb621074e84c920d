//! Label-map files built byte by byte for the tests: NIfTI-1 and NIfTI-2 headers in either byte
//! order, NRRD headers, gzip, and voxel arrays in a chosen byte order.

use flate2::write::GzEncoder;
use flate2::Compression;
use std::io::Write;

/// The NIfTI header fields the reader uses, written at their offsets.
#[derive(Clone, Debug)]
pub struct Nifti {
    pub version: u8,
    pub big: bool,
    pub dim: [i64; 8],
    pub datatype: i16,
    pub pixdim: [f64; 8],
    pub vox_offset: f64,
    pub slope: f64,
    pub inter: f64,
    pub qform_code: i32,
    pub sform_code: i32,
    /// quatern_b, c, d, qoffset_x, y, z.
    pub quatern: [f64; 6],
    pub srow: [[f64; 4]; 3],
    /// Voxel bytes, already in the file's byte order.
    pub data: Vec<u8>,
}

/// NIfTI datatype codes.
pub const UINT8: i16 = 2;
pub const INT16: i16 = 4;
pub const INT32: i16 = 8;
pub const FLOAT32: i16 = 16;
pub const UINT16: i16 = 512;

impl Nifti {
    /// A 3D little-endian NIfTI-1 with unit voxels and no transform codes.
    pub fn new(dims: [i64; 3], datatype: i16, data: Vec<u8>) -> Self {
        Nifti {
            version: 1,
            big: false,
            dim: [3, dims[0], dims[1], dims[2], 1, 1, 1, 1],
            datatype,
            pixdim: [1.0; 8],
            vox_offset: 352.0,
            slope: 0.0,
            inter: 0.0,
            qform_code: 0,
            sform_code: 0,
            quatern: [0.0; 6],
            srow: [[0.0; 4]; 3],
            data,
        }
    }

    pub fn u8(dims: [i64; 3], values: &[u8]) -> Self {
        Self::new(dims, UINT8, values.to_vec())
    }

    /// The same file as NIfTI-2, in the given byte order (data re-encoded by the caller).
    pub fn v2(mut self) -> Self {
        self.version = 2;
        self.vox_offset = 544.0;
        self
    }

    pub fn with_sform(mut self, srow: [[f64; 4]; 3]) -> Self {
        self.sform_code = 1;
        self.srow = srow;
        self
    }

    /// The whole `.nii`: header, zero padding up to vox_offset, voxels.
    pub fn bytes(&self) -> Vec<u8> {
        let v2 = self.version == 2;
        let size = if v2 { 540 } else { 348 };
        let start = if self.vox_offset.is_finite() && self.vox_offset >= size as f64 {
            self.vox_offset as usize
        } else {
            size + 4
        };
        let mut out = vec![0u8; start.max(size)];
        let mut w = Writer {
            out: &mut out,
            big: self.big,
        };
        w.i32(0, size as i32);
        let (dim, dim_step) = if v2 { (16, 8) } else { (40, 2) };
        for (i, &d) in self.dim.iter().enumerate() {
            if v2 {
                w.i64(dim + i * dim_step, d);
            } else {
                w.i16(dim + i * dim_step, d as i16);
            }
        }
        let real = |w: &mut Writer<'_>, at: usize, v: f64| {
            if v2 {
                w.f64(at, v)
            } else {
                w.f32(at, v as f32)
            }
        };
        let width = if v2 { 8 } else { 4 };
        let f = if v2 { V2 } else { V1 };
        w.i16(f.datatype, self.datatype);
        for (i, &p) in self.pixdim.iter().enumerate() {
            real(&mut w, f.pixdim + i * width, p);
        }
        if v2 {
            w.i64(f.vox_offset, self.vox_offset as i64);
        } else {
            w.f32(f.vox_offset, self.vox_offset as f32);
        }
        real(&mut w, f.scl, self.slope);
        real(&mut w, f.scl + width, self.inter);
        if v2 {
            w.i32(f.qform_code, self.qform_code);
            w.i32(f.sform_code, self.sform_code);
        } else {
            w.i16(f.qform_code, self.qform_code as i16);
            w.i16(f.sform_code, self.sform_code as i16);
        }
        for (i, &q) in self.quatern.iter().enumerate() {
            real(&mut w, f.quatern + i * width, q);
        }
        for (r, row) in self.srow.iter().enumerate() {
            for (c, &v) in row.iter().enumerate() {
                real(&mut w, f.srow + (r * 4 + c) * width, v);
            }
        }
        if v2 {
            out[4..12].copy_from_slice(b"n+2\0\r\n\x1a\n");
        } else {
            out[344..348].copy_from_slice(b"n+1\0");
        }
        out.extend_from_slice(&self.data);
        out
    }
}

struct Offsets {
    datatype: usize,
    pixdim: usize,
    vox_offset: usize,
    scl: usize,
    qform_code: usize,
    sform_code: usize,
    quatern: usize,
    srow: usize,
}

const V1: Offsets = Offsets {
    datatype: 70,
    pixdim: 76,
    vox_offset: 108,
    scl: 112,
    qform_code: 252,
    sform_code: 254,
    quatern: 256,
    srow: 280,
};

const V2: Offsets = Offsets {
    datatype: 12,
    pixdim: 104,
    vox_offset: 168,
    scl: 176,
    qform_code: 344,
    sform_code: 348,
    quatern: 352,
    srow: 400,
};

struct Writer<'a> {
    out: &'a mut Vec<u8>,
    big: bool,
}

macro_rules! put {
    ($name:ident, $t:ty) => {
        fn $name(&mut self, at: usize, v: $t) {
            let b = if self.big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            };
            self.out[at..at + b.len()].copy_from_slice(&b);
        }
    };
}

impl Writer<'_> {
    put!(i16, i16);
    put!(i32, i32);
    put!(i64, i64);
    put!(f32, f32);
    put!(f64, f64);
}

/// Voxel values as bytes in the given byte order.
pub fn encode<T: Copy, const N: usize>(
    values: &[T],
    big: bool,
    le: fn(T) -> [u8; N],
    be: fn(T) -> [u8; N],
) -> Vec<u8> {
    values
        .iter()
        .flat_map(|&v| if big { be(v) } else { le(v) })
        .collect()
}

pub fn i16s(values: &[i16], big: bool) -> Vec<u8> {
    encode(values, big, i16::to_le_bytes, i16::to_be_bytes)
}

pub fn u16s(values: &[u16], big: bool) -> Vec<u8> {
    encode(values, big, u16::to_le_bytes, u16::to_be_bytes)
}

pub fn i32s(values: &[i32], big: bool) -> Vec<u8> {
    encode(values, big, i32::to_le_bytes, i32::to_be_bytes)
}

pub fn f32s(values: &[f32], big: bool) -> Vec<u8> {
    encode(values, big, f32::to_le_bytes, f32::to_be_bytes)
}

pub fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = GzEncoder::new(Vec::new(), Compression::fast());
    e.write_all(bytes).expect("in memory");
    e.finish().expect("in memory")
}

/// An attached NRRD: magic, the header lines, the blank line, the data.
pub fn nrrd(header: &str, data: &[u8]) -> Vec<u8> {
    let mut out = format!("NRRD0004\n{}\n\n", header.trim()).into_bytes();
    out.extend_from_slice(data);
    out
}

/// An MGH file: the header fields, zeros to byte 284, the voxels (`int16`), a footer.
pub fn mgh(dims: [i32; 4], kind: i32, good_ras: i16, delta: [f32; 3], voxels: &[i16]) -> Vec<u8> {
    let mut b = Vec::new();
    b.extend(1i32.to_be_bytes());
    dims.iter().for_each(|d| b.extend(d.to_be_bytes()));
    b.extend(kind.to_be_bytes());
    b.extend(0i32.to_be_bytes());
    b.extend(good_ras.to_be_bytes());
    delta.iter().for_each(|d| b.extend(d.to_be_bytes()));
    let mdc_and_centre = [
        1.0f32, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 10.0, 20.0, 30.0,
    ];
    mdc_and_centre
        .iter()
        .for_each(|v| b.extend(v.to_be_bytes()));
    b.resize(284, 0);
    voxels.iter().for_each(|v| b.extend(v.to_be_bytes()));
    b.extend([0u8; 20]);
    b
}
