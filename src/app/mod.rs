//! The web app (wasm32 only): an eframe app on the page's canvas.
//!
//! `start` installs the logger and a panic hook that shows a crash message on the page, then
//! starts eframe's `WebRunner`. The app owns no algorithm: it edits a
//! [`crate::session::Session`] and shows what the engine computed.
//!
//! Modules, from the page in to the pixels out:
//! - the page and its inputs: `page` (canvas, loading text, crash message), `query`
//!   (`?model=`, `?case=`), `file_input`, `folder_drop` and `read_bytes` (picker, dropped files
//!   and folders, chunked reads), `download` (bytes out), `api` (`window.meshsmooth` and the
//!   embedding's messages), `layout` (where the page drew what, for `state()`);
//! - the document and its engines: `document` (the session shared by the UI and the API, the
//!   calls waiting on it), `words` (the case in the reader's language), `backend` (which
//!   engine smooths, and its timing), `workers` (the CPU engine's dedicated workers), `gpu_engine` (the WebGPU engine's driver), `pacing` (how
//!   often the page redraws for work it does not see);
//! - the authoring page's panels: `controls`, `guide`, `structure_list` with
//!   `case_export_view`, `lesson_panel` with `lms_export` (the package for an LMS),
//!   `report_view`, `legend`, `status`, `shortcuts`,
//!   `bottom_panel` with `graphs` and `gallery` / `gallery_view`;
//! - the viewer's panel (`?mode=viewer`): `case_reader`, and `case_text` for screen readers;
//!   the lesson as the student plays it: `tour`, `quiz`, and `labels` over the view;
//! - over the view: `brush` and `drag_params` (painting weights, dragging parameters),
//!   `pointing` (the name under the pointer), `view_tools` (standard views, clip),
//!   `orientation_marker`, `picture` (the view as PNG);
//! - `shell` (the `eframe::App` that lays these out each frame) and `viewer` (the 3D view).
//!
//! A click, followed. **A dropped file**: [`file_input::FileInput`] reads the dropped bytes
//! (`collect_dropped`, chunked by `read_bytes`) and hands them over as an `Arrived` group;
//! the [`shell::Shell`] gives the group to [`Document::ask_open`], which keeps the caller's
//! waiter (an API call's promise) and asks the [`crate::session::Session`] to
//! `begin_open_files`; the session's [`crate::worker::Pool`] posts a `Request::Load` through
//! [`workers::WebWorkers`] to a worker, where [`crate::worker::Worker`] opens the files
//! (`model::open_files`, the CLI's reading) and replies `Loaded`. Each frame the shell calls
//! [`Document::step_loading`], which takes the reply (`Session::poll_opening`) into the
//! session's [`crate::session::CaseDocument`] and answers the waiters; the shell's
//! `sync_view` then uploads the new case to the [`viewer::Viewer`], which draws it.
//! **A parameter drag**: [`drag_params::DragParams`] turns the pointer's drag over the view
//! into new parameters and sets them on the `CaseDocument` (`set_params`, a new revision);
//! the shell's `compute` hands the revision to the engine that smooths: the
//! [`gpu_engine::GpuEngine`], or [`Document::compute_on_cpu`], whose session asks the pool
//! for a `Request::Smooth` (`Session::compute_cpu`) and takes its `Smoothed` reply into the
//! case; `sync_view` uploads the new positions and colours to the `Viewer`.

mod api;
mod backend;
mod bottom_panel;
mod brush;
mod case_export_view;
mod case_reader;
mod case_text;
mod controls;
mod document;
mod download;
mod drag_params;
mod file_input;
mod folder_drop;
mod gallery;
mod gallery_view;
mod gpu_engine;
mod graphs;
mod guide;
mod labels;
mod layout;
mod legend;
mod lesson_panel;
mod lms_export;
mod orientation_marker;
mod pacing;
mod page;
mod picture;
mod pointing;
mod query;
mod quiz;
mod read_bytes;
mod report_view;
mod shell;
mod shortcuts;
mod status;
mod structure_list;
mod tour;
mod view_tools;
pub mod viewer;
mod words;
mod workers;

pub use backend::Backend;
pub use document::Document;
use pacing::{Pacing, PROGRESS_REPAINT};
pub use words::Words;

/// Asks for one frame, as soon as the browser draws the next, for a change made between frames
/// (a worker's reply, a call of `window.meshsmooth`, a file read, a picture taken). egui
/// answers a request for a frame at once with two (for widgets whose response comes a frame
/// late), and a software GPU pays for each with a whole canvas.
fn wake(ctx: &eframe::egui::Context) {
    ctx.request_repaint_after(std::time::Duration::from_millis(1));
}

/// The case the pages open at start: a synthetic abdomen's four structures, smoothed from their
/// label map, with a tour, labels and a quiz (built by `web/sample/build.sh`).
pub const SAMPLE_NAME: &str = "abdomen_phantom.glb";
pub const SAMPLE_BYTES: &[u8] = include_bytes!("../../web/sample/abdomen_phantom.glb");

/// Entry point of the wasm32 binary.
pub fn start() {
    // The engine workers load this same module: they have no window and no app to start.
    if web_sys::window().is_none() {
        return;
    }
    // Fails only when a logger is already installed, which is then kept.
    let _ = eframe::WebLogger::init(log::LevelFilter::Info);
    page::install_crash_message_hook();
    // Installs eframe's own panic hook, which logs and then calls ours.
    let runner = eframe::WebRunner::new();
    wasm_bindgen_futures::spawn_local(async move {
        let result = match page::canvas() {
            Ok(canvas) => runner
                .start(
                    canvas,
                    eframe::WebOptions {
                        // The 3D view's composite pipeline must match egui's depth buffer.
                        depth_buffer: viewer::EGUI_DEPTH_BUFFER_BITS,
                        ..Default::default()
                    },
                    Box::new(|cc| Ok(Box::new(shell::Shell::new(cc)))),
                )
                .await
                .map_err(|e| page::js_error_text(&e)),
            Err(e) => Err(e),
        };
        match result {
            Ok(()) => page::remove_loading_text(),
            Err(message) => {
                log::error!("meshsmooth failed to start: {message}");
                page::show_crash_message(&format!("meshsmooth failed to start: {message}"));
            }
        }
    });
}
