//! Segmentations: label maps (one integer per voxel, one label per structure) and the named,
//! coloured structure surfaces extracted from them.
//!
//! Bytes -> [`crate::io`] (NIfTI, NRRD, colour tables) -> [`crate::io::LabelMap`] -> [`extract`] -> one
//! closed [`crate::mesh::Mesh`] per label, in world millimetres (RAS).

mod cube_table;
mod extract;
mod from_label_maps;
mod palette;
mod specks;
mod structure;

pub use from_label_maps::{
    open, open_staged, reading_stages, structure_name, NamedBytes, OpenError, OpenOptions,
};
pub use palette::default_color;
pub use structure::{extract, labels, ExtractError, ExtractOptions, LabelInfo, Structure};

#[cfg(test)]
mod tests;
