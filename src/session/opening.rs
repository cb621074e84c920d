//! Opening files: handed to the CPU engine's workers (which read the files as a case, build
//! its first structure's topology, check the mesh and measure the original, then send them
//! whole), while the open model stays until the new one is there. Without threads the same
//! request is done on the calling thread as it is made.

use super::{Model, Session};
use crate::case::{self, Case};
use crate::mesh::Mesh;
use crate::model::Opened;
use crate::segmentation::NamedBytes;
use crate::worker::{Input, LoadJob, NamedFile, Reply};

/// How far an opening got: the stage under way (0-based) of [`LoadProgress::total`].
#[derive(Clone, Debug, PartialEq)]
pub struct LoadProgress {
    pub name: String,
    pub stage: usize,
    pub total: usize,
    /// What the stage under way does ("waiting for a worker" before one took it).
    pub doing: String,
    /// The stages done, in [0, 1].
    pub fraction: f32,
}

/// How the files asked to open ended: the first failure among those asked since nothing was
/// opening, and, once none is left, that batch's outcome, numbered so that each listener (the
/// API's waiters, the embedding page) hears each ending once.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Openings {
    failure_so_far: Option<String>,
    ended: u64,
    last: Option<Result<(), String>>,
}

impl Openings {
    /// How many batches of files have ended, the latest included.
    pub fn ended(&self) -> u64 {
        self.ended
    }

    /// How the latest batch ended: open, or the first failure among its files.
    pub fn last(&self) -> Option<&Result<(), String>> {
        self.last.as_ref()
    }

    fn record(&mut self, outcome: &Result<(), String>, batch_over: bool) {
        if let Err(why) = outcome {
            self.failure_so_far.get_or_insert_with(|| why.clone());
        }
        if batch_over {
            self.ended += 1;
            self.last = Some(self.failure_so_far.take().map_or(Ok(()), Err));
        }
    }
}

/// What an opening makes of what comes back.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Purpose {
    /// A file becomes the open case, its first structure the model.
    File,
    /// A file's structures join the open case.
    Add,
    /// A file is the image under the open case's surfaces.
    Image,
    /// A structure of the open case, selected, becomes the model.
    Select { structure: usize },
}

impl Purpose {
    /// How a failure names the file: an image is told apart from the case it goes under.
    fn shown(self, name: &str) -> String {
        match self {
            Purpose::Image => format!("the image {name}"),
            Purpose::File | Purpose::Add | Purpose::Select { .. } => name.to_string(),
        }
    }
}

/// Structures of more vertices than this have their model built by a worker when selected:
/// a smaller one's builds within a frame on the page's thread, and is the model at once.
pub const BUILT_ELSEWHERE_ABOVE: usize = 20_000;

/// An opening asked of the workers.
pub(super) struct WorkerOpening {
    name: String,
    job: LoadJob,
    purpose: Purpose,
    /// The file the model comes from (the first label map, else the first file).
    first_file: String,
}

impl Session {
    /// Opens a file's bytes on this thread, at once. On failure the current model stays, the
    /// error is recorded (and returned) as "Cannot open NAME: reason".
    pub fn open(&mut self, name: &str, bytes: &[u8]) -> Result<&Model, String> {
        match Model::load(name, bytes) {
            Ok(Opened { case, model }) => {
                self.take_file(name, name, case, model);
                Ok(self.doc.model().expect("just set"))
            }
            Err(e) => Err(self.fail(name, &e.reason())),
        }
    }

    /// Starts opening a file's bytes in a worker ([`Self::poll_opening`] takes the model); the
    /// current model stays open meanwhile. Returns the name of an opening this one replaces.
    pub fn begin_open(&mut self, name: &str, bytes: Vec<u8>) -> Option<String> {
        let name = name.to_string();
        self.begin_open_files(vec![NamedFile { name, bytes }])
    }

    /// Starts opening files chosen or dropped together as one case, as the CLI's `case build`
    /// opens them: several masks one structure each, a colour table naming a label map's
    /// labels, surfaces and case glTFs after them. Otherwise as [`Self::begin_open`].
    pub fn begin_open_files(&mut self, files: Vec<NamedFile>) -> Option<String> {
        // Files to add were meant for the case open or opening now, not this one.
        self.additions.clear();
        let named: Vec<NamedBytes> = (files.iter())
            .map(|f| NamedBytes {
                name: &f.name,
                bytes: &f.bytes,
            })
            .collect();
        // A colour table beside a label map names its labels: the case is the label map's.
        // (Two tables are refused by the worker; the name then lists every file.)
        let shown =
            case::split_color_table(&named).map_or_else(|_| named.clone(), |(rest, _)| rest);
        let first_file = case::first_structure_file(&shown)
            .unwrap_or_default()
            .to_string();
        let name = match shown.as_slice() {
            [one] => one.name.to_string(),
            [a, b] => format!("{} and {}", a.name, b.name),
            [a, rest @ ..] => format!("{} and {} more files", a.name, rest.len()),
            [] => String::new(),
        };
        self.begin(name, first_file, Input::Files(files), Purpose::File)
    }

    /// Starts adding a file's structures (a label map's, a case glTF's, a surface) to the open
    /// case; the model stays. While another file opens, this one waits for it (several files
    /// dropped together open as one case). With nothing open, opens the file instead.
    pub fn begin_add(&mut self, name: &str, bytes: Vec<u8>) {
        if self.opening.is_some() || !self.additions.is_empty() {
            self.additions.push_back((name.to_string(), bytes));
        } else {
            self.start_add(name, bytes);
        }
    }

    fn start_add(&mut self, name: &str, bytes: Vec<u8>) {
        if self.doc.model().is_none() {
            self.begin_open(name, bytes);
        } else {
            let first_file = name.to_string();
            self.begin(
                first_file.clone(),
                first_file,
                Input::Add(bytes),
                Purpose::Add,
            );
        }
    }

    /// Starts reading the image the open case's segmentation was drawn on, windowed by
    /// `preset`, in a worker: one file, or the slices of a DICOM series (several files, named
    /// "DICOM series (N slices)"). It replaces the case's image once read and checked against
    /// the structures' grids. Refused at once when nothing is open, or while a file opens (the
    /// grids to check are not known yet).
    pub fn begin_image(
        &mut self,
        files: Vec<NamedFile>,
        preset: case::WindowPreset,
    ) -> Result<(), String> {
        let name = match files.as_slice() {
            [one] => one.name.clone(),
            _ => format!("DICOM series ({} slices)", files.len()),
        };
        let name = name.as_str();
        if self.file_opening() || !self.additions.is_empty() || self.doc.model().is_none() {
            let why = "open the segmentation first, and wait until it is open";
            return Err(self.fail(name, why));
        }
        let input = Input::Image {
            files,
            preset: preset.name().to_string(),
            grids: self.doc.case.image_grids(),
        };
        self.begin(name.to_string(), name.to_string(), input, Purpose::Image);
        Ok(())
    }

    /// Whether structure `mesh`'s model would be built by a worker: a large one, with workers
    /// on other threads, while no file opens (which the structure's model would supersede).
    pub(super) fn builds_elsewhere(&self, mesh: &Mesh) -> bool {
        mesh.vertex_count() > BUILT_ELSEWHERE_ABOVE && self.cpu.threaded() && !self.file_opening()
    }

    /// Whether a file is being opened (not a structure's model built).
    fn file_opening(&self) -> bool {
        (self.opening.as_ref()).is_some_and(|o| !matches!(o.purpose, Purpose::Select { .. }))
    }

    /// Starts building structure `index`'s model (named `name`, of its surface `mesh`) in a
    /// worker; [`Self::poll_opening`] makes it the model once it is there.
    pub(super) fn begin_select(&mut self, index: usize, name: String, mesh: Mesh) {
        let purpose = Purpose::Select { structure: index };
        self.begin(name.clone(), name, Input::Structure(mesh), purpose);
    }

    /// The structure whose model a worker is building, to become the model once it is there.
    pub fn selecting(&self) -> Option<usize> {
        match self.opening.as_ref()?.purpose {
            Purpose::Select { structure } => Some(structure),
            _ => None,
        }
    }

    /// Stops waiting for the structure whose model a worker is building (another became the
    /// model); its answer is dropped.
    pub(super) fn drop_selecting(&mut self) {
        if self.selecting().is_some() {
            if let Some(opening) = self.opening.take() {
                self.cpu.forget_load(opening.job);
            }
        }
    }

    /// Takes the image from under the case's surfaces.
    pub fn remove_image(&mut self) {
        self.doc.set_image(None);
    }

    /// Starts the next file waiting to be added, once nothing is being opened.
    fn next_addition(&mut self) {
        if self.opening.is_none() {
            // Started at once: those still waiting wait for this one.
            if let Some((name, bytes)) = self.additions.pop_front() {
                self.start_add(&name, bytes);
            }
        }
    }

    fn begin(
        &mut self,
        name: String,
        first_file: String,
        input: Input,
        purpose: Purpose,
    ) -> Option<String> {
        let replaced = match self.opening.take() {
            // A file becoming the case drops a structure still being built; else it is built
            // here first, as selected (the new opening supersedes its worker's job).
            Some(WorkerOpening {
                purpose: Purpose::Select { structure },
                ..
            }) => {
                if matches!(purpose, Purpose::Add | Purpose::Image)
                    && self.doc.select(structure).unwrap_or(false)
                {
                    self.became_model();
                }
                None
            }
            other => other.map(|o| o.name),
        };
        self.open_stages.clear();
        let job = self.cpu.load(&name, input);
        self.opening = Some(WorkerOpening {
            name,
            job,
            purpose,
            first_file,
        });
        replaced
    }

    /// Takes what is being opened once it is there: `Ok` with it open (or added), or the
    /// error (as [`Self::open`] reports it) with the previous model still open. `None` while
    /// the worker is at it, or when nothing is being opened.
    pub fn poll_opening(&mut self) -> Option<Result<(), String>> {
        let opening = self.opening.as_ref()?;
        let reply = self.cpu.take_loaded(opening.job)?;
        let WorkerOpening {
            name,
            purpose,
            first_file,
            ..
        } = self.opening.take()?;
        let outcome = self.take_opened(&name, &first_file, purpose, reply);
        if outcome.is_err() && purpose == Purpose::File {
            // Files to add to a case that did not open.
            self.additions.clear();
        }
        self.next_addition();
        if !matches!(purpose, Purpose::Select { .. }) {
            let batch_over = self.opening.is_none();
            self.openings.record(&outcome, batch_over);
        }
        Some(outcome)
    }

    fn take_opened(
        &mut self,
        name: &str,
        first_file: &str,
        purpose: Purpose,
        reply: Reply,
    ) -> Result<(), String> {
        let (model, case, stages) = match reply {
            Reply::Loaded {
                model,
                case,
                stages,
                ..
            } => (model, case, stages),
            Reply::Failed { why, .. } => return Err(self.fail(&purpose.shown(name), &why)),
            _ => return Err(self.fail(name, "a worker answered something else")),
        };
        self.open_stages = stages;
        match (purpose, model, case) {
            (Purpose::File, Some(model), Some(case)) => {
                self.take_file(name, first_file, *case, *model)
            }
            (Purpose::Add, _, Some(case)) => {
                self.error = None;
                self.doc.add(*case);
            }
            (Purpose::Image, _, Some(case)) => {
                self.error = None;
                self.doc.set_image(case.image);
            }
            (Purpose::Select { structure }, Some(model), None) => {
                if !self.doc.select_built(structure, *model) {
                    return Err(self.fail(name, "the case changed while it was built"));
                }
                self.became_model();
            }
            _ => return Err(self.fail(name, "a worker answered something else")),
        }
        Ok(())
    }

    /// Makes the case of files opened as `name` the open one and `model` (its first structure,
    /// from `first_file`) the model. A label map's or a case glTF's structure brings its own
    /// filter and parameters (a label map's with the bound at half its voxel diagonal); a
    /// surface takes those of the model before it, so files opened one after another smooth
    /// alike.
    fn take_file(&mut self, name: &str, first_file: &str, case: Case, model: Model) {
        // A "Suggest all" or checks of the structures before are of no use now.
        self.cancel_suggest_all();
        self.suggest_all = Default::default();
        self.checks = Default::default();
        self.case_export = Default::default();
        self.doc.adopt(case, name, first_file, model);
        self.became_model();
    }

    /// How long each stage of the latest opening took (ms), in order.
    pub fn open_stages(&self) -> &[(String, f64)] {
        &self.open_stages
    }

    /// Whether a file is opening and its worker has not answered yet (an answer waits for the
    /// next frame to take it up).
    pub fn opening_unanswered(&self) -> bool {
        self.opening
            .as_ref()
            .is_some_and(|o| !self.cpu.has_loaded(o.job))
    }

    /// How the files asked to open ended ([`Openings`]).
    pub fn openings(&self) -> &Openings {
        &self.openings
    }

    /// How far the file being opened got, while one is.
    pub fn loading(&self) -> Option<LoadProgress> {
        let opening = self.opening.as_ref()?;
        let (stage, total, doing) = match self.cpu.load_stage(opening.job) {
            Some(s) => (s.stage as usize, s.stages as usize, s.doing.clone()),
            None => (0, 1, "waiting for a worker".to_string()),
        };
        Some(LoadProgress {
            name: opening.name.clone(),
            stage,
            total,
            doing,
            fraction: stage as f32 / total.max(1) as f32,
        })
    }
}
