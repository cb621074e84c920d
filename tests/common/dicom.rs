//! Byte-level edits of the tests' compressed DICOM files (tests/data/make_dicom_compressed.py).
#![allow(dead_code)]

/// Where the first fragment's bytes start in `bytes` (explicit VR little endian): after the
/// Pixel Data header of undefined length, the offset table's item and the fragment's own item
/// header. An RLE fragment opens with its segment count, then the segments' offsets.
pub fn first_fragment(bytes: &[u8]) -> usize {
    let header = [
        0xE0, 0x7F, 0x10, 0x00, b'O', b'B', 0, 0, 0xFF, 0xFF, 0xFF, 0xFF,
    ];
    let at = (bytes.windows(header.len()).rposition(|w| w == header))
        .expect("encapsulated pixel data")
        + header.len();
    let table = u32::from_le_bytes(bytes[at + 4..at + 8].try_into().unwrap()) as usize;
    at + 8 + table + 8
}

/// `bytes` with the first RLE fragment's 32-bit word `index` (0: the segment count, 1..: the
/// segments' offsets) set to `value`.
pub fn with_rle_word(bytes: &[u8], index: usize, value: u32) -> Vec<u8> {
    let mut out = bytes.to_vec();
    let at = first_fragment(&out) + 4 * index;
    out[at..at + 4].copy_from_slice(&value.to_le_bytes());
    out
}

/// `bytes` with its first fragment split in two at `at` bytes into it: a frame over two
/// fragments, as some encoders write a large JPEG.
pub fn with_first_fragment_split(bytes: &[u8], at: usize) -> Vec<u8> {
    let start = first_fragment(bytes);
    let len = u32::from_le_bytes(bytes[start - 4..start].try_into().unwrap()) as usize;
    let item = |len: usize| [[0xFE, 0xFF, 0x00, 0xE0], (len as u32).to_le_bytes()].concat();
    let mut out = bytes[..start - 8].to_vec();
    out.extend(item(at));
    out.extend(&bytes[start..start + at]);
    out.extend(item(len - at));
    out.extend(&bytes[start + at..]);
    out
}
