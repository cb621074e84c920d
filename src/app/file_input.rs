//! Files into the app: the Open button's file picker and files dropped on the page.
//!
//! Browsers read files asynchronously, so both paths deliver `(name, bytes)` into an inbox that
//! the app drains once per frame. Nothing is uploaded: the bytes stay in this page's memory.

use eframe::egui;
use std::cell::{Cell, RefCell};
use std::rc::Rc;

use super::folder_drop::{self, FolderDrops};
use super::read_bytes::{self, OnProgress};
use wasm_bindgen::closure::Closure;
use wasm_bindgen::JsCast;
use web_sys::FileSystemEntry;

/// The extensions `io::load` and `io::load_label_map` understand, for the picker's filter
/// (`.gz` for `.nii.gz`, which the filter cannot name as one extension).
const ACCEPT: &str = ".stl,.obj,.ply,.glb,.gltf,.nii,.gz,.nrrd,.mgh,.mgz,.dcm,.txt,.ctbl";

/// A file whose reading finished (or failed).
pub struct ArrivedFile {
    pub name: String,
    pub bytes: Result<Vec<u8>, String>,
}

/// What files chosen or dropped together are for.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum FilesFor {
    /// Opened together as a new case.
    #[default]
    NewCase,
    /// Their structures are added to the open case (the Add button).
    Add,
    /// The image under the open case's surfaces, windowed by the preset.
    Image(crate::case::WindowPreset),
}

/// Files chosen or dropped together, once every one of them was read.
pub struct Arrived {
    pub files: Vec<ArrivedFile>,
    pub purpose: FilesFor,
}

/// A file's read, which starts when awaited.
type PendingReadFn = Box<
    dyn FnOnce(
        OnProgress,
    )
        -> std::pin::Pin<Box<dyn std::future::Future<Output = Result<Vec<u8>, String>>>>,
>;

/// A file to read: its name and the read.
type PendingRead = (String, PendingReadFn);

/// The read of a file of this machine's.
fn local_read(file: web_sys::File) -> PendingReadFn {
    Box::new(move |progress| {
        Box::pin(async move { read_bytes::read_file(&file, progress).await })
            as std::pin::Pin<Box<dyn std::future::Future<Output = _>>>
    })
}

/// Where [`FolderDrops`] hands a drop that holds a folder: listed (the entries counted shown
/// as the folder's reading), then its files read together as a new case, or the item that
/// could not be listed reported as a file that failed.
fn take_folder_drops(inbox: &Inbox, ctx: &egui::Context) -> Rc<dyn Fn(Vec<FileSystemEntry>)> {
    let (inbox, ctx) = (inbox.clone(), ctx.clone());
    Rc::new(move |entries: Vec<FileSystemEntry>| {
        let folder = entries.iter().find(|e| e.is_directory());
        let name = folder.map(FileSystemEntry::name).unwrap_or_default();
        let (id, progress) = inbox.begin(&name, Unit::Entries, &ctx);
        let (inbox, ctx) = (inbox.clone(), ctx.clone());
        wasm_bindgen_futures::spawn_local(async move {
            let listed = folder_drop::list(entries, progress).await;
            inbox.reading.borrow_mut().retain(|(i, _)| *i != id);
            match listed {
                Ok(files) => {
                    let reads = (files.into_iter())
                        .map(|(name, file)| (name, local_read(file)))
                        .collect();
                    inbox.read_together(reads, FilesFor::NewCase, &ctx);
                }
                Err((name, error)) => {
                    let files = vec![ArrivedFile {
                        name,
                        bytes: Err(error),
                    }];
                    let purpose = FilesFor::NewCase;
                    inbox.deliver(Arrived { files, purpose }, &ctx);
                }
            }
        });
    })
}

/// What a [`Reading`] counts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Unit {
    /// A file's bytes.
    Bytes,
    /// A dropped folder's entries, listed before its files are read.
    Entries,
}

/// A file being read (or a folder listed): bytes (entries) so far, and the total when known.
#[derive(Clone, Debug, PartialEq)]
pub struct Reading {
    pub name: String,
    pub unit: Unit,
    pub read: u64,
    pub total: Option<u64>,
}

impl Reading {
    /// What the page says about it.
    pub fn describe(&self) -> String {
        let mb = |b: u64| b as f64 / 1e6;
        if self.unit == Unit::Entries {
            return format!("Listing {}: {} entries", self.name, self.read);
        }
        match self.total {
            Some(t) if t > 0 => format!(
                "Reading {}: {:.1} of {:.1} MB",
                self.name,
                mb(self.read),
                mb(t)
            ),
            _ => format!("Reading {}: {:.1} MB", self.name, mb(self.read)),
        }
    }

    /// The fraction read, when the total is known.
    pub fn fraction(&self) -> Option<f32> {
        self.total
            .filter(|&t| t > 0)
            .map(|t| (self.read as f64 / t as f64).min(1.0) as f32)
    }
}

/// Shared between the app and the reads in flight.
#[derive(Clone, Default)]
struct Inbox {
    arrived: Rc<RefCell<Vec<Arrived>>>,
    /// The reads in flight, by number.
    reading: Rc<RefCell<Vec<(u64, Reading)>>>,
    next: Rc<Cell<u64>>,
    /// What the picker was opened for.
    picking_for: Rc<Cell<FilesFor>>,
    /// Takes files up as they arrive, between frames (see [`FileInput::on_arrival`]).
    on_arrival: Rc<RefCell<Option<ArrivalHook>>>,
}

/// Called with the files arrived so far; it takes those it opens out of the list.
pub type ArrivalHook = Box<dyn FnMut(&mut Vec<Arrived>)>;

impl Inbox {
    /// Registers a read of `name`; the returned callback reports its progress.
    fn begin(&self, name: &str, unit: Unit, ctx: &egui::Context) -> (u64, OnProgress) {
        let id = self.next.get();
        self.next.set(id + 1);
        let reading = Reading {
            name: name.to_string(),
            unit,
            read: 0,
            total: None,
        };
        self.reading.borrow_mut().push((id, reading));
        let (list, ctx) = (self.reading.clone(), ctx.clone());
        let progress = Box::new(move |read, total| {
            if let Some((_, r)) = list.borrow_mut().iter_mut().find(|(i, _)| *i == id) {
                r.read = read;
                r.total = total;
            }
            // A frame for each chunk would take the machine from the reading.
            ctx.request_repaint_after(super::PROGRESS_REPAINT);
        });
        (id, progress)
    }

    fn deliver(&self, files: Arrived, ctx: &egui::Context) {
        self.arrived.borrow_mut().push(files);
        if let (Ok(mut hook), Ok(mut arrived)) = (
            self.on_arrival.try_borrow_mut(),
            self.arrived.try_borrow_mut(),
        ) {
            if let Some(hook) = hook.as_mut() {
                hook(&mut arrived);
            }
        }
        super::wake(ctx);
    }

    /// Reads `files` one after another and delivers them together once all are read, for
    /// `purpose`.
    fn read_together(&self, files: Vec<PendingRead>, purpose: FilesFor, ctx: &egui::Context) {
        let reads: Vec<_> = (files.into_iter())
            .map(|(name, read)| {
                let (id, progress) = self.begin(&name, Unit::Bytes, ctx);
                (id, name, read(progress))
            })
            .collect();
        let (inbox, ctx) = (self.clone(), ctx.clone());
        wasm_bindgen_futures::spawn_local(async move {
            let mut files = Vec::with_capacity(reads.len());
            for (id, name, read) in reads {
                let bytes = read.await;
                inbox.reading.borrow_mut().retain(|(i, _)| *i != id);
                files.push(ArrivedFile { name, bytes });
            }
            inbox.deliver(Arrived { files, purpose }, &ctx);
        });
    }
}

/// The `change` listener of the picker element.
type ChangeListener = Closure<dyn FnMut()>;

/// The hidden `<input type=file>` behind the Open button, and the inbox of arrived files.
pub struct FileInput {
    inbox: Inbox,
    picker: Result<web_sys::HtmlInputElement, String>,
    /// Kept alive as long as the input element may fire `change`.
    _on_change: Option<ChangeListener>,
    /// Drops that hold a folder, which this takes from eframe.
    folders: Option<FolderDrops>,
}

impl FileInput {
    pub fn new(ctx: &egui::Context) -> Self {
        let inbox = Inbox::default();
        let folders = FolderDrops::listen(take_folder_drops(&inbox, ctx))
            .map_err(|e| log::error!("dropped folders will not be read: {e}"))
            .ok();
        match create_picker(&inbox, ctx) {
            Ok((input, on_change)) => Self {
                inbox,
                picker: Ok(input),
                _on_change: Some(on_change),
                folders,
            },
            Err(e) => {
                log::error!("no file picker: {e}");
                Self {
                    inbox,
                    picker: Err(e),
                    _on_change: None,
                    folders,
                }
            }
        }
    }

    /// Opens the browser's file dialog; the chosen files arrive later through
    /// [`Self::take_arrived`], for `purpose`.
    pub fn open_picker(&self, purpose: FilesFor) -> Result<(), String> {
        let input = self.picker.as_ref().map_err(String::clone)?;
        self.inbox.picking_for.set(purpose);
        // Clearing the value lets the same file be chosen twice in a row.
        input.set_value("");
        input.click();
        Ok(())
    }

    /// Starts reading the files dropped on the page this frame, to open together as one case.
    pub fn collect_dropped(&self, ctx: &egui::Context) {
        let dropped = ctx.input(|i| i.raw.dropped_files.clone());
        // Those of drops that held a folder come through `folders`.
        let skipped = self.folders.as_ref().map_or(0, FolderDrops::take_skipped);
        let files: Vec<PendingRead> = (dropped.into_iter().skip(skipped))
            .map(|file| {
                let name = file
                    .path()
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_else(|| file.path().to_string_lossy().into_owned());
                let read: PendingReadFn = Box::new(move |progress| {
                    Box::pin(async move {
                        match file.web_file() {
                            Some(web_file) => read_bytes::read_file(web_file, progress).await,
                            None => file.bytes_async().await,
                        }
                    })
                        as std::pin::Pin<Box<dyn std::future::Future<Output = _>>>
                });
                (name, read)
            })
            .collect();
        if !files.is_empty() {
            self.inbox.read_together(files, FilesFor::NewCase, ctx);
        }
    }

    /// Starts fetching `url` (same origin, see `query`) into the inbox as `name`.
    pub fn fetch(&self, url: String, name: String, ctx: &egui::Context) {
        let inbox = self.inbox.clone();
        let ctx = ctx.clone();
        let (id, progress) = inbox.begin(&name, Unit::Bytes, &ctx);
        wasm_bindgen_futures::spawn_local(async move {
            let bytes = read_bytes::fetch(&url, progress).await;
            inbox.reading.borrow_mut().retain(|(i, _)| *i != id);
            let files = vec![ArrivedFile { name, bytes }];
            let purpose = FilesFor::NewCase;
            inbox.deliver(Arrived { files, purpose }, &ctx);
        });
    }

    /// Lets `hook` take files up as they arrive, rather than at the next frame.
    pub fn on_arrival(&self, hook: ArrivalHook) {
        *self.inbox.on_arrival.borrow_mut() = Some(hook);
    }

    /// Files whose reading finished since the last call, oldest first.
    pub fn take_arrived(&self) -> Vec<Arrived> {
        std::mem::take(&mut *self.inbox.arrived.borrow_mut())
    }

    /// The files still being read, oldest first.
    pub fn reading(&self) -> Vec<Reading> {
        self.inbox
            .reading
            .borrow()
            .iter()
            .map(|(_, r)| r.clone())
            .collect()
    }
}

fn create_picker(
    inbox: &Inbox,
    ctx: &egui::Context,
) -> Result<(web_sys::HtmlInputElement, ChangeListener), String> {
    let document = web_sys::window()
        .and_then(|w| w.document())
        .ok_or("no document")?;
    let input = document
        .create_element("input")
        .map_err(|e| super::page::js_error_text(&e))?
        .dyn_into::<web_sys::HtmlInputElement>()
        .map_err(|_| "created element is not an <input>")?;
    input.set_type("file");
    input.set_accept(ACCEPT);
    input.set_multiple(true);
    input.set_hidden(true);
    input.set_id("meshsmooth_file_input");
    let body = document.body().ok_or("the page has no <body>")?;
    body.append_child(&input)
        .map_err(|e| super::page::js_error_text(&e))?;

    let on_change = {
        let input = input.clone();
        let inbox = inbox.clone();
        let ctx = ctx.clone();
        Closure::<dyn FnMut()>::new(move || {
            let Some(list) = input.files() else {
                return;
            };
            let files: Vec<PendingRead> = (0..list.length())
                .filter_map(|i| list.get(i))
                .map(|file| (file.name(), local_read(file)))
                .collect();
            if !files.is_empty() {
                inbox.read_together(files, inbox.picking_for.get(), &ctx);
            }
        })
    };
    input.set_onchange(Some(on_change.as_ref().unchecked_ref()));
    Ok((input, on_change))
}
