//! What the page has open, shared by the UI and the JavaScript embedding API: the session, the
//! API calls waiting for a result, and the timings the status bar shows.
//!
//! Both sides only change the session; the shell computes what a change needs once per frame
//! (so an API call never blocks the page inside a frame), then answers the waiting calls.

use crate::session::Session;
use crate::suggest::Offload;
use crate::view::{Clip, Planes, StandardView, ViewLink};
use crate::worker::NamedFile;

use super::backend::{Backend, EngineTimings};
use super::layout::{DrawnLabel, PanelLayout, ViewReport};
use super::words::Words;
use std::cell::RefCell;
use std::rc::Rc;

/// A call waiting for the result of the current parameters (the API's `metrics()` and
/// `exportMesh()`); it receives the session once that result is there.
pub type Waiter = Box<dyn FnOnce(&Session)>;

/// A call waiting for a file being opened (the API's `loadMesh`): the session once the file is
/// open, or why it is not.
pub type LoadWaiter = Box<dyn FnOnce(Result<&Session, String>)>;

/// A call waiting for a picture of the view (the API's `screenshot()`): PNG bytes, or why not.
pub type PictureWaiter = Box<dyn FnOnce(Result<Vec<u8>, String>)>;

/// When a waiting call is answered.
pub type Ready = fn(&Session) -> bool;

/// What a frame did for a file being opened (see [`Document::step_loading`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Opening {
    /// Nothing is being opened.
    Idle,
    /// Still opening.
    Working,
    /// Opened, or failed, in this frame.
    Done,
}

/// What the view is asked to show beyond the camera the user moves: the clipping plane, and a
/// standard side to look from (taken by the view in its next frame).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ViewAsks {
    pub clip: Option<Clip>,
    /// The image's three planes, shown instead of a clip.
    pub planes: Option<Planes>,
    pub look_from: Option<StandardView>,
    /// How far every structure is drawn back towards its segmentation (0 as smoothed).
    pub toward_segmentation: f32,
    /// The tour step to show next (the shell takes it up).
    pub step: Option<usize>,
    /// The case's labels are not drawn.
    pub hide_labels: bool,
}

pub struct Document {
    /// The case and the engines; the shell reads the case through [`Self::case`].
    session: Session,
    /// Which engine smooths: its one home (the shell's GPU engine runs only while it is the
    /// WebGPU engine).
    backend: Backend,
    /// Why the GPU engine was given up for the CPU engine.
    gpu_fallback: Option<String>,
    /// Timings of the last result.
    pub timings: Option<EngineTimings>,
    /// What the 3D view reports to `state()`.
    pub view: ViewReport,
    pub view_asks: ViewAsks,
    /// The name of the structure under the pointer in the view.
    pub pointed: Option<String>,
    /// The reader's languages, most wanted first: the viewer (and the author's preview) names
    /// structures in the first one they have a name in.
    pub languages: Vec<String>,
    /// Whether keys act (an embedding page can turn them off).
    pub shortcuts: bool,
    /// Where the graphs and gallery cards are, for `state()`.
    pub panel: PanelLayout,
    /// The tour step shown, while the student follows the case's tour.
    pub tour: Option<usize>,
    /// The step the student left the tour at.
    pub tour_left: Option<usize>,
    /// The quiz the student is taking.
    pub quiz: Option<crate::view::QuizRun>,
    /// The author's next click in the view places a label.
    pub placing_label: bool,
    /// The language tag the Lesson panel's words are edited in; empty: the own (English) words.
    pub lesson_language: String,
    /// The author sees the case as the student will, in the viewer's panel, without exporting.
    pub previewing: bool,
    /// What the lesson's player tells the embedding page (event, detail), in order.
    pub lesson_events: Vec<(&'static str, serde_json::Value)>,
    waiting: Vec<Waiter>,
    /// Calls waiting for background work (a suggestion, the graphs).
    waiting_for: Vec<(Ready, Waiter)>,
    /// Set by the API's `gallery()`: the page shows the gallery tab.
    pub show_gallery: bool,
    /// Whether the background's runs went to the GPU engine in the latest frame.
    pub guidance_on_gpu: bool,
    /// Calls waiting for the file being opened.
    waiting_for_load: Vec<LoadWaiter>,
    /// Calls waiting for a picture of the view.
    pub waiting_for_picture: Vec<PictureWaiter>,
}

/// The handle the shell and the API hold.
pub type SharedDocument = Rc<RefCell<Document>>;

impl Document {
    /// The case's names, labels and notes in the words the page shows them in.
    pub fn words(&self) -> Words<'_> {
        // The reader's languages where the page is read (the viewer, the author's preview);
        // none while the author edits, who sees the case's own names.
        let languages = match super::query::is_viewer() || self.previewing {
            true => &self.languages[..],
            false => &[],
        };
        Words {
            structures: self.session.case().as_case().structures.as_slice(),
            languages,
        }
    }

    /// The case (`session().case()`), its openings, the CPU engine and the background work.
    pub fn session(&self) -> &Session {
        &self.session
    }

    pub fn session_mut(&mut self) -> &mut Session {
        &mut self.session
    }

    /// The session beside the panel layout the panels write, for panels that need both.
    pub fn session_and_panel(&mut self) -> (&mut Session, &mut PanelLayout) {
        (&mut self.session, &mut self.panel)
    }

    pub fn with_backend(backend: Backend) -> Self {
        Self {
            session: Session::default(),
            backend,
            gpu_fallback: None,
            timings: None,
            view: ViewReport::default(),
            view_asks: ViewAsks::default(),
            pointed: None,
            languages: Vec::new(),
            shortcuts: true,
            panel: PanelLayout::default(),
            tour: None,
            tour_left: None,
            quiz: None,
            placing_label: false,
            lesson_language: String::new(),
            previewing: false,
            lesson_events: Vec::new(),
            waiting: Vec::new(),
            waiting_for: Vec::new(),
            show_gallery: false,
            guidance_on_gpu: false,
            waiting_for_load: Vec::new(),
            waiting_for_picture: Vec::new(),
        }
    }

    /// Opens a file's bytes at once, on the page's thread (the bundled sample at start); on
    /// failure the current model stays and the error is kept.
    pub fn open_now(&mut self, name: &str, bytes: &[u8]) -> Result<(), String> {
        match self.session.open(name, bytes) {
            Ok(_) => {
                self.opened();
                Ok(())
            }
            Err(message) => {
                log::warn!("{message}");
                Err(message)
            }
        }
    }

    /// Asks a worker to open files chosen or dropped together as one case
    /// ([`Self::step_loading`] takes it); the current model stays until it is open. `waiter`,
    /// when given, hears how it ended. Files still opening are dropped for these, and their
    /// waiters hear so.
    pub fn ask_open(&mut self, files: Vec<NamedFile>, waiter: Option<LoadWaiter>) {
        let name = files.first().map_or_else(String::new, |f| f.name.clone());
        if let Some(replaced) = self.session.begin_open_files(files) {
            let why = format!("{replaced} was not opened: {name} was opened before it finished");
            for w in std::mem::take(&mut self.waiting_for_load) {
                w(Err(why.clone()));
            }
        }
        self.waiting_for_load.extend(waiter);
    }

    /// Makes structure `index` of the open case the model, at once or once a worker built a
    /// large one's model (its settings and result are in the case; see
    /// [`Session::select_structure`]); another model ends the page's tour and quiz.
    pub fn select(&mut self, index: usize) -> Result<(), String> {
        let before = self.session.case().model_id();
        self.session.select_structure(index)?;
        if self.session.case().model_id() != before {
            self.opened();
        } else if self.session.selecting() == Some(index) {
            self.leave_lesson();
        }
        Ok(())
    }

    /// Asks a worker to add a file's structures to the open case (after the file opening now,
    /// if one is). `waiter`, when given, hears once everything asked to open is open.
    pub fn ask_add(&mut self, name: &str, bytes: Vec<u8>, waiter: Option<LoadWaiter>) {
        self.session.begin_add(name, bytes);
        self.waiting_for_load.extend(waiter);
    }

    /// Asks a worker to read the image under the open case's surfaces: one file, or the
    /// slices of a DICOM series. `waiter`, when given, hears once it is read (or at once, when
    /// it cannot be asked).
    pub fn ask_image(
        &mut self,
        files: Vec<crate::worker::NamedFile>,
        preset: crate::case::WindowPreset,
        waiter: Option<LoadWaiter>,
    ) {
        match self.session.begin_image(files, preset) {
            Ok(()) => self.waiting_for_load.extend(waiter),
            Err(why) => {
                log::warn!("{why}");
                if let Some(w) = waiter {
                    w(Err(why));
                }
            }
        }
    }

    /// Whether nothing is being opened, a worker is still opening it, or it opened (or failed)
    /// in this frame. The last takes the frame: the engines take up a new model from the next
    /// frame on, before the view does. The waiters hear once nothing more is to open, of the
    /// first failure if there was one.
    pub fn step_loading(&mut self) -> Opening {
        if self.session.loading().is_none() {
            return Opening::Idle;
        }
        let model_before = self.session.case().model_id();
        let selected = self.session.selecting();
        let Some(outcome) = self.session.poll_opening() else {
            return Opening::Working;
        };
        let new_model = self.session.case().model_id() != model_before;
        match &outcome {
            // The lesson was left when the structure was selected.
            Ok(()) if new_model && selected.is_some() => self.took_model(),
            // A file added to the case leaves the model as it was.
            Ok(()) if new_model => self.opened(),
            Ok(()) => {}
            Err(message) => log::warn!("{message}"),
        }
        if let (None, Some(outcome)) = (self.session.loading(), self.session.openings().last()) {
            let outcome = outcome.clone();
            for w in std::mem::take(&mut self.waiting_for_load) {
                w(outcome.clone().map(|()| &self.session));
            }
        }
        Opening::Done
    }

    /// What a newly opened model needs.
    fn opened(&mut self) {
        self.took_model();
        self.leave_lesson();
    }

    /// Another model: the timings were another's.
    fn took_model(&mut self) {
        if let Some(model) = self.session.case().model() {
            log::info!(
                "opened {}: {} vertices, {} faces",
                model.name,
                model.report.vertices,
                model.report.faces
            );
        }
        self.timings = None;
    }

    /// Another case or another structure: the tour and the quiz end.
    fn leave_lesson(&mut self) {
        self.tour = None;
        self.tour_left = None;
        self.quiz = None;
    }

    /// Which engine smooths.
    pub fn backend(&self) -> Backend {
        self.backend
    }

    /// Why the GPU engine was given up, once it was.
    pub fn gpu_fallback(&self) -> Option<&str> {
        self.gpu_fallback.as_deref()
    }

    /// Gives up the GPU engine for the CPU engine, for the rest of the page's life.
    pub fn fall_back_to_cpu(&mut self, why: String) {
        log::error!("GPU engine failed, using the CPU engine: {why}");
        self.backend = Backend::Cpu;
        self.gpu_fallback = Some(why);
    }

    /// Whether work for the current parameters is still to do.
    pub fn busy(&self) -> bool {
        self.session.case().needs_smoothing()
    }

    /// Runs `waiter` once the current parameters' result is there (at once if it is).
    pub fn when_current(&mut self, waiter: Waiter) {
        if self.busy() {
            self.waiting.push(waiter);
        } else {
            waiter(&self.session);
        }
    }

    /// Runs `waiter` once `ready` holds for the session (checked every frame).
    pub fn when(&mut self, ready: Ready, waiter: Waiter) {
        self.waiting_for.push((ready, waiter));
    }

    /// Answers the waiting calls whose result is there.
    pub fn answer_waiting(&mut self) {
        if !self.waiting_for.is_empty() {
            let (ready, later): (Vec<_>, Vec<_>) = std::mem::take(&mut self.waiting_for)
                .into_iter()
                .partition(|(ready, _)| ready(&self.session));
            self.waiting_for = later;
            for (_, waiter) in ready {
                waiter(&self.session);
            }
        }
        if self.busy() || self.waiting.is_empty() {
            return;
        }
        for waiter in std::mem::take(&mut self.waiting) {
            waiter(&self.session);
        }
    }

    /// Whether all the work under way runs in the CPU engine's workers, whose replies wake
    /// the page: then frames are needed only when one lands, not continuously. The GPU
    /// engine works in frames, but only while it has the current result or the background's
    /// runs to do (where they go to it: on a software adapter they go to the workers);
    /// "Suggest all" and the checks run in the workers with either engine.
    pub fn working_elsewhere(&self) -> bool {
        let guidance_on_gpu = self.guidance_on_gpu && self.session.background().guidance_busy();
        let gpu_at_work = self.backend == Backend::WebGpu && (self.busy() || guidance_on_gpu);
        !gpu_at_work
            && self.session.case_export().progress().is_none()
            && self.session.cpu_engine().threaded()
    }

    /// Whether anything is computing (the current result or background work), so the page
    /// keeps drawing frames.
    pub fn working(&self) -> bool {
        self.busy()
            || self.session.background().guidance_busy()
            || self.session.loading().is_some()
            || self.session.background().suggesting_all()
            || self.session.background().checking()
            || self.session.case_export().progress().is_some()
    }

    /// The CPU engine's share of this frame: asks its workers for the current parameters'
    /// result, or takes it once it came (then true).
    pub fn compute_on_cpu(&mut self) -> bool {
        let Some(t) = self.session.compute_cpu() else {
            return false;
        };
        self.timings = Some(EngineTimings::Cpu(t));
        true
    }

    /// Between frames (an API call, a worker's reply): takes the structures "Suggest all" got
    /// and hands out the next; with the CPU engine in workers, sends the current parameters'
    /// smoothing or takes its result now, moves the background work on, and answers the calls
    /// waiting, rather than a frame of a large mesh later. True when what the page shows
    /// changed (a result taken, a search or graph finished, "Suggest all" ended): a frame is
    /// due.
    pub fn step_cpu_engine(&mut self) -> bool {
        self.session.pump_cpu_engine();
        // Its surfaces show with the next paced frame; the workers need not wait for it. Its
        // end shows at once.
        let ended = self.session.step_suggest_all();
        if !self.session.cpu_engine().threaded() {
            return ended;
        }
        // The GPU engine computes the current result in frames; the background's runs that
        // go to the workers move on between frames with either engine.
        let took = self.backend == Backend::Cpu && self.compute_on_cpu();
        let finished = !self.guidance_on_gpu && self.compute_guidance(None);
        self.answer_waiting();
        took || finished || ended
    }

    /// The background work's share of this frame (graphs, suggestions, the gallery): hands
    /// its runs to the CPU engine's workers, or to the GPU engine's evaluator when one is lent.
    /// With the CPU engine it waits until the current parameters' result is there: what the
    /// user is looking at comes first. True when a job finished.
    pub fn compute_guidance(&mut self, offload: Option<&mut dyn Offload>) -> bool {
        if !crate::AUTHORING || (self.backend == Backend::Cpu && self.busy()) {
            return false;
        }
        self.session.step_guidance_on(&now_ms, offload)
    }

    /// What the API's `state()` returns.
    pub fn state_json(&self) -> serde_json::Value {
        let mut state = super::api::json::session_state(&self.session, self.busy());
        state["backend"] = serde_json::json!(self.backend.name());
        state["mode"] = serde_json::json!(super::query::mode_name());
        state["preview"] = serde_json::json!(self.previewing);
        state["shortcuts"] = serde_json::json!(self.shortcuts);
        // The page's own memory beside its workers' (each instance's peak: it only grows).
        state["memory"] = serde_json::json!({
            "page": super::workers::memory_bytes(),
            "workers": self.session.cpu_engine().memory(),
        });
        state["guidance"]["engine"] = serde_json::json!(if self.guidance_on_gpu {
            "webgpu"
        } else {
            "cpu"
        });
        state["timings"] = match self.timings {
            Some(EngineTimings::Cpu(t)) => {
                serde_json::json!({"smooth_ms": t.smooth_ms, "measure_ms": t.measure_ms})
            }
            Some(EngineTimings::Gpu { run_ms }) => serde_json::json!({ "gpu_run_ms": run_ms }),
            None => serde_json::Value::Null,
        };
        let v = &self.view;
        state["brush"] = serde_json::json!({"on": v.brush_on, "pick_ms": v.pick_ms});
        state["view"] = v.rect.to_json();
        state["view"]["clip"] = serde_json::to_value(self.view_asks.clip).unwrap_or_default();
        state["view"]["clip_plane"] = serde_json::json!(v.clip_plane);
        state["view"]["planes"] = serde_json::to_value(self.view_asks.planes).unwrap_or_default();
        state["view"]["pointed"] = serde_json::json!(self.pointed);
        state["view"]["labels"] = v.labels.iter().map(DrawnLabel::to_json).collect();
        state["view"]["toward_segmentation"] =
            serde_json::json!(self.view_asks.toward_segmentation);
        state["view"]["link"] = serde_json::json!(super::query::viewer_url(&self.view_link()));
        state["view"]["camera"] = match self.view.pose {
            Some(p) => serde_json::json!({"yaw": p.yaw, "pitch": p.pitch, "distance": p.distance,
                "target": p.target.to_array()}),
            None => serde_json::Value::Null,
        };
        state["layout"] = self.panel.to_json();
        state["tour"] = self.tour_json();
        state["quiz"] = self.quiz_json();
        state
    }
}

impl Document {
    /// The view as it stands: camera, hidden and see-through structures, the selected one,
    /// the clipping plane or the image's planes and the slide towards the segmentation.
    pub fn view_link(&self) -> ViewLink {
        let listed = self.session.case().as_case().structures.iter().enumerate();
        ViewLink {
            camera: self.view.pose,
            hidden: (listed.clone().filter(|(_, s)| !s.visible))
                .map(|(i, _)| i)
                .collect(),
            opacity: (listed.filter(|(_, s)| s.color[3] < 1.0))
                .map(|(i, s)| (i, s.color[3]))
                .collect(),
            selected: self.session.case().current_structure().filter(|&i| i > 0),
            clip: self.view_asks.clip,
            planes: self.view_asks.planes,
            toward_segmentation: self.view_asks.toward_segmentation,
        }
    }
}

/// Milliseconds from the page's high-resolution clock.
pub fn now_ms() -> f64 {
    web_sys::window()
        .and_then(|w| w.performance())
        .map_or_else(js_sys::Date::now, |p| p.now())
}

#[cfg(test)]
mod tests;
