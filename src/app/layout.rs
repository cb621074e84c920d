//! Where the page drew what tests and the embedding page click (egui draws on a canvas
//! without a DOM), as `state()` reports it: the view, the graphs, the gallery, the structure
//! list.

use crate::view::CameraPose;

/// A rectangle on the page in points (CSS pixels at zoom 1), as `state()` reports it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PageRect {
    pub left: f32,
    pub top: f32,
    pub width: f32,
    pub height: f32,
}

impl PageRect {
    pub fn contains(self, [x, y]: [f32; 2]) -> bool {
        (self.left..=self.left + self.width).contains(&x)
            && (self.top..=self.top + self.height).contains(&y)
    }

    pub fn to_json(self) -> serde_json::Value {
        serde_json::json!({"x": self.left, "y": self.top, "width": self.width, "height": self.height})
    }
}

impl From<eframe::egui::Rect> for PageRect {
    fn from(r: eframe::egui::Rect) -> Self {
        Self {
            left: r.left(),
            top: r.top(),
            width: r.width(),
            height: r.height(),
        }
    }
}

/// The 3D view's part of `state()`: where it is on the page, whether the weight brush is on
/// and how long its latest pick took, and the labels drawn.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ViewReport {
    pub rect: PageRect,
    /// Where the camera is.
    pub pose: Option<CameraPose>,
    /// The clipping plane `(n, d)` in world millimetres (`n . p > d` cut away), zero with none.
    pub clip_plane: [f32; 4],
    pub brush_on: bool,
    pub pick_ms: Option<f64>,
    pub labels: Vec<DrawnLabel>,
}

/// A lesson label as the view drew it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DrawnLabel {
    /// Its text in the reader's language.
    pub text: String,
    /// Where its point is on the page.
    pub point: [f32; 2],
    /// A surface lies in front of its point.
    pub faded: bool,
    /// The plate its text is on, which shows or hides its note when clicked.
    pub plate: PageRect,
    /// Its note in the reader's language, empty when it has none.
    pub note: String,
    /// Whether the note is shown.
    pub open: bool,
}

impl DrawnLabel {
    pub fn to_json(&self) -> serde_json::Value {
        let [x, y] = self.point;
        serde_json::json!({"text": self.text, "x": x, "y": y, "faded": self.faded,
            "plate": self.plate.to_json(), "note": self.note, "open": self.open})
    }
}

/// Where the bottom panel's clickable parts were drawn in the latest frame (points), for
/// `state().layout`: egui draws on a canvas without a DOM, so tests find them here.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PanelLayout {
    /// The quality graphs shown: one column per parameter.
    pub graphs: Vec<GraphColumn>,
    /// The gallery cards' visible rectangles, in gallery order.
    pub gallery: Vec<PageRect>,
    /// The Structures list's rows as drawn, its Name field and its filter field.
    pub structures: Vec<StructureRow>,
    pub structure_name: Option<PageRect>,
    pub structure_filter: Option<PageRect>,
    /// The lesson's controls as drawn, by what they do (`labels`, the tour's `start`, `back`,
    /// `next`, `leave`, `resume`, the quiz's `quiz`, `choice-0` to `choice-3`,
    /// `next-question`, `again`, `end-quiz`; the authoring page's `lesson-tab` and its Lesson
    /// panel: `record`, `step-title-N`, `step-caption-N`, `step-up-N`, `step-down-N`,
    /// `step-delete-N`, `step-show-N`, `place-label`, `label-text-N`, `label-delete-N`,
    /// `quiz-on`, `quiz-find-it`, `quiz-name-it`).
    pub lesson: Vec<(String, PageRect)>,
    /// The sliders of the image's planes under the view (sagittal, coronal, axial), while the
    /// planes are shown.
    pub planes: Vec<PageRect>,
}

/// One row of the Structures list: its visibility box, show-alone button and name (which
/// selects it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StructureRow {
    pub index: usize,
    pub visible: PageRect,
    pub solo: PageRect,
    pub name: PageRect,
}

/// One parameter's column of graphs.
#[derive(Clone, Debug, PartialEq)]
pub struct GraphColumn {
    pub param: &'static str,
    /// Each strip's plot area and the parameter values at its left and right edges: a value's
    /// x is `left + width * (value - x0) / (x1 - x0)`.
    pub strips: Vec<(PageRect, [f64; 2])>,
}

impl PanelLayout {
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "graphs": self.graphs.iter().map(|c| serde_json::json!({
                "param": c.param,
                "strips": c.strips.iter().map(|(r, x)| {
                    let mut s = r.to_json();
                    s["x0"] = serde_json::json!(x[0]);
                    s["x1"] = serde_json::json!(x[1]);
                    s
                }).collect::<Vec<_>>(),
            })).collect::<Vec<_>>(),
            "gallery": self.gallery.iter().map(|r| r.to_json()).collect::<Vec<_>>(),
            "structures": self.structures.iter().map(|r| serde_json::json!({
                "index": r.index,
                "visible": r.visible.to_json(),
                "solo": r.solo.to_json(),
                "name": r.name.to_json(),
            })).collect::<Vec<_>>(),
            "structure_name": self.structure_name.map(PageRect::to_json),
            "structure_filter": self.structure_filter.map(PageRect::to_json),
            "lesson": self.lesson.iter().map(|(k, r)| (k.clone(), r.to_json()))
                .collect::<serde_json::Map<_, _>>(),
            "planes": self.planes.iter().map(|r| r.to_json()).collect::<Vec<_>>(),
        })
    }
}
