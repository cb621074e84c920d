//! The case in words, for screen readers: egui draws on a canvas that assistive technology
//! cannot read, so the page keeps the canvas's label and a list of the structures (hidden from
//! sight) up to date with the case. Element ids match `index.html`.

use crate::session::Session;

const CANVAS_ID: &str = "meshsmooth_canvas";
const LIST_ID: &str = "case_structures";

/// What the page's words were last written for: the structures' version, the selected one,
/// the case's file and title.
#[derive(Default)]
pub struct CaseText {
    written: Option<(u64, Option<usize>, String, String)>,
}

impl CaseText {
    /// Rewrites the canvas's label and the structures' list where the case changed.
    pub fn update(&mut self, session: &Session) {
        let (version, current) = (
            session.case().case_version(),
            session.case().current_structure(),
        );
        let (file, title) = (session.case().case_file(), session.case().case_title());
        if let Some((v, c, f, t)) = &self.written {
            if (*v, *c, f.as_str(), t.as_str()) == (version, current, file, title) {
                return;
            }
        }
        self.written = Some((version, current, file.to_string(), title.to_string()));
        let words = (label(session), lines(session));
        let Some(document) = web_sys::window().and_then(|w| w.document()) else {
            return;
        };
        if let Some(canvas) = document.get_element_by_id(CANVAS_ID) {
            let _ = canvas.set_attribute("aria-label", &words.0);
        }
        if let Some(list) = document.get_element_by_id(LIST_ID) {
            list.set_inner_html("");
            for line in &words.1 {
                if let Ok(item) = document.create_element("li") {
                    item.set_text_content(Some(line));
                    let _ = list.append_child(&item);
                }
            }
        }
    }
}

/// The canvas's label: what the view shows.
fn label(session: &Session) -> String {
    let structures = session.case().case_structures();
    let shown = structures.iter().filter(|s| s.visible).count();
    let title = session.case().case_title();
    let what = if title.is_empty() {
        session.case().case_file()
    } else {
        title
    };
    let mut text = format!(
        "3D view of {what}: {} structures, {shown} shown",
        structures.len()
    );
    if let Some(s) = session.case().model_structure() {
        text.push_str(&format!("; selected: {}", s.name));
    }
    text
}

/// One line per structure: its name, group, whether it is shown and how opaque, whether it is
/// selected, and its description.
fn lines(session: &Session) -> Vec<String> {
    let current = session.case().current_structure();
    (session.case().case_structures().iter().enumerate())
        .map(|(i, s)| {
            let mut line = s.name.clone();
            if let Some(group) = &s.group {
                line.push_str(&format!(" ({group})"));
            }
            line.push_str(if s.visible { ", shown" } else { ", hidden" });
            if s.visible && s.color[3] < 1.0 {
                line.push_str(&format!(", {:.0}% opaque", s.color[3] * 100.0));
            }
            if Some(i) == current {
                line.push_str(", selected");
            }
            if !s.description.is_empty() {
                line.push_str(&format!(": {}", s.description));
            }
            line
        })
        .collect()
}
