//! OBJ: v and f records.
use super::LoadError;
use crate::mesh::Mesh;

pub(super) fn parse(_bytes: &[u8]) -> Result<Mesh, LoadError> {
    Err(LoadError::Unsupported {
        format: super::Format::Obj,
        detail: "not yet readable".into(),
    })
}
