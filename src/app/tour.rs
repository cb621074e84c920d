//! The case's tour as the page follows it: which step is shown, asked by the student's
//! buttons or the platform's calls, and what `state()` and the platform hear of it.

use serde_json::{json, Value};

use super::document::Document;

impl Document {
    /// Shows tour step `index` from the next frame on (the camera flies there).
    pub fn ask_step(&mut self, index: usize) -> Result<(), String> {
        let steps = self.session().case().lesson().steps.len();
        if index >= steps {
            return Err(match steps {
                0 => "the case has no tour".to_string(),
                n => format!("the case's tour has steps 0 to {}: no step {index}", n - 1),
            });
        }
        self.view_asks.step = Some(index);
        self.tour_left = None;
        Ok(())
    }

    /// Leaves the tour, the view staying as it is; the step left is offered to come back to.
    pub fn leave_tour(&mut self) {
        self.tour_left = self.tour.take().or(self.tour_left);
        self.view_asks.step = None;
    }

    /// `{step, steps, title, caption, left}` (`step` null outside the tour, `left` the step
    /// the student left it at), or null without a tour.
    pub fn tour_json(&self) -> Value {
        let steps = &self.session().case().lesson().steps;
        if steps.is_empty() {
            return Value::Null;
        }
        let lesson = self.session().case().lesson();
        let shown = (self.tour).and_then(|i| lesson.step_text(i, self.words().languages));
        json!({
            "step": self.tour,
            "steps": steps.len(),
            "title": shown.map(|(title, _)| title),
            "caption": shown.map(|(_, caption)| caption),
            "left": self.tour_left,
        })
    }

    /// The platform's `step` event: the step shown and its xAPI statement.
    pub fn step_event(&self, index: usize) -> Value {
        let mut detail = self.tour_json();
        let case = self.session().case().as_case();
        detail["statement"] = (case.lesson.steps.get(index))
            .map(|step| crate::case::xapi::step_shown(case, index, step))
            .unwrap_or_default();
        detail
    }
}
