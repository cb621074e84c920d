//! The files a segmentation command reads: its inputs and the colour table, named as given.

use crate::case::{EntryKind, FolderListing};
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

/// The files of a folder and of its subfolders (a DICOM export's series folders, a folder of
/// masks), each named by its path, as a [`FolderListing`] keeps them. Links are not followed.
pub(super) fn read_folder(dir: &Path) -> Result<Vec<(String, Vec<u8>)>, String> {
    let mut listing = FolderListing::default();
    let at = |e: String| format!("{}: {e}", dir.display());
    list(&mut listing, dir, 0).map_err(at)?;
    let files = listing.files().map_err(at)?;
    (files.into_iter()).map(|(_, path)| read(&path)).collect()
}

/// Lists `dir`, `depth` levels below the folder given, into `listing`; an error names a
/// subfolder that cannot be listed by its path.
fn list(listing: &mut FolderListing<PathBuf>, dir: &Path, depth: usize) -> Result<(), String> {
    let failed = |e: std::io::Error| format!("{}: {e}", dir.display());
    for entry in std::fs::read_dir(dir).map_err(failed)? {
        let entry = entry.map_err(failed)?;
        listing.count(1)?;
        let kind = entry.file_type().map_err(failed)?;
        let kind = EntryKind::of(kind.is_dir(), kind.is_file());
        let path = entry.path();
        if let Some(sub) = listing.take(path.display().to_string(), kind, depth, path)? {
            list(listing, &sub, depth + 1)?;
        }
    }
    Ok(())
}

impl Inputs {
    /// Reads every input, a folder's files as [`read_folder`] lists them, and the table; an
    /// error names the file.
    pub(super) fn read(inputs: &[PathBuf], table: Option<&Path>) -> Result<Self, String> {
        let mut files = Vec::new();
        for path in inputs {
            match path.is_dir() {
                true => files.extend(read_folder(path)?),
                false => files.push(read(path)?),
            }
        }
        Ok(Self {
            files,
            table: table.map(read).transpose()?,
        })
    }

    /// The files to open and the colour table naming their labels: the one given, else one
    /// among the files beside a label map, as the page takes a table dropped beside one.
    pub(super) fn named(&self) -> Result<(Vec<NamedBytes<'_>>, Option<NamedBytes<'_>>), String> {
        let files: Vec<NamedBytes> = self.files.iter().map(named).collect();
        match &self.table {
            Some(table) => Ok((files, Some(named(table)))),
            None => crate::case::split_color_table(&files).map_err(|e| e.to_string()),
        }
    }
}

fn named((name, bytes): &(String, Vec<u8>)) -> NamedBytes<'_> {
    NamedBytes { name, bytes }
}
