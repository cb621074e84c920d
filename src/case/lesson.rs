//! The lesson a case carries: a tour of views with captions, labels on the structures'
//! surfaces, and a quiz. It names structures by their names, so that it reads the same in the
//! case glTF's `extras` and in a pipeline's JSON, and survives reordering.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::names::{self, Names};
use super::Case;
use super::{Clip, Planes};

/// Longest step title, label text or structure name the lesson accepts (characters).
const MAX_SHORT_TEXT: usize = 200;
/// Longest caption or label note (characters): a few sentences.
const MAX_LONG_TEXT: usize = 4000;
/// Most steps, labels or quiz structures (a whole-body case has a few hundred structures).
const MAX_ITEMS: usize = 1000;

/// What an author prepared for teaching with the case.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lesson {
    /// The tour, in order.
    #[serde(default)]
    pub steps: Vec<Step>,
    #[serde(default)]
    pub labels: Vec<Label>,
    #[serde(default)]
    pub quiz: Option<Quiz>,
}

/// One view of the tour: where the camera is, what is shown and how, and what it teaches.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Step {
    pub title: String,
    /// A few sentences shown beside the view.
    #[serde(default)]
    pub caption: String,
    /// The title and caption in other languages, by language tag, as structures' names are
    /// (the own ones stand for English); a reader sees those of the first of their languages
    /// there is one in.
    #[serde(default)]
    pub titles: Names,
    #[serde(default)]
    pub captions: Names,
    pub camera: Camera,
    /// Structures hidden in this view (the others are shown).
    #[serde(default)]
    pub hidden: Vec<String>,
    /// Structures drawn less than opaque, with their opacity in [0, 1].
    #[serde(default)]
    pub opacity: BTreeMap<String, f32>,
    #[serde(default)]
    pub selected: Option<String>,
    #[serde(default)]
    pub clip: Option<Clip>,
    /// The case's image in its three planes, where the step shows them (never beside a clip).
    #[serde(default)]
    pub planes: Option<Planes>,
    /// The slide from the smoothed surfaces (0) towards the segmentation (1).
    #[serde(default)]
    pub toward_segmentation: f32,
}

/// An orbit camera in the case's RAS millimetres, superior up: the eye at `distance` from
/// `target`, turned by `yaw` about the superior axis (0 looks from anterior) and raised by
/// `pitch` (radians), as the viewer's camera holds it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    pub target: [f32; 3],
    pub yaw: f32,
    pub pitch: f32,
    pub distance: f32,
}

impl Camera {
    /// Unit vector from the target to the eye (the viewer's orbit camera's convention).
    pub fn direction(&self) -> [f32; 3] {
        let (sin_yaw, cos_yaw) = self.yaw.sin_cos();
        let (sin_pitch, cos_pitch) = self.pitch.sin_cos();
        [-sin_yaw * cos_pitch, cos_yaw * cos_pitch, sin_pitch]
    }

    pub fn eye(&self) -> [f32; 3] {
        let d = self.direction();
        [0, 1, 2].map(|k| self.target[k] + self.distance * d[k])
    }
}

/// A point on a structure's surface with its text, shown with the structure.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Label {
    pub structure: String,
    /// Where it points, in the case's RAS millimetres.
    pub point: [f32; 3],
    pub text: String,
    /// A longer note, shown on asking.
    #[serde(default)]
    pub note: String,
    /// The text and note in other languages, by language tag, as a step's title and caption.
    #[serde(default)]
    pub texts: Names,
    #[serde(default)]
    pub notes: Names,
}

impl Label {
    /// A label saying `text`, with no note and no other languages.
    pub fn new(structure: &str, point: [f32; 3], text: &str) -> Self {
        Label {
            structure: structure.into(),
            point,
            text: text.into(),
            note: String::new(),
            texts: Names::new(),
            notes: Names::new(),
        }
    }
}

/// The quiz: which structures are asked, how, and the share of right answers that passes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Quiz {
    /// The structures asked; empty asks every structure shown.
    #[serde(default)]
    pub structures: Vec<String>,
    pub modes: Vec<QuizMode>,
    /// In [0, 1].
    pub pass_mark: f32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum QuizMode {
    /// The name is given; the student clicks the structure.
    FindIt,
    /// A structure is highlighted; the student picks its name from four.
    NameIt,
}

impl Quiz {
    /// Whether `right` of `questions` answers reach the pass mark.
    pub fn passes(&self, right: usize, questions: usize) -> bool {
        right as f32 / questions.max(1) as f32 >= self.pass_mark
    }
}

impl Lesson {
    pub fn is_empty(&self) -> bool {
        self.steps.is_empty() && self.labels.is_empty() && self.quiz.is_none()
    }

    /// Names structure `old` `new` wherever the lesson names it (the author renamed it).
    pub fn rename(&mut self, old: &str, new: &str) {
        let rename = |name: &mut String| {
            if name == old {
                *name = new.to_string();
            }
        };
        for step in &mut self.steps {
            step.hidden.iter_mut().for_each(rename);
            step.selected.iter_mut().for_each(rename);
            if let Some(a) = step.opacity.remove(old) {
                step.opacity.insert(new.to_string(), a);
            }
        }
        self.labels
            .iter_mut()
            .for_each(|l| rename(&mut l.structure));
        if let Some(quiz) = &mut self.quiz {
            quiz.structures.iter_mut().for_each(rename);
        }
    }

    /// The title and caption of step `index` a reader of `languages` (most wanted first) sees.
    pub fn step_text(&self, index: usize, languages: &[String]) -> Option<(&str, &str)> {
        let step = self.steps.get(index)?;
        Some((
            names::pick(&step.title, &step.titles, languages),
            names::pick(&step.caption, &step.captions, languages),
        ))
    }

    /// Reads a lesson from JSON (a pipeline's file, or what a case glTF's `extras` hold).
    pub fn from_json(text: &[u8]) -> Result<Self, String> {
        serde_json::from_slice(text).map_err(|e| format!("not a lesson: {e}"))
    }

    /// Refuses a lesson that names a structure `case` does not have, or holds a number or a
    /// text no viewer could show; the reason names the step, label or quiz entry.
    pub fn check(&self, case: &Case) -> Result<(), String> {
        let names = case.names();
        let known = |what: &str, name: &str| match names.contains(&name) {
            true => Ok(()),
            false => Err(format!(
                "{what} names '{name}', which the case does not have"
            )),
        };
        count("steps", self.steps.len())?;
        count("labels", self.labels.len())?;
        for (i, step) in self.steps.iter().enumerate() {
            let what = format!("step {} ('{}')", i + 1, short(&step.title));
            check_step(step, &what, &known)?;
        }
        for (i, label) in self.labels.iter().enumerate() {
            let what = format!("label {} ('{}')", i + 1, short(&label.text));
            known(&what, &label.structure)?;
            text(&what, "text", &label.text, MAX_SHORT_TEXT, false)?;
            text(&what, "note", &label.note, MAX_LONG_TEXT, true)?;
            translations(
                &what,
                &[
                    ("text", &label.texts, MAX_SHORT_TEXT),
                    ("note", &label.notes, MAX_LONG_TEXT),
                ],
            )?;
            finite(&what, "point", &label.point)?;
        }
        if let Some(quiz) = &self.quiz {
            count("quiz structures", quiz.structures.len())?;
            for name in &quiz.structures {
                known("the quiz", name)?;
            }
            if quiz.modes.is_empty() {
                return Err("the quiz has no mode (find-it, name-it)".into());
            }
            if !(0.0..=1.0).contains(&quiz.pass_mark) {
                return Err(format!(
                    "the quiz's pass mark {} is not in [0, 1]",
                    quiz.pass_mark
                ));
            }
        }
        Ok(())
    }
}

/// Refuses a text's other languages (`field`, the texts by tag, their longest) whose tags are not
/// language tags or whose texts are empty or too long.
fn translations(what: &str, fields: &[(&str, &Names, usize)]) -> Result<(), String> {
    for &(field, texts, max) in fields {
        names::checked(texts).map_err(|e| format!("{what}: its {field}s: {e}"))?;
        for (tag, t) in texts {
            text(what, &format!("{field} in '{tag}'"), t, max, false)?;
        }
    }
    Ok(())
}

fn check_step(
    step: &Step,
    what: &str,
    known: &impl Fn(&str, &str) -> Result<(), String>,
) -> Result<(), String> {
    text(what, "title", &step.title, MAX_SHORT_TEXT, false)?;
    text(what, "caption", &step.caption, MAX_LONG_TEXT, true)?;
    translations(
        what,
        &[
            ("title", &step.titles, MAX_SHORT_TEXT),
            ("caption", &step.captions, MAX_LONG_TEXT),
        ],
    )?;
    let c = &step.camera;
    finite(
        what,
        "camera",
        &[c.target[0], c.target[1], c.target[2], c.yaw, c.pitch],
    )?;
    if !(c.distance.is_finite() && c.distance > 0.0) {
        return Err(format!(
            "{what}: the camera's distance {} is not a positive length",
            c.distance
        ));
    }
    for name in step.hidden.iter().chain(step.opacity.keys()) {
        known(what, name)?;
    }
    if let Some(name) = &step.selected {
        known(what, name)?;
    }
    let unit = |v: f32| (0.0..=1.0).contains(&v);
    if let Some((name, a)) = step.opacity.iter().find(|(_, a)| !unit(**a)) {
        return Err(format!(
            "{what}: the opacity {a} of '{name}' is not in [0, 1]"
        ));
    }
    if step.clip.is_some_and(|c| !unit(c.at)) {
        return Err(format!("{what}: the clipping plane lies outside [0, 1]"));
    }
    if let Some(p) = step.planes {
        if step.clip.is_some() {
            return Err(format!(
                "{what}: shows both a clipping plane and the image's planes"
            ));
        }
        if ![p.sagittal, p.coronal, p.axial].into_iter().all(unit) {
            return Err(format!(
                "{what}: one of the image's planes lies outside [0, 1]"
            ));
        }
    }
    if !unit(step.toward_segmentation) {
        return Err(format!(
            "{what}: the slide towards the segmentation {} is not in [0, 1]",
            step.toward_segmentation
        ));
    }
    Ok(())
}

fn count(what: &str, n: usize) -> Result<(), String> {
    match n <= MAX_ITEMS {
        true => Ok(()),
        false => Err(format!("the lesson has {n} {what}, more than {MAX_ITEMS}")),
    }
}

fn text(
    what: &str,
    field: &str,
    value: &str,
    max: usize,
    may_be_empty: bool,
) -> Result<(), String> {
    let chars = value.chars().count();
    if chars > max {
        return Err(format!(
            "{what}: the {field} has {chars} characters, more than {max}"
        ));
    }
    if !may_be_empty && value.trim().is_empty() {
        return Err(format!("{what}: the {field} is empty"));
    }
    Ok(())
}

fn finite(what: &str, field: &str, values: &[f32]) -> Result<(), String> {
    match values.iter().find(|v| !v.is_finite()) {
        Some(v) => Err(format!(
            "{what}: the {field} holds {v}, not a finite number"
        )),
        None => Ok(()),
    }
}

/// The start of a text, for naming the item it belongs to.
fn short(text: &str) -> String {
    let mut s: String = text.chars().take(40).collect();
    if text.chars().count() > 40 {
        s.push_str("...");
    }
    s
}
