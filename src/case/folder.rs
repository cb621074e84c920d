//! A folder opened as one case's files, with its subfolders: which entries are read, how deep
//! and how many, in what order, and what is said when it holds nothing. The CLI lists folders
//! on disk and the page a dropped folder through the browser's entries; each keeps only its
//! I/O and hands every entry to a [`FolderListing`].

use super::from_files::file_name;

/// A folder is read with its subfolders (a DICOM export keeps each series some levels below
/// the folder a user picks) down to this many levels below it...
pub const FOLDER_DEPTH: usize = 8;
/// ...and up to this many entries in all: the listing stays bounded.
pub const FOLDER_ENTRIES: usize = 20_000;

/// Whether a file or subfolder found in a folder opens with the folder's others: every one but
/// hidden ones (a file manager's `.DS_Store`) and a DICOMDIR index, which holds no slice or
/// segment.
pub fn read_in_folder(name: &str) -> bool {
    let name = file_name(name);
    !name.starts_with('.') && !name.eq_ignore_ascii_case("DICOMDIR")
}

/// The order a folder's files open in: by their paths, folder by folder (`a/b` before `a-c`).
pub fn folder_order(a: &str, b: &str) -> std::cmp::Ordering {
    a.split(['/', '\\']).cmp(b.split(['/', '\\']))
}

/// What an entry of a folder is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EntryKind {
    Folder,
    File,
    /// A link or a device: not followed, not read.
    Other,
}

impl EntryKind {
    /// The kind of an entry that is a folder, a regular file, or neither.
    pub fn of(folder: bool, file: bool) -> Self {
        match (folder, file) {
            (true, _) => EntryKind::Folder,
            (_, true) => EntryKind::File,
            _ => EntryKind::Other,
        }
    }
}

/// What a folder's listing found so far: the files to open, each by its path and what the
/// lister reads it by (`F`), the entries counted and the subfolders walked.
#[derive(Debug)]
pub struct FolderListing<F> {
    files: Vec<(String, F)>,
    entries: usize,
    subfolders: usize,
}

impl<F> Default for FolderListing<F> {
    fn default() -> Self {
        Self {
            files: Vec::new(),
            entries: 0,
            subfolders: 0,
        }
    }
}

impl<F> FolderListing<F> {
    /// Entries listed so far, every one counted (those left out too).
    pub fn entries(&self) -> usize {
        self.entries
    }

    /// How many more entries a lister may read before the listing is refused: it stops
    /// asking the folder for more past this.
    pub fn room(&self) -> usize {
        (FOLDER_ENTRIES + 1).saturating_sub(self.entries)
    }

    /// Counts `count` entries more; refused once they pass [`FOLDER_ENTRIES`].
    pub fn count(&mut self, count: usize) -> Result<(), String> {
        self.entries = self.entries.saturating_add(count);
        if self.entries > FOLDER_ENTRIES {
            return Err(format!(
                "the folder and its subfolders hold more than {FOLDER_ENTRIES} entries: open \
                 the folder of one series or one set of masks"
            ));
        }
        Ok(())
    }

    /// Takes an entry (counted already) found `depth` levels below the folder given, at `path`
    /// (its name last): a file is kept, a subfolder handed back to be listed at `depth + 1`;
    /// hidden entries, a DICOMDIR and links are left out. A subfolder deeper than
    /// [`FOLDER_DEPTH`] is refused.
    pub fn take(
        &mut self,
        path: String,
        kind: EntryKind,
        depth: usize,
        item: F,
    ) -> Result<Option<F>, String> {
        if !read_in_folder(&path) {
            return Ok(None);
        }
        match kind {
            EntryKind::Folder if depth >= FOLDER_DEPTH => Err(format!(
                "its subfolders go more than {FOLDER_DEPTH} levels down: open the folder that \
                 holds the files"
            )),
            EntryKind::Folder => {
                self.subfolders += 1;
                Ok(Some(item))
            }
            EntryKind::File => {
                self.files.push((path, item));
                Ok(None)
            }
            EntryKind::Other => Ok(None),
        }
    }

    /// The files found, in [`folder_order`]; refused when there are none.
    pub fn files(mut self) -> Result<Vec<(String, F)>, String> {
        if self.files.is_empty() {
            return Err(match self.subfolders {
                0 => "the folder holds no file".to_string(),
                n => format!("neither the folder nor its {n} subfolder(s) hold a file"),
            });
        }
        self.files.sort_by(|a, b| folder_order(&a.0, &b.0));
        Ok(self.files)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_folders_hidden_files_and_dicomdir_are_not_read_with_its_others() {
        for kept in [
            "liver.nii.gz",
            "masks/kidney_left.nii.gz",
            "IM0001",
            "dicomdir.txt",
        ] {
            assert!(read_in_folder(kept), "{kept}");
        }
        for skipped in [
            ".DS_Store",
            "masks/._liver.nii.gz",
            "DICOMDIR",
            "series\\dicomdir",
        ] {
            assert!(!read_in_folder(skipped), "{skipped}");
        }
    }

    #[test]
    fn a_folders_files_open_in_the_order_of_their_paths_folder_by_folder() {
        let mut paths = vec![
            "export/SE2/IM1",
            "export/a-c.nii.gz",
            "export\\a\\z.nii.gz",
            "export/SE10/IM1",
            "export/a/b.nii.gz",
            "export/SE1/IM2",
            "export/SE1/IM10",
        ];
        paths.sort_by(|a, b| folder_order(a, b));
        let want = [
            "export/SE1/IM10",
            "export/SE1/IM2",
            "export/SE10/IM1",
            "export/SE2/IM1",
            "export/a/b.nii.gz",
            "export\\a\\z.nii.gz",
            "export/a-c.nii.gz",
        ];
        assert_eq!(paths, want);
    }

    #[test]
    fn a_listing_keeps_files_walks_subfolders_and_leaves_out_the_rest() {
        let mut listing = FolderListing::default();
        let mut take = |path: &str, kind, depth| listing.take(path.into(), kind, depth, path.len());
        assert_eq!(take("x/SE1", EntryKind::Folder, 0), Ok(Some(5)));
        assert_eq!(take("x/SE1/IM2", EntryKind::File, 1), Ok(None));
        assert_eq!(take("x/.git", EntryKind::Folder, 0), Ok(None));
        assert_eq!(take("x/DICOMDIR", EntryKind::File, 0), Ok(None));
        assert_eq!(take("x/link", EntryKind::Other, 0), Ok(None));
        assert_eq!(take("x/a.nii", EntryKind::File, 0), Ok(None));
        let deep = take("x/1/2/3/4/5/6/7/8/9", EntryKind::Folder, FOLDER_DEPTH).unwrap_err();
        assert!(deep.contains("more than 8 levels down"), "{deep}");
        let files = listing.files().unwrap();
        assert_eq!(files, vec![("x/SE1/IM2".into(), 9), ("x/a.nii".into(), 7)]);
        let kinds =
            [(true, false), (false, true), (false, false)].map(|(d, f)| EntryKind::of(d, f));
        assert_eq!(
            kinds,
            [EntryKind::Folder, EntryKind::File, EntryKind::Other]
        );
    }

    #[test]
    fn a_listing_is_bounded_and_says_when_nothing_was_found() {
        let mut listing: FolderListing<()> = FolderListing::default();
        assert_eq!(listing.room(), FOLDER_ENTRIES + 1);
        listing.count(FOLDER_ENTRIES).unwrap();
        assert_eq!((listing.entries(), listing.room()), (FOLDER_ENTRIES, 1));
        let e = listing.count(1).unwrap_err();
        assert!(e.contains("more than 20000 entries"), "{e}");
        assert_eq!(listing.room(), 0);

        let empty: FolderListing<()> = FolderListing::default();
        assert_eq!(empty.files().unwrap_err(), "the folder holds no file");
        let mut nested = FolderListing::default();
        nested.take("x/a".into(), EntryKind::Folder, 0, ()).unwrap();
        nested
            .take("x/a/b".into(), EntryKind::Folder, 1, ())
            .unwrap();
        let e = nested.files().unwrap_err();
        assert_eq!(e, "neither the folder nor its 2 subfolder(s) hold a file");
    }
}
