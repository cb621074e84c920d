//! The API's calls on the view: `setView` (its standard sides, clipping plane and slide towards
//! the segmentation, as its tools set them), `screenshot` (a PNG of it), `showStep` and
//! `leaveTour` (the case's tour), `startQuiz`, `nextQuestion` and `endQuiz` (its quiz), and the
//! author's `lesson`, `setLesson` and `recordStep`.

use eframe::egui;
use js_sys::{Function, Promise, Uint8Array};
use wasm_bindgen::closure::Closure;
use wasm_bindgen::JsValue;

use super::{error, from_js, to_js, Api};
use crate::app::document::{Document, SharedDocument};
use crate::view::ViewRequest;

pub(super) fn set_view(
    doc: &SharedDocument,
    ctx: &egui::Context,
) -> Closure<dyn FnMut(JsValue) -> Result<(), JsValue>> {
    let (doc, ctx) = (doc.clone(), ctx.clone());
    Closure::new(move |value: JsValue| {
        let request = from_js(&value)
            .and_then(|v| ViewRequest::from_json(&v))
            .map_err(|e| error(&e))?;
        let mut doc = doc.borrow_mut();
        if let Some(side) = request.from {
            doc.view_asks.look_from = Some(side);
        }
        // A clip and the three planes are shown one at a time.
        if let Some(clip) = request.clip {
            doc.view_asks.clip = clip;
            if clip.is_some() {
                doc.view_asks.planes = None;
            }
        }
        if let Some(planes) = request.planes {
            doc.view_asks.planes = planes;
            if planes.is_some() {
                doc.view_asks.clip = None;
            }
        }
        if let Some(t) = request.toward_segmentation {
            doc.view_asks.toward_segmentation = t;
        }
        crate::app::wake(&ctx);
        Ok(())
    })
}

pub(super) fn define_screenshot(
    api: &Api,
    doc: &SharedDocument,
    ctx: &egui::Context,
) -> Result<(), String> {
    let (d, c) = (doc.clone(), ctx.clone());
    api.define(
        "screenshot",
        Closure::<dyn FnMut() -> Promise>::new(move || {
            let (d, c) = (d.clone(), c.clone());
            Promise::new(&mut |resolve: Function, reject: Function| {
                let waiter = Box::new(move |png: Result<Vec<u8>, String>| {
                    let _ = match png {
                        Ok(bytes) => resolve.call1(&JsValue::NULL, &Uint8Array::from(&bytes[..])),
                        Err(e) => reject.call1(&JsValue::NULL, &error(&e)),
                    };
                });
                d.borrow_mut().waiting_for_picture.push(waiter);
                crate::app::wake(&c);
            })
        }),
    )?;
    Ok(())
}

/// `showStep(index)` (the tour's step, from 0; the camera flies there) and `leaveTour()`.
pub(super) fn define_tour(
    api: &Api,
    doc: &SharedDocument,
    ctx: &egui::Context,
) -> Result<(), String> {
    let (d, c) = (doc.clone(), ctx.clone());
    api.define(
        "showStep",
        Closure::<dyn FnMut(JsValue) -> Result<(), JsValue>>::new(move |index: JsValue| {
            let index = (index.as_f64())
                .filter(|i| i.fract() == 0.0 && *i >= 0.0)
                .ok_or_else(|| error("showStep(index): index must be a whole number >= 0"))?;
            d.borrow_mut()
                .ask_step(index as usize)
                .map_err(|e| error(&e))?;
            crate::app::wake(&c);
            Ok(())
        }),
    )?;
    let (d, c) = (doc.clone(), ctx.clone());
    api.define(
        "leaveTour",
        Closure::<dyn FnMut()>::new(move || {
            d.borrow_mut().leave_tour();
            crate::app::wake(&c);
        }),
    )?;
    define_quiz(api, doc, ctx)?;
    define_lesson(api, doc, ctx)
}

/// `startQuiz()`, `nextQuestion()` (the question asked being answered) and `endQuiz()`.
fn define_quiz(api: &Api, doc: &SharedDocument, ctx: &egui::Context) -> Result<(), String> {
    type Call = fn(&mut Document) -> Result<(), String>;
    let calls: [(&str, Call); 3] = [
        ("startQuiz", Document::start_quiz),
        ("nextQuestion", Document::next_question),
        ("endQuiz", |d| {
            d.end_quiz();
            Ok(())
        }),
    ];
    for (name, call) in calls {
        let (d, c) = (doc.clone(), ctx.clone());
        api.define(
            name,
            Closure::<dyn FnMut() -> Result<(), JsValue>>::new(move || {
                let done = call(&mut d.borrow_mut());
                crate::app::wake(&c);
                done.map_err(|e| error(&format!("{name}: {e}")))
            }),
        )?;
    }
    Ok(())
}

/// `lesson()`, `setLesson(lesson)` and `recordStep({title, caption})`: the author's lesson.
fn define_lesson(api: &Api, doc: &SharedDocument, ctx: &egui::Context) -> Result<(), String> {
    let d = doc.clone();
    api.define(
        "lesson",
        Closure::<dyn FnMut() -> JsValue>::new(move || {
            to_js(&serde_json::json!(d.borrow().session().case().lesson()))
        }),
    )?;
    let (d, c) = (doc.clone(), ctx.clone());
    api.define(
        "setLesson",
        Closure::<dyn FnMut(JsValue) -> Result<(), JsValue>>::new(move |value: JsValue| {
            let lesson = from_js(&value)
                .and_then(|v| serde_json::from_value(v).map_err(|e| format!("not a lesson: {e}")))
                .map_err(|e| error(&format!("setLesson: {e}")))?;
            let set = d.borrow_mut().session_mut().case_mut().set_lesson(lesson);
            crate::app::wake(&c);
            set.map_err(|e| error(&format!("setLesson: {e}")))
        }),
    )?;
    let (d, c) = (doc.clone(), ctx.clone());
    api.define(
        "recordStep",
        Closure::<dyn FnMut(JsValue) -> Result<JsValue, JsValue>>::new(move |value: JsValue| {
            let recorded = record_step(&mut d.borrow_mut(), &value);
            crate::app::wake(&c);
            recorded
                .map(|n| JsValue::from(n as f64))
                .map_err(|e| error(&format!("recordStep: {e}")))
        }),
    )
}

/// `recordStep({title, caption})`: the view as it stands as the tour's last step.
fn record_step(doc: &mut Document, value: &JsValue) -> Result<usize, String> {
    let v = from_js(value)?;
    let text = |key: &str| v.get(key).and_then(|t| t.as_str()).unwrap_or_default();
    doc.record_step(text("title"), text("caption"))
}
