//! Folders dropped on the page. eframe hands the app every dropped item as a file, a folder as
//! one it cannot read; so a listener on the window, which the browser calls before eframe's on
//! the canvas, takes each drop that holds a folder and lists the folder with the browser's File
//! and Directory Entries API. A folder's files open as the CLI reads a folder (a
//! [`FolderListing`]: with its subfolders, in the order of their paths), with the files dropped
//! beside it, as one case. What cannot be read is named: the folder, or the
//! subfolder or file by its path in it.

use std::cell::Cell;
use std::rc::Rc;

use js_sys::{Array, Function, Promise};
use wasm_bindgen::closure::Closure;
use wasm_bindgen::{JsCast, JsValue};
use wasm_bindgen_futures::JsFuture;
use web_sys::{FileSystemDirectoryEntry, FileSystemEntry, FileSystemFileEntry};

use super::read_bytes::OnProgress;
use crate::case::{EntryKind, FolderListing};

/// A drop's files in order, each named by its path in the drop (`masks/liver.nii.gz`); or the
/// item that could not be listed and why.
pub type Listed = Result<Vec<(String, web_sys::File)>, (String, String)>;

/// The `drop` listener, and how many of eframe's dropped files belong to drops it took.
pub struct FolderDrops {
    _listener: Closure<dyn FnMut(web_sys::DragEvent)>,
    taken: Rc<Cell<usize>>,
}

impl FolderDrops {
    /// Listens on the window; `take` gets each taken drop's items, to [`list`].
    pub fn listen(take: Rc<dyn Fn(Vec<FileSystemEntry>)>) -> Result<FolderDrops, String> {
        let window = web_sys::window().ok_or("no window")?;
        let taken = Rc::new(Cell::new(0));
        let listener = {
            let taken = taken.clone();
            Closure::<dyn FnMut(web_sys::DragEvent)>::new(move |event: web_sys::DragEvent| {
                let Some(transfer) = event.data_transfer() else {
                    return;
                };
                let entries = entries_of(&transfer);
                if !entries.iter().any(|e| e.is_directory()) {
                    return;
                }
                // eframe still sees the drop (it ends its hover hint) and hands on its files;
                // the app skips as many.
                let files = transfer.files().map_or(0, |f| f.length() as usize);
                taken.set(taken.get() + files);
                event.prevent_default();
                take(entries);
            })
        };
        window
            .add_event_listener_with_callback_and_bool(
                "drop",
                listener.as_ref().unchecked_ref(),
                true,
            )
            .map_err(|e| super::page::js_error_text(&e))?;
        Ok(FolderDrops {
            _listener: listener,
            taken,
        })
    }

    /// How many of the files eframe hands on next belong to taken drops (then 0 again).
    pub fn take_skipped(&self) -> usize {
        self.taken.replace(0)
    }
}

/// The drop's items as entries; the browser gives them only while the drop is handled.
fn entries_of(transfer: &web_sys::DataTransfer) -> Vec<FileSystemEntry> {
    let items = transfer.items();
    (0..items.length())
        .filter_map(|i| items.get(i))
        .filter_map(|item| item.webkit_get_as_entry().ok().flatten())
        .collect()
}

/// Every file of the dropped items: loose files as they are, each folder's files (its
/// subfolders' too) as a [`FolderListing`] keeps them; `progress` hears the entries listed.
pub async fn list(entries: Vec<FileSystemEntry>, mut progress: OnProgress) -> Listed {
    let mut files = Vec::new();
    for entry in entries {
        let name = entry.name();
        if entry.is_directory() {
            files.extend(files_of(entry.unchecked_into(), &name, &mut progress).await?);
        } else if entry.is_file() {
            let file = file_of(entry.unchecked_into()).await;
            files.push((name.clone(), file.map_err(|e| (name, e))?));
        }
    }
    Ok(files)
}

/// The files `folder` and its subfolders hold that open with the others, by their paths; or
/// what could not be read (the folder, a subfolder or a file, by its path) and why.
/// `progress` hears the entries listed so far.
async fn files_of(
    folder: FileSystemDirectoryEntry,
    name: &str,
    progress: &mut OnProgress,
) -> Result<Vec<(String, web_sys::File)>, (String, String)> {
    let refused = |e: String| (name.to_string(), e);
    let mut listing = FolderListing::default();
    let mut folders = vec![(folder, name.to_string(), 0)];
    while let Some((folder, path, depth)) = folders.pop() {
        let entries = entries_in(&folder, listing.room(), progress, listing.entries()).await;
        let entries = entries.map_err(|e| (path.clone(), e))?;
        listing.count(entries.len()).map_err(refused)?;
        for entry in entries {
            let at = format!("{path}/{}", entry.name());
            let kind = EntryKind::of(entry.is_directory(), entry.is_file());
            if let Some(sub) = listing
                .take(at.clone(), kind, depth, entry)
                .map_err(refused)?
            {
                folders.push((sub.unchecked_into(), at, depth + 1));
            }
        }
    }
    let found = listing.files().map_err(refused)?;
    let mut files = Vec::with_capacity(found.len());
    for (path, entry) in found {
        match file_of(entry.unchecked_into()).await {
            Ok(file) => files.push((path, file)),
            Err(e) => return Err((path, e)),
        }
    }
    Ok(files)
}

/// The entries `folder` holds, up to a batch past `room`; `progress` hears them counted on
/// from `listed`.
async fn entries_in(
    folder: &FileSystemDirectoryEntry,
    room: usize,
    progress: &mut OnProgress,
    listed: usize,
) -> Result<Vec<FileSystemEntry>, String> {
    let reader = folder.create_reader();
    let mut entries = Vec::new();
    // Each call gives the next batch of entries, an empty one at the end.
    while entries.len() < room {
        let batch: Array = called_back(|ok, fail| {
            if let Err(e) = reader.read_entries_with_callback_and_callback(ok, fail) {
                let _ = fail.call1(&JsValue::NULL, &e);
            }
        })
        .await
        .map_err(|e| format!("the browser could not list it: {e}"))?
        .unchecked_into();
        if batch.length() == 0 {
            break;
        }
        entries.extend(batch.iter().map(|e| e.unchecked_into::<FileSystemEntry>()));
        progress((listed + entries.len()) as u64, None);
    }
    Ok(entries)
}

async fn file_of(entry: FileSystemFileEntry) -> Result<web_sys::File, String> {
    let file = called_back(|ok, fail| entry.file_with_callback_and_callback(ok, fail)).await;
    let file = file.map_err(|e| format!("the browser could not read it: {e}"))?;
    Ok(file.unchecked_into())
}

/// The value an API of success and error callbacks gives (`start` is called with both), or the
/// error's text.
async fn called_back(start: impl FnOnce(&Function, &Function)) -> Result<JsValue, String> {
    let mut start = Some(start);
    let promise = Promise::new(&mut |ok, fail| {
        if let Some(start) = start.take() {
            start(&ok, &fail);
        }
    });
    (JsFuture::from(promise).await).map_err(|e| super::page::js_error_text(&e))
}
