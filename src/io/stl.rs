//! STL, binary and ASCII. Triangle soup, welded by exact position equality.
use super::LoadError;
use crate::mesh::Mesh;

pub(super) fn parse(_bytes: &[u8]) -> Result<Mesh, LoadError> {
    Err(LoadError::Unsupported {
        format: super::Format::Stl,
        detail: "not yet readable".into(),
    })
}
