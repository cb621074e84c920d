//! Assembles GLB files from a glTF document and its binary chunk, for the readers' tests.

use serde_json::Value;

/// A GLB of `doc` and `bin`, each chunk padded to four bytes (JSON with spaces, BIN with zeros).
pub fn glb(doc: &Value, bin: &[u8]) -> Vec<u8> {
    let mut json = doc.to_string().into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut bin = bin.to_vec();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(((28 + json.len() + bin.len()) as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&json);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(&bin);
    out
}

/// The JSON chunk and the binary chunk of a GLB `glb` assembled (not every test reads one back).
#[allow(dead_code)]
pub fn parts(bytes: &[u8]) -> (Value, Vec<u8>) {
    let len = u32::from_le_bytes(bytes[12..16].try_into().expect("4")) as usize;
    let json = serde_json::from_slice(&bytes[20..20 + len]).expect("JSON");
    (json, bytes[20 + len + 8..].to_vec())
}
