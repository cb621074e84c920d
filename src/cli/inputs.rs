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

/// The files of a folder and of its subfolders (a DICOM export's series folders, a folder of
/// masks), each named by its path, in [`crate::case::folder_order`]: every regular file in a
/// folder that [`crate::case::read_in_folder`] keeps. Links are not followed.
pub(super) fn read_folder(dir: &Path) -> Result<Vec<(String, Vec<u8>)>, String> {
    let mut walk = Walk::default();
    let at = |e: String| format!("{}: {e}", dir.display());
    walk.folder(dir, 0).map_err(at)?;
    if walk.files.is_empty() {
        return Err(at(crate::case::no_file_in_folder(walk.subfolders)));
    }
    walk.files
        .sort_by(|a, b| crate::case::folder_order(&a.0, &b.0));
    (walk.files.iter()).map(|(_, p)| read(p)).collect()
}

/// What a folder's listing found so far: files (by their path's text, and path), entries seen
/// and subfolders walked.
#[derive(Default)]
struct Walk {
    files: Vec<(String, PathBuf)>,
    entries: usize,
    subfolders: usize,
}

impl Walk {
    /// Lists `dir`, `depth` levels below the folder given; an error names a subfolder that
    /// cannot be listed by its path, and says when the limits are passed.
    fn folder(&mut self, dir: &Path, depth: usize) -> Result<(), String> {
        let failed = |e: std::io::Error| format!("{}: {e}", dir.display());
        for entry in std::fs::read_dir(dir).map_err(failed)? {
            let entry = entry.map_err(failed)?;
            self.entries += 1;
            if self.entries > crate::case::FOLDER_ENTRIES {
                return Err(crate::case::folder_too_large());
            }
            let name = entry.file_name().to_string_lossy().into_owned();
            if !crate::case::read_in_folder(&name) {
                continue;
            }
            let kind = entry.file_type().map_err(failed)?;
            if kind.is_dir() {
                if depth == crate::case::FOLDER_DEPTH {
                    return Err(crate::case::folder_too_deep());
                }
                self.subfolders += 1;
                self.folder(&entry.path(), depth + 1)?;
            } else if kind.is_file() {
                let path = entry.path();
                self.files.push((path.display().to_string(), path));
            }
        }
        Ok(())
    }
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
