//! Segmentations: label maps (one integer per voxel, one label per structure) and the named,
//! coloured structure surfaces extracted from them.
//!
//! Bytes -> [`crate::io`] (NIfTI, NRRD, colour tables) -> [`crate::io::LabelMap`] -> [`extract`] -> one
//! closed [`crate::mesh::Mesh`] per label, in world millimetres (RAS), coded where its name is
//! a standard one ([`standard_class`]).

mod cube_table;
mod extract;
mod from_label_maps;
mod palette;
mod specks;
mod standard_codes;
mod structure;

pub use from_label_maps::{
    open, open_staged, reading_stages, structure_name, NamedBytes, OpenError, OpenOptions,
};
pub use palette::default_color;
pub use standard_codes::{standard_class, StandardClass};
pub use structure::{extract, labels, ExtractError, ExtractOptions, LabelInfo, Structure};

#[cfg(test)]
mod tests;
