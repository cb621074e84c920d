//! The API's calls on the view: `setView` (its standard sides, clipping plane and slide towards
//! the segmentation, as its tools set them), `screenshot` (a PNG of it), and `showStep` and
//! `leaveTour` (the case's tour).

use eframe::egui;
use js_sys::{Function, Promise, Uint8Array};
use wasm_bindgen::closure::Closure;
use wasm_bindgen::JsValue;

use super::{error, from_js, Api};
use crate::app::document::SharedDocument;
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
    )
}
