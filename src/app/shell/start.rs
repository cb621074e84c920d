//! What the page does once, as it starts: open the file its address names (or the bundled
//! sample), install `window.meshsmooth`, and answer the page that embeds it.

use eframe::egui;

use crate::app::document::SharedDocument;
use crate::app::file_input::FileInput;
use crate::app::{api, query, SAMPLE_BYTES, SAMPLE_NAME};

/// Opens `?model=URL` (same origin only) or else the bundled sample.
pub(super) fn open_start_model(doc: &SharedDocument, files: &FileInput, ctx: &egui::Context) {
    match query::model_url() {
        None => {
            let _ = doc.borrow_mut().open(SAMPLE_NAME, SAMPLE_BYTES);
        }
        Some(Err(e)) => {
            let _ = doc.borrow_mut().open(SAMPLE_NAME, SAMPLE_BYTES);
            doc.borrow_mut().session.fail("?model", &e);
        }
        Some(Ok(model)) => files.fetch(model.url, model.name, ctx),
    }
}

/// Installs `window.meshsmooth`, and answers the embedding page where `?parent=` names one.
pub(super) fn embed(doc: &SharedDocument, ctx: &egui::Context) -> Option<api::Embedding> {
    let api = match api::install(doc, ctx) {
        Ok(api) => api,
        Err(e) => {
            log::error!("no embedding API: {e}");
            return None;
        }
    };
    let embedding = match api::Embedding::from_query()? {
        Ok(embedding) => embedding,
        Err(e) => {
            doc.borrow_mut().session.fail("?parent", &e);
            return None;
        }
    };
    let (mode, backend) = {
        let doc = doc.borrow();
        let mode = if doc.reading { "viewer" } else { "author" };
        (mode, doc.backend.name())
    };
    if let Err(e) = embedding.listen(&api, mode, backend) {
        log::error!("the embedding page is not answered: {e}");
        return None;
    }
    Some(embedding)
}
