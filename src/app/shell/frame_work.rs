//! The work a frame does beside drawing: the keyboard's shortcuts, the case's background work
//! (Suggest all's answers, the checks', a share of writing the case glTF), and after it the
//! calls and the embedding answered and the next frame paced.

use eframe::egui;

use super::Shell;
use crate::app::document::now_ms;
use crate::app::shortcuts;

/// Milliseconds of a frame the case glTF being written may take on this thread: the view
/// stays usable (about ten frames a second) and the file is written at nearly full speed.
const EXPORT_FRAME_MS: f64 = 80.0;

impl Shell {
    /// The keyboard's shortcuts, where the page takes them (the viewer only those it reads).
    pub(super) fn take_shortcuts(&mut self, ctx: &egui::Context) {
        let (keys, reads) = {
            let doc = self.doc.borrow();
            (doc.shortcuts, super::reading::reads(&doc))
        };
        let pressed = if keys {
            shortcuts::pressed(ctx)
        } else {
            Vec::new()
        };
        for action in pressed {
            if !reads || shortcuts::reads(action) {
                self.apply(action);
            }
        }
    }

    /// The case's background work steps on: Suggest all's answers, the checks', and this
    /// frame's share of writing the case glTF.
    pub(super) fn step_case_work(&mut self) {
        if !crate::AUTHORING {
            return;
        }
        let mut doc = self.doc.borrow_mut();
        let session = doc.session_mut();
        session.step_suggest_all();
        session.step_checks();
        // Writing the case glTF takes this frame's share of time on this thread.
        let start = now_ms();
        while session.case_export().progress().is_some() && now_ms() - start < EXPORT_FRAME_MS {
            session.case_export_mut().step();
        }
    }

    /// After the frame's work: the calls and the embedding answered, the screen reader's text
    /// updated, and the next frame asked for while work goes on (paced while workers work).
    pub(super) fn tell_and_pace(&mut self, ctx: &egui::Context) {
        let mut doc = self.doc.borrow_mut();
        doc.answer_waiting();
        if let Some(embedding) = &mut self.embedding {
            embedding.after_frame(&mut doc);
        }
        doc.lesson_events.clear();
        self.case_text.update(&doc);
        self.case_text.update_lesson(&doc);
        self.repainting = doc.working();
        if self.repainting && doc.working_elsewhere() {
            // The replies wake the page; this only moves the progress on. Frames drawn
            // for nothing would take a core from the workers.
            ctx.request_repaint_after(crate::app::Pacing::of(ctx).work_repaint);
        } else if self.repainting {
            ctx.request_repaint();
        }
    }
}
