//! Files into the app: the Open button's file picker and files dropped on the page.
//!
//! Browsers read files asynchronously, so both paths deliver `(name, bytes)` into an inbox that
//! the app drains once per frame. Nothing is uploaded: the bytes stay in this page's memory.

use eframe::egui;
use std::cell::{Cell, RefCell};
use std::rc::Rc;

use wasm_bindgen::closure::Closure;
use wasm_bindgen::JsCast;

/// The extensions `io::load` understands, for the picker's filter.
const ACCEPT: &str = ".stl,.obj,.ply,.glb,.gltf";

/// A file whose reading finished (or failed).
pub struct ArrivedFile {
    pub name: String,
    pub bytes: Result<Vec<u8>, String>,
}

/// Shared between the app and the reads in flight.
#[derive(Clone, Default)]
struct Inbox {
    arrived: Rc<RefCell<Vec<ArrivedFile>>>,
    reading: Rc<Cell<usize>>,
}

impl Inbox {
    fn begin(&self) {
        self.reading.set(self.reading.get() + 1);
    }

    fn deliver(&self, file: ArrivedFile, ctx: &egui::Context) {
        self.reading.set(self.reading.get().saturating_sub(1));
        self.arrived.borrow_mut().push(file);
        ctx.request_repaint();
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
}

impl FileInput {
    pub fn new(ctx: &egui::Context) -> Self {
        let inbox = Inbox::default();
        match create_picker(&inbox, ctx) {
            Ok((input, on_change)) => Self {
                inbox,
                picker: Ok(input),
                _on_change: Some(on_change),
            },
            Err(e) => {
                log::error!("no file picker: {e}");
                Self {
                    inbox,
                    picker: Err(e),
                    _on_change: None,
                }
            }
        }
    }

    /// Opens the browser's file dialog; the chosen file arrives later through [`Self::take_arrived`].
    pub fn open_picker(&self) -> Result<(), String> {
        let input = self.picker.as_ref().map_err(String::clone)?;
        // Clearing the value lets the same file be chosen twice in a row.
        input.set_value("");
        input.click();
        Ok(())
    }

    /// Starts reading the files dropped on the page this frame. One mesh is open at a time,
    /// so only the first file of a multi-file drop is read.
    pub fn collect_dropped(&self, ctx: &egui::Context) {
        let dropped = ctx.input(|i| i.raw.dropped_files.clone());
        let Some(file) = dropped.into_iter().next() else {
            return;
        };
        let name = file
            .path()
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| file.path().to_string_lossy().into_owned());
        let inbox = self.inbox.clone();
        let ctx = ctx.clone();
        inbox.begin();
        wasm_bindgen_futures::spawn_local(async move {
            let bytes = file.bytes_async().await;
            inbox.deliver(ArrivedFile { name, bytes }, &ctx);
        });
    }

    /// Starts fetching `url` (same origin, see `query`) into the inbox as `name`.
    pub fn fetch(&self, url: String, name: String, ctx: &egui::Context) {
        let inbox = self.inbox.clone();
        let ctx = ctx.clone();
        inbox.begin();
        wasm_bindgen_futures::spawn_local(async move {
            let bytes = super::query::fetch(&url).await;
            inbox.deliver(ArrivedFile { name, bytes }, &ctx);
        });
    }

    /// Files whose reading finished since the last call, oldest first.
    pub fn take_arrived(&self) -> Vec<ArrivedFile> {
        std::mem::take(&mut *self.inbox.arrived.borrow_mut())
    }

    /// Number of files still being read.
    pub fn reading(&self) -> usize {
        self.inbox.reading.get()
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
            let Some(file) = input.files().and_then(|list| list.get(0)) else {
                return;
            };
            let inbox = inbox.clone();
            let ctx = ctx.clone();
            inbox.begin();
            wasm_bindgen_futures::spawn_local(async move {
                let name = file.name();
                let bytes = read_file(&file).await;
                inbox.deliver(ArrivedFile { name, bytes }, &ctx);
            });
        })
    };
    input.set_onchange(Some(on_change.as_ref().unchecked_ref()));
    Ok((input, on_change))
}

async fn read_file(file: &web_sys::File) -> Result<Vec<u8>, String> {
    // Wasm32 memory is 4 GiB at most; refuse early rather than fail inside the copy.
    if file.size() > f64::from(u32::MAX) {
        return Err(format!(
            "the file is too large ({:.1} GB) to read in the browser",
            file.size() / 1e9
        ));
    }
    let buffer = wasm_bindgen_futures::JsFuture::from(file.array_buffer())
        .await
        .map_err(|e| {
            format!(
                "the browser could not read it: {}",
                super::page::js_error_text(&e)
            )
        })?;
    Ok(js_sys::Uint8Array::new(&buffer).to_vec())
}
