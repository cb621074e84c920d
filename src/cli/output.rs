//! Where the command-line tool writes its files: checked before any work starts, and replaced
//! whole or not at all, so a failed or interrupted write (a full disk, a killed process) never
//! leaves a half-written file where the user had a good one.

use std::fs;
use std::path::{Path, PathBuf};

/// Refuses a destination that cannot be written before the work that would fill it (a
/// suggestion on a large mesh takes seconds): its folder must exist, and it must be neither a
/// folder nor a read-only file.
pub(crate) fn check_destination(path: &Path) -> Result<(), String> {
    if path.is_dir() {
        return Err(format!("{}: is a folder, not a file", path.display()));
    }
    if read_only(path) {
        return Err(read_only_error(path));
    }
    let folder = folder_of(path);
    if !folder.is_dir() {
        return Err(format!(
            "{}: the folder {} does not exist",
            path.display(),
            folder.display()
        ));
    }
    Ok(())
}

/// Writes `path` through `write`, which fills a temporary file beside it; the temporary file
/// then replaces `path` in one rename. A file already at `path` keeps its permissions, and a
/// link at `path` keeps pointing where it did (the file it names is replaced); a read-only file
/// is refused, as writing into it would be. On any error the temporary file is removed and
/// whatever was at `path` is left as it was.
pub(crate) fn write_whole(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), String> {
    let target = fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
    if read_only(&target) {
        return Err(read_only_error(path));
    }
    let temporary = temporary_beside(&target);
    let result = write(&temporary).and_then(|()| {
        if let Ok(existing) = fs::metadata(&target) {
            fs::set_permissions(&temporary, existing.permissions())
                .map_err(|e| format!("{}: {e}", path.display()))?;
        }
        fs::rename(&temporary, &target).map_err(|e| format!("{}: {e}", path.display()))
    });
    if result.is_err() {
        fs::remove_file(&temporary).ok();
    }
    result
}

/// [`write_whole`] for bytes at hand.
pub(crate) fn write_file(path: &Path, bytes: &[u8]) -> Result<(), String> {
    write_whole(path, |temporary| {
        fs::write(temporary, bytes).map_err(|e| format!("{}: {e}", path.display()))
    })
}

fn read_only(path: &Path) -> bool {
    fs::metadata(path).is_ok_and(|m| m.permissions().readonly())
}

fn read_only_error(path: &Path) -> String {
    format!("{}: the file is read-only", path.display())
}

/// The folder `path` is in (the current one for a bare file name).
fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// A name beside `path` that no other run of the tool picks: hidden, with the process id, and
/// the same extension (writers that go by the extension, such as the PNG encoder, still see it).
fn temporary_beside(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map_or_else(|| "output".into(), |n| n.to_string_lossy());
    let extension = path
        .extension()
        .map_or_else(String::new, |e| format!(".{}", e.to_string_lossy()));
    folder_of(path).join(format!(
        ".{name}.meshsmooth-{}.partial{extension}",
        std::process::id()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("meshsmooth-output-{name}-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn entries(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_and_no_litter() {
        let dir = scratch("failed");
        let path = dir.join("model.ply");
        fs::write(&path, b"the user's model").unwrap();
        let err = write_whole(&path, |temporary| {
            fs::write(temporary, b"half of a").unwrap();
            Err("disk full".into())
        })
        .unwrap_err();
        assert_eq!(err, "disk full");
        assert_eq!(fs::read(&path).unwrap(), b"the user's model");
        assert_eq!(entries(&dir), ["model.ply"]);
        fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn a_write_replaces_the_file_whole_and_refuses_a_read_only_one() {
        let dir = scratch("replace");
        let path = dir.join("model.ply");
        fs::write(&path, b"old").unwrap();
        write_file(&path, b"new model").unwrap();
        assert_eq!(fs::read(&path).unwrap(), b"new model");
        assert_eq!(entries(&dir), ["model.ply"]);
        // A new file is simply created.
        write_file(&dir.join("new.stl"), b"x").unwrap();
        assert_eq!(entries(&dir), ["model.ply", "new.stl"]);
        let mut permissions = fs::metadata(&path).unwrap().permissions();
        permissions.set_readonly(true);
        fs::set_permissions(&path, permissions.clone()).unwrap();
        let err = write_file(&path, b"newer").unwrap_err();
        assert!(err.contains("read-only"), "{err}");
        assert_eq!(fs::read(&path).unwrap(), b"new model");
        #[allow(clippy::permissions_set_readonly_false)]
        permissions.set_readonly(false);
        fs::set_permissions(&path, permissions).unwrap();
        fs::remove_dir_all(&dir).ok();
    }

    #[cfg(unix)]
    #[test]
    fn a_replaced_file_keeps_its_mode() {
        use std::os::unix::fs::PermissionsExt;
        let dir = scratch("mode");
        let path = dir.join("model.ply");
        fs::write(&path, b"old").unwrap();
        fs::set_permissions(&path, fs::Permissions::from_mode(0o640)).unwrap();
        write_file(&path, b"new").unwrap();
        let mode = fs::metadata(&path).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o640);
        fs::remove_dir_all(&dir).ok();
    }

    #[cfg(unix)]
    #[test]
    fn a_link_keeps_pointing_at_the_file_it_names() {
        let dir = scratch("link");
        let real = dir.join("real.ply");
        let link = dir.join("link.ply");
        fs::write(&real, b"old").unwrap();
        std::os::unix::fs::symlink(&real, &link).unwrap();
        write_file(&link, b"new").unwrap();
        assert!(fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(fs::read(&real).unwrap(), b"new");
        fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn destinations_are_checked_before_the_work() {
        let dir = scratch("check");
        assert!(check_destination(&dir.join("out.ply")).is_ok());
        assert!(check_destination(Path::new("out.ply")).is_ok());
        let missing = dir.join("no such folder").join("out.ply");
        let err = check_destination(&missing).unwrap_err();
        assert!(err.contains("does not exist"), "{err}");
        let err = check_destination(&dir).unwrap_err();
        assert!(err.contains("is a folder"), "{err}");
        fs::remove_dir_all(&dir).ok();
    }
}
