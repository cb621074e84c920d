//! The GLB container: a 12-byte header, a JSON chunk, then an optional BIN chunk.
//!
//! Split here rather than by the `gltf` crate so that every length is checked against the bytes
//! we hold and errors carry byte offsets (the crate's splitter underflows on a header length < 12).

use super::super::{Format, LoadError, Location};

const HEADER_LEN: usize = 12;
const CHUNK_HEADER_LEN: usize = 8;
const CHUNK_JSON: u32 = 0x4E4F_534A; // "JSON"
const CHUNK_BIN: u32 = 0x004E_4942; // "BIN\0"

/// The chunks of a GLB file, borrowed from the input.
pub(super) struct Glb<'a> {
    pub json: &'a [u8],
    /// Offset of the JSON chunk's first byte in the file, for error messages.
    pub json_offset: usize,
    pub bin: Option<&'a [u8]>,
}

fn read_u32(bytes: &[u8], at: usize) -> Option<u32> {
    let b = bytes.get(at..at.checked_add(4)?)?;
    Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

fn truncated(offset: usize, detail: String) -> LoadError {
    LoadError::Truncated {
        format: Format::Glb,
        offset,
        detail,
    }
}

/// The file's length as its GLB header declares it, after checking the magic, the version
/// and that the length fits the bytes and holds a JSON chunk's header.
fn declared_length(bytes: &[u8]) -> Result<usize, LoadError> {
    if bytes.len() < HEADER_LEN {
        return Err(truncated(
            bytes.len(),
            format!("the GLB header needs {HEADER_LEN} bytes"),
        ));
    }
    if !bytes.starts_with(b"glTF") {
        return Err(LoadError::BadMagic {
            format: Format::Glb,
            detail: "the first four bytes are not 'glTF'".into(),
        });
    }
    let version = read_u32(bytes, 4).unwrap_or(0);
    if version != 2 {
        return Err(LoadError::Unsupported {
            format: Format::Glb,
            detail: format!("GLB version {version} (only version 2 is readable)"),
        });
    }
    let declared = read_u32(bytes, 8).unwrap_or(0) as usize;
    if declared > bytes.len() {
        return Err(truncated(
            bytes.len(),
            format!("the header says the file is {declared} bytes long"),
        ));
    }
    if declared < HEADER_LEN + CHUNK_HEADER_LEN {
        return Err(LoadError::Syntax {
            format: Format::Glb,
            location: Location::Byte(8),
            detail: format!("the header's length {declared} is too small to hold a JSON chunk"),
        });
    }
    Ok(declared)
}

/// Splits a GLB file into its JSON and BIN chunks. Unknown chunk types are skipped, as the
/// specification asks of readers.
pub(super) fn split(bytes: &[u8]) -> Result<Glb<'_>, LoadError> {
    let declared = declared_length(bytes)?;
    // Bytes past the declared length are not part of the file.
    let file = &bytes[..declared];

    let mut at = HEADER_LEN;
    let mut json: Option<(usize, &[u8])> = None;
    let mut bin = None;
    while at < file.len() {
        let (Some(length), Some(kind)) = (read_u32(file, at), read_u32(file, at + 4)) else {
            return Err(truncated(
                file.len(),
                format!("chunk header at byte {at} needs {CHUNK_HEADER_LEN} bytes"),
            ));
        };
        let start = at + CHUNK_HEADER_LEN;
        let end = start
            .checked_add(length as usize)
            .filter(|&end| end <= file.len())
            .ok_or_else(|| {
                truncated(
                    file.len(),
                    format!(
                        "the chunk at byte {at} claims {length} bytes but only {} remain",
                        file.len() - start
                    ),
                )
            })?;
        let data = &file[start..end];
        match (json.is_some(), kind) {
            (false, CHUNK_JSON) => json = Some((start, data)),
            (false, _) => {
                return Err(LoadError::Syntax {
                    format: Format::Glb,
                    location: Location::Byte(at + 4),
                    detail: "the first chunk must be the JSON chunk".into(),
                })
            }
            (true, CHUNK_BIN) if bin.is_none() => bin = Some(data),
            (true, CHUNK_JSON) => {
                return Err(LoadError::Syntax {
                    format: Format::Glb,
                    location: Location::Byte(at + 4),
                    detail: "a second JSON chunk".into(),
                })
            }
            _ => {}
        }
        at = end;
    }
    let (json_offset, json) = json.ok_or_else(|| truncated(file.len(), "no JSON chunk".into()))?;
    Ok(Glb {
        json,
        json_offset,
        bin,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn glb(chunks: &[(u32, &[u8])]) -> Vec<u8> {
        let mut out = b"glTF".to_vec();
        out.extend(2u32.to_le_bytes());
        out.extend(0u32.to_le_bytes());
        for (kind, data) in chunks {
            out.extend((data.len() as u32).to_le_bytes());
            out.extend(kind.to_le_bytes());
            out.extend(*data);
        }
        let len = out.len() as u32;
        out[8..12].copy_from_slice(&len.to_le_bytes());
        out
    }

    #[test]
    fn splits_json_and_bin_and_skips_unknown_chunks() {
        let bytes = glb(&[
            (CHUNK_JSON, b"{}  "),
            (0x1234, b"xxxx"),
            (CHUNK_BIN, b"abcd"),
        ]);
        let g = split(&bytes).expect("valid container");
        assert_eq!(g.json, b"{}  ");
        assert_eq!(g.json_offset, 20);
        assert_eq!(g.bin, Some(&b"abcd"[..]));
    }

    #[test]
    fn rejects_a_chunk_longer_than_the_file() {
        let mut bytes = glb(&[(CHUNK_JSON, b"{}  ")]);
        bytes[12..16].copy_from_slice(&100u32.to_le_bytes());
        let err = split(&bytes).err();
        assert!(
            matches!(err, Some(LoadError::Truncated { offset: 24, .. })),
            "{err:?}"
        );
    }

    #[test]
    fn rejects_tiny_declared_length_and_bin_first() {
        let mut bytes = glb(&[(CHUNK_JSON, b"{}  ")]);
        bytes[8..12].copy_from_slice(&3u32.to_le_bytes());
        assert!(matches!(split(&bytes), Err(LoadError::Syntax { .. })));
        let bytes = glb(&[(CHUNK_BIN, b"abcd")]);
        assert!(matches!(
            split(&bytes),
            Err(LoadError::Syntax {
                location: Location::Byte(16),
                ..
            })
        ));
    }
}
