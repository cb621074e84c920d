//! While the file the page's address names (`?case=`, `?model=`) is read and opened, the page
//! paints its first frame and then waits, for a moment at most, for the file: the next frame
//! painted shows it open, rather than frames for each step of the opening. Every painted frame
//! costs a whole canvas, which on a software or weak GPU took most of the time between the
//! page and its case; the first frame's own work (the first use of every pipeline and of the
//! text) is done while a worker reads the file.

use eframe::egui;
use std::time::Duration;

/// How long frames wait for the address's file, from the app's start. A file that takes longer
/// (a large one, a slow connection) is shown being read and opened.
const LONGEST_WAIT_MS: f64 = 1500.0;

#[derive(Clone, Copy, Debug, PartialEq)]
enum State {
    /// The next frame is the first painted; frames wait after it (until `until`).
    First {
        until: f64,
    },
    /// Frames are not painted until the file is open or this time (ms, the page's clock) came.
    Waiting {
        until: f64,
    },
    Painting,
}

pub(super) struct FirstPaint {
    state: State,
}

impl FirstPaint {
    /// `waits`: the page started reading a file its address names, at `now` (ms).
    pub fn new(waits: bool, now: f64) -> Self {
        let state = match waits {
            true => State::First {
                until: now + LONGEST_WAIT_MS,
            },
            false => State::Painting,
        };
        Self { state }
    }

    /// Whether frames wait for the address's file.
    pub fn waiting(&self) -> bool {
        matches!(self.state, State::Waiting { .. })
    }

    /// Before a frame's input reaches egui (eframe's `raw_input_hook`): while waiting, and the
    /// file is not `open` yet, marks the page as not visible, so that eframe runs no ui and
    /// paints nothing, and asks for a frame when the wait ends.
    pub fn before_frame(
        &mut self,
        open: bool,
        now: f64,
        ctx: &egui::Context,
        raw_input: &mut egui::RawInput,
    ) {
        if let Some(left_ms) = self.step(open, now) {
            if let Some(viewport) = raw_input.viewports.get_mut(&raw_input.viewport_id) {
                viewport.occluded = Some(true);
            }
            ctx.request_repaint_after(Duration::from_secs_f64(left_ms / 1000.0));
        }
    }

    /// The wait left (ms) when this frame is not to be painted.
    fn step(&mut self, open: bool, now: f64) -> Option<f64> {
        match self.state {
            State::First { until } => {
                self.state = State::Waiting { until };
                None
            }
            State::Waiting { until } if !open && now < until => Some(until - now),
            State::Waiting { .. } => {
                self.state = State::Painting;
                None
            }
            State::Painting => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test]
    fn a_page_without_a_file_paints_every_frame() {
        let mut paint = FirstPaint::new(false, 0.0);
        assert!(!paint.waiting());
        assert_eq!(paint.step(false, 0.0), None);
        assert_eq!(paint.step(false, 10.0), None);
        assert!(!paint.waiting());
    }

    #[wasm_bindgen_test]
    fn frames_after_the_first_wait_until_the_file_is_open() {
        let mut paint = FirstPaint::new(true, 100.0);
        assert_eq!(paint.step(false, 100.0), None, "the first frame is painted");
        assert!(paint.waiting());
        assert_eq!(paint.step(false, 100.0), Some(LONGEST_WAIT_MS));
        assert_eq!(paint.step(false, 600.0), Some(LONGEST_WAIT_MS - 500.0));
        assert_eq!(paint.step(true, 700.0), None);
        assert!(!paint.waiting());
        // Once the file is open, frames never wait again.
        assert_eq!(paint.step(false, 800.0), None);
    }

    #[wasm_bindgen_test]
    fn frames_wait_no_longer_than_the_longest_wait() {
        let mut paint = FirstPaint::new(true, 0.0);
        assert_eq!(paint.step(false, 0.0), None);
        assert!(paint.step(false, LONGEST_WAIT_MS - 1.0).is_some());
        assert_eq!(paint.step(false, LONGEST_WAIT_MS), None);
        assert!(!paint.waiting());
    }

    #[wasm_bindgen_test]
    fn a_waiting_frame_is_marked_not_visible() {
        let ctx = egui::Context::default();
        let frame = || {
            let mut raw = egui::RawInput::default();
            raw.viewports
                .insert(raw.viewport_id, egui::ViewportInfo::default());
            raw
        };
        let visible = |raw: &egui::RawInput| raw.viewports[&raw.viewport_id].visible();
        let mut paint = FirstPaint::new(true, 0.0);
        let mut raw = frame();
        paint.before_frame(false, 0.0, &ctx, &mut raw);
        assert_ne!(visible(&raw), Some(false), "the first frame is painted");
        let mut raw = frame();
        paint.before_frame(false, 10.0, &ctx, &mut raw);
        assert_eq!(visible(&raw), Some(false));
        let mut raw = frame();
        paint.before_frame(true, 20.0, &ctx, &mut raw);
        assert_ne!(visible(&raw), Some(false));
    }
}
