//! The API's exports: `exportMesh` (the model alone), `exportCase` (the case glTF at once),
//! `writeCase` (the case glTF a structure per frame, as the page's button writes it) and
//! `exportLms` (the package for an LMS, as the Lesson panel's buttons save it).

use eframe::egui;
use js_sys::{Promise, Uint8Array};
use serde_json::{json, Value};
use wasm_bindgen::closure::Closure;
use wasm_bindgen::JsValue;

use super::{from_js, settled, to_js, when_current, when_ready, Api};
use crate::app::document::SharedDocument;
use crate::app::lms_export;
use crate::export::lms::LmsFormat;
use crate::export::{CaseGltfOptions, Container, ExportFormat, Simplification};

/// `exportMesh`, `exportCase`, `writeCase` and `exportLms`.
pub(super) fn define_export(
    api: &Api,
    doc: &SharedDocument,
    ctx: &egui::Context,
) -> Result<(), String> {
    api.define("exportMesh", export_mesh(doc, ctx))?;
    api.define("exportCase", export_case(doc, ctx))?;
    api.define("writeCase", write_case(doc, ctx))?;
    api.define("exportLms", export_lms(doc, ctx))
}

/// `exportMesh(format)`: the model alone, once its result is current.
fn export_mesh(
    doc: &SharedDocument,
    ctx: &egui::Context,
) -> Closure<dyn FnMut(JsValue) -> Promise> {
    let (d, c) = (doc.clone(), ctx.clone());
    Closure::<dyn FnMut(JsValue) -> Promise>::new(move |format: JsValue| {
        let name = format.as_string().unwrap_or_default();
        let Some(format) = ExportFormat::from_extension(&name) else {
            return settled(Err(format!(
                "unknown export format '{name}': use glb, stl, ply or obj"
            )));
        };
        when_current(&d, &c, move |session| {
            let bytes = session.case().export(format, None)?;
            Ok(Uint8Array::from(bytes.as_slice()).into())
        })
    })
}

/// `exportCase(format, options)`: the case glTF at once (the one `writeCase` wrote when its
/// options are these).
fn export_case(
    doc: &SharedDocument,
    ctx: &egui::Context,
) -> Closure<dyn FnMut(JsValue, JsValue) -> Promise> {
    let (d, c) = (doc.clone(), ctx.clone());
    Closure::<dyn FnMut(JsValue, JsValue) -> Promise>::new(
        move |format: JsValue, asked: JsValue| {
            let name = format.as_string().unwrap_or_else(|| "glb".into());
            let container = match name.as_str() {
                "glb" => Container::Glb,
                "gltf" => Container::Gltf,
                _ => {
                    return settled(Err(format!(
                        "unknown case format '{name}': use glb or gltf"
                    )))
                }
            };
            let options = match case_options(&asked, "exportCase") {
                Ok(o) => CaseGltfOptions { container, ..o },
                Err(e) => return settled(Err(e)),
            };
            when_current(&d, &c, move |session| {
                let written = (session.case_export().written()).filter(|w| w.options == options);
                let bytes = match written {
                    Some(w) => w.bytes.clone(),
                    None => session.case().export_case(&options)?,
                };
                Ok(Uint8Array::from(bytes.as_slice()).into())
            })
        },
    )
}

/// `writeCase(options)`: the case glTF a structure per frame, as the page's button writes it.
fn write_case(doc: &SharedDocument, ctx: &egui::Context) -> Closure<dyn FnMut(JsValue) -> Promise> {
    let (d, c) = (doc.clone(), ctx.clone());
    Closure::<dyn FnMut(JsValue) -> Promise>::new(move |asked: JsValue| {
        let started = case_options(&asked, "writeCase")
            .and_then(|o| d.borrow_mut().session_mut().case_export_mut().start(o));
        if let Err(e) = started {
            return settled(Err(e));
        }
        crate::app::wake(&c);
        when_ready(
            &d,
            &c,
            |s| s.case_export().progress().is_none(),
            |session| match session.case_export().written() {
                Some(w) => Ok(to_js(
                    &json!({ "bytes": w.bytes.len(), "triangles": w.triangles }),
                )),
                None => Err(session
                    .case_export()
                    .error()
                    .unwrap_or("the case changed while it was written")
                    .to_string()),
            },
        )
    })
}

/// `exportLms(format)`: the package for an LMS, as the Lesson panel's buttons save it.
fn export_lms(doc: &SharedDocument, ctx: &egui::Context) -> Closure<dyn FnMut(JsValue) -> Promise> {
    let (d, c) = (doc.clone(), ctx.clone());
    Closure::<dyn FnMut(JsValue) -> Promise>::new(move |format: JsValue| {
        let name = format.as_string().unwrap_or_default();
        let Some(format) = LmsFormat::from_name(&name) else {
            return settled(Err(format!(
                "unknown package format '{name}': use scorm12, scorm2004 or cmi5"
            )));
        };
        when_current(&d, &c, move |session| {
            let (case, glb) = lms_export::case_and_glb(session)?;
            let zip = async move {
                let zip = lms_export::package(format, case, glb).await;
                zip.map(|z| Uint8Array::from(z.as_slice()).into())
                    .map_err(|e| super::error(&e))
            };
            Ok(wasm_bindgen_futures::future_to_promise(zip).into())
        })
    })
}

/// The case glTF's options from `{simplify, triangle_budget, compressed}` (each optional; the
/// page writes the local error).
fn case_options(asked: &JsValue, call: &str) -> Result<CaseGltfOptions, String> {
    let mut options = CaseGltfOptions {
        local_error: true,
        ..CaseGltfOptions::default()
    };
    if asked.is_undefined() || asked.is_null() {
        return Ok(options);
    }
    let Value::Object(fields) = from_js(asked)? else {
        return Err(format!("{call}: the options must be an object"));
    };
    for (key, value) in fields {
        match (key.as_str(), &value) {
            (_, Value::Null) => {}
            ("simplify", v) => match v.as_f64() {
                Some(d) if d > 0.0 && d.is_finite() => {
                    options.simplify = Some(Simplification::VoxelDiagonals(d));
                }
                _ => return Err(format!("{call}: simplify {v} must be a number of voxel diagonals > 0")),
            },
            ("triangle_budget", v) => match v.as_u64() {
                Some(n) if n > 0 => {
                    options.simplify = Some(Simplification::TriangleBudget(n as usize));
                }
                _ => return Err(format!("{call}: triangle_budget {v} must be a whole number > 0")),
            },
            ("compressed", Value::Bool(on)) => options.compressed = *on,
            (other, _) => {
                return Err(format!(
                    "{call}: unknown or malformed option {other} (simplify, triangle_budget, compressed)"
                ))
            }
        }
    }
    Ok(options)
}
