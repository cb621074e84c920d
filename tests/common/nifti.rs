//! Writes NIfTI-1 label maps for the tests and the benchmarks' generated cases.

/// A NIfTI-1 header (352 bytes, data right after) for `dims` uint8 labels with the given sform
/// (code 2), qform code 0 and `pixdim` as the voxel sizes it states.
pub fn nifti_header(dims: [usize; 3], sform: [[f32; 4]; 3], pixdim: [f32; 3]) -> Vec<u8> {
    let mut h = vec![0u8; 352];
    h[0..4].copy_from_slice(&348i32.to_le_bytes());
    let dim: [i16; 8] = [
        3,
        dims[0] as i16,
        dims[1] as i16,
        dims[2] as i16,
        1,
        1,
        1,
        1,
    ];
    for (i, d) in dim.iter().enumerate() {
        h[40 + 2 * i..42 + 2 * i].copy_from_slice(&d.to_le_bytes());
    }
    h[70..72].copy_from_slice(&2i16.to_le_bytes()); // datatype uint8
    h[72..74].copy_from_slice(&8i16.to_le_bytes()); // bitpix
    let pixdim = [1.0f32, pixdim[0], pixdim[1], pixdim[2]];
    for (i, p) in pixdim.iter().enumerate() {
        h[76 + 4 * i..80 + 4 * i].copy_from_slice(&p.to_le_bytes());
    }
    h[108..112].copy_from_slice(&352f32.to_le_bytes()); // vox_offset
    h[123] = 2; // xyzt_units: millimetres
    h[254..256].copy_from_slice(&2i16.to_le_bytes()); // sform_code
    for (r, row) in sform.iter().enumerate() {
        for (c, v) in row.iter().enumerate() {
            let at = 280 + 16 * r + 4 * c;
            h[at..at + 4].copy_from_slice(&v.to_le_bytes());
        }
    }
    h[344..348].copy_from_slice(b"n+1\0");
    h
}
