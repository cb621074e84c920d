//! Segmentations: label maps (one integer per voxel, one label per structure) and the named,
//! coloured structure surfaces extracted from them.
//!
//! Bytes -> [`crate::io`] (NIfTI, NRRD, colour tables) -> [`LabelMap`] -> one closed
//! [`crate::mesh::Mesh`] per label, in world millimetres (RAS).

mod label_map;

pub use label_map::{Affine, LabelLayer, LabelMap, Segment, MAX_LABELS};
