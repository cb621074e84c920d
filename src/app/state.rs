//! What the app has open: the loaded model and the last error.
//!
//! A file that cannot be read leaves the previous model in place and sets the error message.

use crate::io;
use crate::mesh::{Mesh, MeshReport, Topology};

/// A mesh the app opened, with its connectivity and report.
pub struct LoadedModel {
    pub name: String,
    pub mesh: Mesh,
    pub topology: Topology,
    pub report: MeshReport,
    pub warnings: Vec<String>,
}

impl LoadedModel {
    /// Parses `bytes` (the format chosen by `name`'s extension) and builds topology and report.
    pub fn load(name: &str, bytes: &[u8]) -> Result<Self, io::LoadError> {
        Ok(Self::from_mesh(name, io::load(bytes, name)?))
    }

    pub fn from_mesh(name: &str, mesh: Mesh) -> Self {
        let topology = Topology::build(&mesh);
        let report = MeshReport::new(&mesh, &topology);
        let warnings = report.warnings();
        Self {
            name: name.to_string(),
            mesh,
            topology,
            report,
            warnings,
        }
    }
}

/// The app's document state.
#[derive(Default)]
pub struct AppState {
    pub model: Option<LoadedModel>,
    /// Why the last file could not be opened; cleared by the next successful open.
    pub error: Option<String>,
}

impl AppState {
    /// Opens a file's bytes; on failure keeps the current model and records the error.
    pub fn open(&mut self, name: &str, bytes: &[u8]) {
        match LoadedModel::load(name, bytes) {
            Ok(model) => {
                log::info!(
                    "opened {name}: {} vertices, {} faces",
                    model.report.vertices,
                    model.report.faces
                );
                self.model = Some(model);
                self.error = None;
            }
            Err(e) => self.fail(name, &e.to_string()),
        }
    }

    /// Records that `name` could not be opened (or read) because of `reason`.
    pub fn fail(&mut self, name: &str, reason: &str) {
        log::warn!("cannot open {name}: {reason}");
        self.error = Some(format!("Cannot open {name}: {reason}"));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    wasm_bindgen_test::wasm_bindgen_test_configure!(run_in_browser);

    #[wasm_bindgen_test]
    fn a_bad_file_keeps_the_previous_model_and_reports_why() {
        let mut state = AppState {
            model: Some(LoadedModel::from_mesh(
                "tet.ply",
                crate::mesh::fixtures::tetrahedron(),
            )),
            error: None,
        };
        state.open("notes.txt", b"not a mesh");
        assert_eq!(
            state.model.as_ref().map(|m| m.name.as_str()),
            Some("tet.ply")
        );
        let error = state.error.as_deref().unwrap_or_default();
        assert!(error.starts_with("Cannot open notes.txt: "), "{error}");
        assert!(error.contains(".stl .obj .ply"), "{error}");

        state.open("empty.stl", b"");
        assert_eq!(state.model.as_ref().map(|m| m.report.faces), Some(4));
        assert!(state.error.as_deref().unwrap_or_default().contains("empty"));
    }

    #[wasm_bindgen_test]
    fn the_bundled_sample_opens_as_a_closed_tube() {
        let mut state = AppState::default();
        state.open(crate::app::SAMPLE_NAME, crate::app::SAMPLE_BYTES);
        assert_eq!(state.error, None);
        let model = state.model.expect("the sample loads");
        assert_eq!((model.report.vertices, model.report.faces), (2296, 4588));
        assert!(model.report.closed);
        assert_eq!(model.report.genus, Some(0));
        assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    }
}
