//! PLY: ASCII and binary.
use super::LoadError;
use crate::mesh::Mesh;

pub(super) fn parse(_bytes: &[u8]) -> Result<Mesh, LoadError> {
    Err(LoadError::Unsupported {
        format: super::Format::Ply,
        detail: "not yet readable".into(),
    })
}
