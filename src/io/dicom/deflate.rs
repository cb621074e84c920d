//! Deflated Explicit VR Little Endian (PS3.5 A.5): everything after the file meta group is one
//! raw deflate stream of an explicit VR little-endian data set. It is inflated here, under a
//! limit, into the same file in plain explicit VR little endian (the meta group's transfer
//! syntax rewritten), which the length walk and dicom-rs then read as any other. dicom-rs can
//! inflate too (its `deflate` feature), but without a limit, and the walk must measure the
//! inflated lengths before dicom-rs allocates what they claim.

use std::io::{ErrorKind, Read};
use std::ops::Range;

use flate2::bufread::DeflateDecoder;

use crate::io::gzip::MAX_RATIO;
use crate::io::{Format, LoadError};

pub(in crate::io) const DEFLATED_EXPLICIT_LE: &str = "1.2.840.10008.1.2.1.99";
const EXPLICIT_LE_VALUE: &[u8; 20] = b"1.2.840.10008.1.2.1\0";

/// The most a deflated data set is inflated to: past the size of any segmentation or slice
/// meshsmooth opens, and within what the browser's 32-bit memory can hold twice.
pub(in crate::io) const MAX_INFLATED: u64 = 1 << 30;

/// Where a file's meta group lies: `group` from its group length element (0002,0000) to its
/// end, `syntax` the transfer syntax element (header and value).
pub(in crate::io) struct MetaGroup {
    pub group: Range<usize>,
    pub syntax: Range<usize>,
}

/// `bytes`, whose data set after `meta` is deflated, as the same file in explicit VR little
/// endian: "DICM", the meta group with its transfer syntax (and group length) rewritten, and
/// the inflated data set. Refused when the stream is corrupt, or inflates past
/// [`MAX_INFLATED`] or what deflate could expand the bytes to.
pub(in crate::io) fn as_explicit(
    bytes: &[u8],
    meta: &MetaGroup,
    format: Format,
) -> Result<Vec<u8>, LoadError> {
    let deflated = &bytes[meta.group.end..];
    let limit = (deflated.len() as u64)
        .saturating_mul(MAX_RATIO)
        .min(MAX_INFLATED);
    let mut out = b"DICM".to_vec();
    out.extend_from_slice(&meta_in_explicit(bytes, meta));
    inflate_into(&mut out, deflated, limit, format)?;
    Ok(out)
}

/// Appends what `deflated` inflates to onto `out`: refused past `limit` bytes, and growing
/// `out` by doubling, but never past the limit, so that a bomb costs the limit, not twice it.
fn inflate_into(
    out: &mut Vec<u8>,
    deflated: &[u8],
    limit: u64,
    format: Format,
) -> Result<(), LoadError> {
    let head = out.len();
    let cap = head.saturating_add(limit as usize).saturating_add(1);
    let mut stream = DeflateDecoder::new(deflated).take(limit + 1);
    let mut chunk = vec![0u8; 1 << 16];
    loop {
        let n = match stream.read(&mut chunk) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == ErrorKind::Interrupted => continue,
            Err(e) => {
                return Err(LoadError::Unsupported {
                    format,
                    detail: format!(
                        "the deflated data set does not inflate after {} bytes: {e}",
                        out.len() - head
                    ),
                })
            }
        };
        if out.len() + n > out.capacity() {
            let room = out.capacity().min(cap - out.len());
            out.reserve_exact(room.max(n));
        }
        out.extend_from_slice(&chunk[..n]);
    }
    if (out.len() - head) as u64 > limit {
        return Err(LoadError::Unsupported {
            format,
            detail: format!(
                "the deflated data set inflates past {limit} bytes, the most read from its {} \
                 (at most {MAX_RATIO} times as many, and {MAX_INFLATED})",
                deflated.len()
            ),
        });
    }
    Ok(())
}

/// The meta group with the transfer syntax explicit VR little endian, and its group length
/// changed by as much as the value's length did.
fn meta_in_explicit(bytes: &[u8], meta: &MetaGroup) -> Vec<u8> {
    let group = meta.group.clone();
    // (0002,0000) UL: an 8-byte header, then the length of the rest of the group.
    let rest = group.end - (group.start + 12);
    let rewritten = 8 + EXPLICIT_LE_VALUE.len();
    let length = rest - meta.syntax.len() + rewritten;
    let mut out = Vec::with_capacity(group.len() + rewritten);
    out.extend_from_slice(&bytes[group.start..group.start + 8]);
    out.extend_from_slice(&(length as u32).to_le_bytes());
    out.extend_from_slice(&bytes[group.start + 12..meta.syntax.start]);
    out.extend_from_slice(&[0x02, 0x00, 0x10, 0x00, b'U', b'I']);
    out.extend_from_slice(&(EXPLICIT_LE_VALUE.len() as u16).to_le_bytes());
    out.extend_from_slice(EXPLICIT_LE_VALUE);
    out.extend_from_slice(&bytes[meta.syntax.end..group.end]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use flate2::write::DeflateEncoder;
    use std::io::Write;

    fn deflate(bytes: &[u8]) -> Vec<u8> {
        let mut encoder = DeflateEncoder::new(Vec::new(), flate2::Compression::best());
        encoder.write_all(bytes).expect("in memory");
        encoder.finish().expect("in memory")
    }

    #[test]
    fn a_stream_past_the_limit_is_refused_holding_no_more_than_it() {
        let bomb = deflate(&vec![0u8; 4 << 20]);
        let mut out = b"head".to_vec();
        let e = inflate_into(&mut out, &bomb, 100_000, Format::DicomSeg).expect_err("refused");
        assert!(e.to_string().contains("inflates past 100000 bytes"), "{e}");
        assert!(
            out.capacity() <= 4 + 100_001 + (1 << 16),
            "{}",
            out.capacity()
        );

        let mut out = b"head".to_vec();
        inflate_into(&mut out, &bomb, 4 << 20, Format::DicomSeg).expect("at the limit");
        assert_eq!(out.len(), 4 + (4 << 20));
        assert!(out[4..].iter().all(|&b| b == 0));
    }
}
