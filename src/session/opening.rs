//! Opening files and structures: handed to the CPU engine's workers (which parse, build the
//! topology, check the mesh and measure the original, then send the model whole), while the
//! open model stays until the new one is there. Without threads the same request is done on
//! the calling thread as it is made.

use super::{Model, Session, Structures};
use crate::worker::{Input, LoadJob, Reply};

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

/// An opening asked of the workers.
pub(super) struct Opening {
    name: String,
    job: LoadJob,
    /// A structure's list, attached to the model that comes back.
    structures: Option<Structures>,
}

impl Session {
    /// Opens a file's bytes on this thread, at once. On failure the current model stays, the
    /// error is recorded (and returned) as "Cannot open NAME: reason".
    pub fn open(&mut self, name: &str, bytes: &[u8]) -> Result<&Model, String> {
        match Model::load(name, bytes) {
            Ok(model) => {
                self.set_model(model);
                self.reset_looks();
                Ok(self.model.as_ref().expect("just set"))
            }
            Err(e) => Err(self.fail(name, &e.to_string())),
        }
    }

    /// Starts opening a file's bytes in a worker ([`Self::poll_opening`] takes the model); the
    /// current model stays open meanwhile. Returns the name of an opening this one replaces.
    pub fn begin_open(&mut self, name: &str, bytes: Vec<u8>) -> Option<String> {
        self.begin(name.to_string(), Input::File(bytes), None)
    }

    /// Starts opening structure `index` of the open segmentation as the model, as a file opens.
    /// Errors when no segmentation is open or it has no such structure.
    pub fn begin_open_structure(&mut self, index: usize) -> Result<Option<String>, String> {
        let Some(structures) = self.structures().cloned() else {
            return Err("no segmentation is open".to_string());
        };
        let Some(structure) = structures.list.get(index) else {
            return Err(format!(
                "structure {index} does not exist: the segmentation has {}",
                structures.list.len()
            ));
        };
        let name = format!("{}: {}", structures.file, structure.name);
        let input = Input::Structure(structure.mesh.clone());
        let structures = Structures {
            current: index,
            ..structures
        };
        Ok(self.begin(name, input, Some(structures)))
    }

    fn begin(
        &mut self,
        name: String,
        input: Input,
        structures: Option<Structures>,
    ) -> Option<String> {
        let replaced = self.opening.take().map(|o| o.name);
        self.open_stages.clear();
        let job = self.cpu.load(&name, input);
        self.opening = Some(Opening {
            name,
            job,
            structures,
        });
        replaced
    }

    /// Takes the model being opened once it is there: `Ok` with it open, or the error (as
    /// [`Self::open`] reports it) with the previous model still open. `None` while the worker
    /// is at it, or when nothing is being opened.
    pub fn poll_opening(&mut self) -> Option<Result<(), String>> {
        let opening = self.opening.as_ref()?;
        let reply = self.cpu.take_loaded(opening.job)?;
        let Opening {
            name, structures, ..
        } = self.opening.take()?;
        match reply {
            Reply::Loaded {
                mut model, stages, ..
            } => {
                self.open_stages = stages;
                let switching = structures.is_some();
                if switching {
                    // Another structure of the open segmentation: the one leaving keeps its
                    // smoothing, the one coming gets back what it kept.
                    self.keep_model_structure();
                    model.structures = structures;
                }
                self.set_model(*model);
                if switching {
                    self.restore_model_structure();
                } else {
                    self.reset_looks();
                }
                Some(Ok(()))
            }
            Reply::Failed { why, .. } => Some(Err(self.fail(&name, &why))),
            _ => Some(Err(self.fail(&name, "a worker answered something else"))),
        }
    }

    /// How long each stage of the latest opening took (ms), in order.
    pub fn open_stages(&self) -> &[(String, f64)] {
        &self.open_stages
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
