//! `setView`: the view's standard sides, clipping plane and slide towards the segmentation, as
//! its tools set them.

use eframe::egui;
use wasm_bindgen::closure::Closure;
use wasm_bindgen::JsValue;

use super::{error, from_js};
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
        if let Some(clip) = request.clip {
            doc.view_asks.clip = clip;
        }
        if let Some(t) = request.toward_segmentation {
            doc.view_asks.toward_segmentation = t;
        }
        ctx.request_repaint();
        Ok(())
    })
}
