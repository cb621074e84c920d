//! The files a segmentation command reads: its inputs and the colour table, named as given.

use crate::segmentation::NamedBytes;
use std::path::{Path, PathBuf};

pub(super) struct Inputs {
    files: Vec<(String, Vec<u8>)>,
    table: Option<(String, Vec<u8>)>,
}

fn read(path: &Path) -> Result<(String, Vec<u8>), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok((path.display().to_string(), bytes))
}

/// The files of a folder (a DICOM series' slices), sorted by name: every regular file that
/// [`crate::case::read_in_folder`] keeps.
pub(super) fn read_folder(dir: &Path) -> Result<Vec<(String, Vec<u8>)>, String> {
    let failed = |e: std::io::Error| format!("{}: {e}", dir.display());
    let (mut paths, mut subfolders) = (Vec::new(), 0);
    for entry in std::fs::read_dir(dir).map_err(failed)? {
        let entry = entry.map_err(failed)?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let kind = entry.file_type().map_err(failed)?;
        subfolders += usize::from(kind.is_dir());
        if crate::case::read_in_folder(&name) && kind.is_file() {
            paths.push(entry.path());
        }
    }
    if paths.is_empty() {
        let why = crate::case::no_file_in_folder(subfolders);
        return Err(format!("{}: {why}", dir.display()));
    }
    paths.sort();
    paths.iter().map(|p| read(p)).collect()
}

impl Inputs {
    /// Reads every input and the table; an error names the file.
    pub(super) fn read(inputs: &[PathBuf], table: Option<&Path>) -> Result<Self, String> {
        Ok(Self {
            files: inputs.iter().map(|p| read(p)).collect::<Result<_, _>>()?,
            table: table.map(read).transpose()?,
        })
    }

    pub(super) fn files(&self) -> Vec<NamedBytes<'_>> {
        self.files
            .iter()
            .map(|(name, bytes)| NamedBytes { name, bytes })
            .collect()
    }

    pub(super) fn table(&self) -> Option<NamedBytes<'_>> {
        self.table
            .as_ref()
            .map(|(name, bytes)| NamedBytes { name, bytes })
    }
}
