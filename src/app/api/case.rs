//! The API's calls on the case's structures: `structures`, `selectStructure`,
//! `setStructure`, `soloStructure` and `setCase`.

use eframe::egui;
use js_sys::Promise;
use wasm_bindgen::closure::Closure;
use wasm_bindgen::JsValue;

use super::{from_js, setter, settled, to_js, Api};
use crate::app::document::SharedDocument;
use crate::session::Session;

pub(super) fn define(api: &Api, doc: &SharedDocument, ctx: &egui::Context) -> Result<(), String> {
    let d = doc.clone();
    api.define(
        "structures",
        Closure::<dyn FnMut() -> JsValue>::new(move || {
            let doc = d.borrow();
            match super::json::structures(doc.session().case()) {
                Some(s) => to_js(&s),
                None => JsValue::NULL,
            }
        }),
    )?;

    api.define("selectStructure", select_structure(doc, ctx))?;

    let reading = crate::app::query::is_viewer();
    api.define(
        "setStructure",
        setter(doc, ctx, move |session, values| {
            let (index, change) = super::json::structure_change(&from_js(&values)?)?;
            let words = [&change.name, &change.description]
                .iter()
                .any(|c| c.is_some())
                || change.group.is_some()
                || change.names.is_some();
            if reading && words {
                return Err("setStructure: the viewer changes how a structure is shown \
                    (visible, opacity, color), not its name, group, description or names"
                    .into());
            }
            let index = (index.or(session.case().current_structure())).ok_or("nothing is open")?;
            session.case_mut().set_structure(index, change)
        }),
    )?;

    api.define(
        "soloStructure",
        setter(doc, ctx, |session, index| {
            let index = (index.as_f64())
                .filter(|i| *i >= 0.0 && i.fract() == 0.0)
                .ok_or("soloStructure(index): index must be a whole number >= 0")?;
            session.case_mut().solo_structure(index as usize)
        }),
    )?;

    api.define("setCase", setter(doc, ctx, set_case))?;
    Ok(())
}

/// `selectStructure(index)`: makes that structure the model; resolves with its info.
fn select_structure(
    doc: &SharedDocument,
    ctx: &egui::Context,
) -> Closure<dyn FnMut(JsValue) -> Promise> {
    let (d, c) = (doc.clone(), ctx.clone());
    Closure::new(move |index: JsValue| {
        let Some(index) = index.as_f64().filter(|i| *i >= 0.0 && i.fract() == 0.0) else {
            return settled(Err(
                "selectStructure(index): index must be a whole number >= 0".into(),
            ));
        };
        let index = index as usize;
        let selected = d.borrow_mut().select(index);
        crate::app::wake(&c);
        let info = move |session: &Session| {
            if session.case().current_structure() != Some(index) {
                let why = session.error().unwrap_or("another was opened first");
                return Err(format!("structure {index} was not selected: {why}"));
            }
            super::json::info(session.case())
                .map(|v| to_js(&v))
                .ok_or_else(|| "nothing is open".to_string())
        };
        match selected {
            Err(e) => settled(Err(e)),
            // A large structure's model is built by a worker first.
            Ok(()) if d.borrow().session().selecting() == Some(index) => {
                super::when_ready(&d, &c, |s| s.selecting().is_none(), info)
            }
            Ok(()) => settled(info(d.borrow().session())),
        }
    })
}

/// `setCase({title, description})`: names the case; unknown keys are refused.
fn set_case(session: &mut Session, values: JsValue) -> Result<(), String> {
    let values = from_js(&values)?;
    let text = |key: &str| match values.get(key) {
        None => Ok(None),
        Some(v) => v
            .as_str()
            .map(Some)
            .ok_or_else(|| format!("setCase: {key} must be a string")),
    };
    if let Some(key) = values
        .as_object()
        .ok_or("setCase takes an object: {title, description}")?
        .keys()
        .find(|k| !["title", "description"].contains(&k.as_str()))
    {
        return Err(format!("setCase: unknown key {key} (title, description)"));
    }
    session
        .case_mut()
        .set_case_text(text("title")?, text("description")?);
    Ok(())
}
