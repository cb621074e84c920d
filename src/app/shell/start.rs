//! What the page does once, as it starts: choose the engines and the look, start the workers,
//! open the file its address names (or the bundled sample), install `window.meshsmooth`, and
//! answer the page that embeds it.

use eframe::egui;
use std::rc::Rc;

use crate::app::document::SharedDocument;
use crate::app::file_input::FileInput;
use crate::app::gpu_engine::GpuEngine;
use crate::app::{api, query, workers, SAMPLE_BYTES, SAMPLE_NAME};
use crate::worker::Pool;

/// Opens `?model=URL` (same origin only) or else the bundled sample. True when it fetches
/// the address's file (the sample opens at once).
pub(super) fn open_start_model(
    doc: &SharedDocument,
    files: &FileInput,
    ctx: &egui::Context,
) -> bool {
    // The student's viewer bundles no sample: a package names its case.
    let open_sample = || {
        if crate::AUTHORING {
            let _ = doc.borrow_mut().open_now(SAMPLE_NAME, SAMPLE_BYTES);
        }
    };
    match query::model_url() {
        None => {
            open_sample();
            false
        }
        Some(Err(e)) => {
            open_sample();
            doc.borrow_mut().session_mut().fail("?model", &e);
            false
        }
        Some(Ok(model)) => {
            files.fetch(model.url, model.name, ctx);
            true
        }
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
            doc.borrow_mut().session_mut().fail("?parent", &e);
            return None;
        }
    };
    let (mode, backend) = (
        crate::app::query::mode_name(),
        doc.borrow().backend().name(),
    );
    if let Err(e) = embedding.listen(&api, mode, backend) {
        log::error!("the embedding page is not answered: {e}");
        return None;
    }
    Some(embedding)
}

/// WebGPU: the GPU engine on eframe's device. WebGL2 (no compute shaders): the CPU engine. The
/// viewer smooths nothing of its own (a case carries its surfaces), so it has no GPU engine and
/// compiles no smoothing kernels, which a software adapter takes long over: WebGPU only draws.
pub(super) fn gpu_engine(
    cc: &eframe::CreationContext<'_>,
    reading: bool,
    software: bool,
) -> Option<GpuEngine> {
    let rs = cc.wgpu_render_state.as_ref()?;
    let info = rs.adapter.get_info();
    log::info!("adapter: {} ({:?})", info.name, info.backend);
    (crate::AUTHORING && info.backend == wgpu::Backend::BrowserWebGpu && !reading)
        .then(|| GpuEngine::new(&rs.device, &rs.queue, software))
}

/// Starts the CPU engine's workers: the background's and one more kept for the view; the
/// viewer only opens and shows, which one worker does. Without workers (a page that cannot start
/// any) the engine runs on the page, blocking frames, rather than not at all.
pub(super) fn start_workers(doc: &SharedDocument, reading: bool, ctx: &egui::Context) {
    let count = match reading {
        true => 1,
        false => workers::pool_size() + 1,
    };
    match workers::WebWorkers::start(count, ctx) {
        Ok(w) => {
            let weak = Rc::downgrade(doc);
            w.on_reply(Box::new(move || {
                // Between frames the document is free; skipped should it not be.
                match weak.upgrade().as_ref().map(|d| d.try_borrow_mut()) {
                    Some(Ok(mut doc)) => doc.step_cpu_engine(),
                    _ => false,
                }
            }));
            let pool = Pool::with_view_worker(Box::new(w));
            log::info!("CPU engine: {}", crate::app::api::json::cpu_engine(&pool));
            doc.borrow_mut().session_mut().set_cpu_engine(pool);
        }
        Err(why) => log::error!("no engine workers, the CPU engine runs on the page: {why}"),
    }
}

/// The page's look: dark, as on radiology workstations, where the model stands out and colours
/// read true. Glyphs drawn plain: hinting runs each glyph through the font's bytecode
/// interpreter and binning rasterises it at up to four offsets, work that lies on the first
/// frame's path (compiled and then recompiled by the browser) for text that reads the same. On
/// a `software` GPU each frame costs a whole canvas of CPU time, and comes a few times a second:
/// widgets change at once rather than animate over frames, and progress moves less often.
pub(super) fn set_style(ctx: &egui::Context, software: bool) {
    if !crate::AUTHORING {
        ctx.set_fonts(viewer_fonts());
    }
    crate::app::Pacing::for_gpu(software).keep(ctx);
    ctx.set_theme(egui::Theme::Dark);
    ctx.all_styles_mut(|s| {
        s.visuals.text_options.font_hinting = false;
        s.visuals.text_options.subpixel_binning = false;
        if software {
            s.animation_time = 0.0;
        }
    });
}

/// The student's viewer's fonts: egui's proportional font and its icons, for monospace text
/// too (the author's build has egui's default fonts, which add a monospace font).
fn viewer_fonts() -> egui::FontDefinitions {
    use egui::{FontData, FontFamily, FontTweak};
    use std::sync::Arc;
    let mut fonts = egui::FontDefinitions::empty();
    let text = FontData::from_static(epaint_default_fonts::UBUNTU_LIGHT);
    // As egui's defaults size its icons.
    let icons = FontData::from_static(epaint_default_fonts::EGUI_ICONS).tweak(FontTweak {
        scale: 0.90,
        ..Default::default()
    });
    fonts
        .font_data
        .insert("Ubuntu-Light".into(), Arc::new(text));
    fonts.font_data.insert("egui-icons".into(), Arc::new(icons));
    for family in [FontFamily::Proportional, FontFamily::Monospace] {
        fonts
            .families
            .insert(family, vec!["Ubuntu-Light".into(), "egui-icons".into()]);
    }
    fonts
}
