//! The API's calls that hand the page a file: `loadMesh`, `loadCase`, `addFile` and
//! `addImage`, each opened by a worker and settled once it is open.

use super::{error, settled, to_js};
use crate::app::document::{LoadWaiter, SharedDocument};
use crate::case::WindowPreset;
use crate::worker::NamedFile;
use eframe::egui;
use js_sys::{Array, Function, Promise, Uint8Array};
use wasm_bindgen::closure::Closure;
use wasm_bindgen::{JsCast, JsValue};

/// Settles a promise once a file (or structure) is open: with `answer` of the session (the
/// model's `info --json` keys, the structures), or with why it did not open.
fn load_waiter(
    resolve: Function,
    reject: Function,
    answer: fn(&crate::session::Session) -> Option<serde_json::Value>,
) -> LoadWaiter {
    Box::new(move |outcome: Result<&crate::session::Session, String>| {
        let value = outcome.and_then(|session| {
            answer(session)
                .map(|v| to_js(&v))
                .ok_or_else(|| "nothing is open".to_string())
        });
        let _ = match value {
            Ok(v) => resolve.call1(&JsValue::NULL, &v),
            Err(e) => reject.call1(&JsValue::NULL, &error(&e)),
        };
    })
}

pub(super) fn info_waiter(resolve: Function, reject: Function) -> LoadWaiter {
    load_waiter(resolve, reject, |s| super::json::info(s.case()))
}

/// How a file handed to the API opens.
#[derive(Clone, Copy)]
pub(super) enum FileCall {
    /// `loadMesh`: opens it, resolving with the model's info.
    Mesh,
    /// `loadCase`: opens it, resolving with the structures.
    Case,
    /// `addFile`: adds its structures to the open case, resolving with the structures.
    Add,
}

impl FileCall {
    pub(super) fn name(self) -> &'static str {
        match self {
            FileCall::Mesh => "loadMesh",
            FileCall::Case => "loadCase",
            FileCall::Add => "addFile",
        }
    }
}

/// `loadMesh`, `loadCase` or `addFile` of `(bytes: Uint8Array, name)`: opened in a worker, the
/// promise settles once it is open (or not).
pub(super) fn file_call(
    doc: &SharedDocument,
    ctx: &egui::Context,
    call: FileCall,
) -> Closure<dyn FnMut(JsValue, JsValue) -> Promise> {
    let (d, c) = (doc.clone(), ctx.clone());
    Closure::new(move |bytes: JsValue, name: JsValue| {
        let (bytes, name) = match file_arguments(call.name(), &bytes, &name) {
            Ok(file) => file,
            Err(why) => return settled(Err(why)),
        };
        let mut bytes = Some(bytes);
        let (d, c) = (d.clone(), c.clone());
        Promise::new(&mut |resolve: Function, reject: Function| {
            let Some(bytes) = bytes.take() else { return };
            let structures = |s: &crate::session::Session| super::json::structures(s.case());
            let mut doc = d.borrow_mut();
            let file = |bytes| {
                vec![NamedFile {
                    name: name.clone(),
                    bytes,
                }]
            };
            match call {
                FileCall::Mesh => doc.ask_open(file(bytes), Some(info_waiter(resolve, reject))),
                FileCall::Case => {
                    let waiter = load_waiter(resolve, reject, structures);
                    doc.ask_open(file(bytes), Some(waiter))
                }
                FileCall::Add => {
                    let waiter = load_waiter(resolve, reject, structures);
                    doc.ask_add(&name, bytes, Some(waiter))
                }
            }
            crate::app::wake(&c);
        })
    })
}

/// `addImage(bytes: Uint8Array, name, preset)`: the image under the open case's surfaces, read
/// by a worker with the window `preset` names (`ct-soft-tissue` when left out); the promise
/// settles with the structures (their `image`) once it is read, or with why not. A DICOM
/// series comes as arrays: `addImage([bytes, ...], [name, ...], preset)`, one a slice.
pub(super) fn image_call(
    doc: &SharedDocument,
    ctx: &egui::Context,
) -> Closure<dyn FnMut(JsValue, JsValue, JsValue) -> Promise> {
    let (d, c) = (doc.clone(), ctx.clone());
    Closure::new(move |bytes: JsValue, name: JsValue, preset: JsValue| {
        let files = match image_files(&bytes, &name) {
            Ok(files) => files,
            Err(why) => return settled(Err(why)),
        };
        let preset = match preset.as_string() {
            Some(name) => WindowPreset::from_name(&name),
            None if preset.is_undefined() || preset.is_null() => Some(WindowPreset::CtSoftTissue),
            None => None,
        };
        let Some(preset) = preset else {
            let names: Vec<&str> = WindowPreset::ALL.iter().map(|p| p.name()).collect();
            let why = format!("addImage: preset must be one of {}", names.join(", "));
            return settled(Err(why));
        };
        let mut files = Some(files);
        let (d, c) = (d.clone(), c.clone());
        Promise::new(&mut |resolve: Function, reject: Function| {
            let Some(files) = files.take() else { return };
            let structures = |s: &crate::session::Session| super::json::structures(s.case());
            let waiter = load_waiter(resolve, reject, structures);
            d.borrow_mut().ask_image(files, preset, Some(waiter));
            crate::app::wake(&c);
        })
    })
}

/// `addImage`'s files: one `(bytes, name)`, or arrays of the slices' bytes and names.
fn image_files(bytes: &JsValue, names: &JsValue) -> Result<Vec<NamedFile>, String> {
    let (Some(all), Some(names)) = (bytes.dyn_ref::<Array>(), names.dyn_ref::<Array>()) else {
        let (bytes, name) = file_arguments("addImage", bytes, names)?;
        return Ok(vec![NamedFile { name, bytes }]);
    };
    if all.length() != names.length() || all.length() == 0 {
        return Err("addImage(bytes, names): a series needs as many names as slices".into());
    }
    (all.iter().zip(names.iter()))
        .map(|(b, n)| {
            file_arguments("addImage", &b, &n).map(|(bytes, name)| NamedFile { name, bytes })
        })
        .collect()
}

/// A call's `(bytes: Uint8Array, name)` arguments, or why they are not.
fn file_arguments(
    call: &str,
    bytes: &JsValue,
    name: &JsValue,
) -> Result<(Vec<u8>, String), String> {
    let bytes = (bytes.dyn_ref::<Uint8Array>())
        .ok_or_else(|| format!("{call}(bytes, name): bytes must be a Uint8Array"))?;
    let name = (name.as_string().filter(|n| !n.is_empty()))
        .ok_or_else(|| format!("{call}(bytes, name): name must name the file"))?;
    Ok((bytes.to_vec(), name))
}
