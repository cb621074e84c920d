//! Writing the case glTF in the page: one structure per step, so the view stays interactive
//! while a case of a hundred structures is simplified and compressed, and the author sees the
//! file's size and triangles before saving it. The file is kept while the case stays as it
//! was written; any change to a structure, the case's text or the options makes it stale.

use std::borrow::Cow;
use std::hash::{Hash, Hasher};

use super::{CaseDocument, Session};
use crate::case::CaseStructure;
use crate::export::{CaseGltfOptions, CaseWriter};

/// The case glTF being written, or written.
#[derive(Default)]
pub(super) struct CaseExport {
    writing: Option<Writing>,
    written: Option<WrittenCase>,
    error: Option<String>,
}

struct Writing {
    writer: CaseWriter,
    options: CaseGltfOptions,
    state: u64,
}

/// A case glTF written from the case as it stands.
pub struct WrittenCase {
    pub bytes: Vec<u8>,
    pub triangles: usize,
    pub options: CaseGltfOptions,
    state: u64,
}

/// How far writing the case glTF has come.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExportProgress {
    pub structures_done: usize,
    pub structures: usize,
    /// The binary buffer's bytes so far.
    pub bytes: usize,
    pub triangles: usize,
}

/// What the case is now, as far as its file goes: each structure's settings and whether its
/// result is in, the looks' version and the case's text.
fn case_state(doc: &CaseDocument) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    doc.case_version.hash(&mut h);
    doc.case.title.hash(&mut h);
    doc.case.description.hash(&mut h);
    for s in &doc.case.structures {
        (s.revision, s.smoothed_now().is_some()).hash(&mut h);
    }
    h.finish()
}

/// The structure as the file holds it: a result for settings since changed is not written.
fn as_written(s: &CaseStructure) -> Cow<'_, CaseStructure> {
    if s.smoothed.is_some() && s.smoothed_now().is_none() {
        let mut s = s.clone();
        s.smoothed = None;
        Cow::Owned(s)
    } else {
        Cow::Borrowed(s)
    }
}

impl Session {
    /// The case glTF being written or written, read.
    pub fn case_export(&self) -> CaseExportOf<'_> {
        CaseExportOf {
            export: &self.case_export,
            doc: &self.doc,
        }
    }

    /// The case glTF being written or written, to start, step or stop.
    pub fn case_export_mut(&mut self) -> CaseExportMut<'_> {
        CaseExportMut {
            export: &mut self.case_export,
            doc: &self.doc,
        }
    }
}

/// Writing the open case's glTF, as it is read: [`Session::case_export`].
pub struct CaseExportOf<'a> {
    export: &'a CaseExport,
    doc: &'a CaseDocument,
}

/// Writing the open case's glTF, as it is done: [`Session::case_export_mut`].
pub struct CaseExportMut<'a> {
    export: &'a mut CaseExport,
    doc: &'a CaseDocument,
}

impl CaseExportMut<'_> {
    /// Starts writing the case glTF with `options` (replacing one under way or written).
    pub fn start(&mut self, options: CaseGltfOptions) -> Result<(), String> {
        self.doc.current_structure().ok_or("nothing is open")?;
        let writer = CaseWriter::new(&self.doc.case, &options).map_err(|e| e.to_string())?;
        *self.export = CaseExport {
            writing: Some(Writing {
                writer,
                options,
                state: case_state(self.doc),
            }),
            written: None,
            error: None,
        };
        Ok(())
    }

    /// Stops writing the case glTF.
    pub fn cancel(&mut self) {
        self.export.writing = None;
    }

    /// Writes the next structure; returns whether anything was done. A case changed while
    /// it is written is written again from the start.
    pub fn step(&mut self) -> bool {
        let Some(writing) = &mut self.export.writing else {
            return false;
        };
        let state = case_state(self.doc);
        if state != writing.state {
            let options = writing.options;
            if let Err(e) = self.start(options) {
                self.export.error = Some(e);
            }
            return true;
        }
        let next = writing.writer.structures();
        let outcome = match self.doc.case.structures.get(next) {
            Some(s) => writing.writer.add(&as_written(s)).map(|()| None),
            None => {
                let Some(w) = self.export.writing.take() else {
                    return false;
                };
                let triangles = w.writer.triangles();
                w.writer.finish(&self.doc.case).map(|bytes| {
                    Some(WrittenCase {
                        bytes,
                        triangles,
                        options: w.options,
                        state,
                    })
                })
            }
        };
        match outcome {
            Ok(Some(written)) => self.export.written = Some(written),
            Ok(None) => {}
            Err(e) => {
                self.export.writing = None;
                self.export.error = Some(e.to_string());
            }
        }
        true
    }
}

impl<'a> CaseExportOf<'a> {
    /// How far the case glTF being written has come.
    pub fn progress(&self) -> Option<ExportProgress> {
        let w = &self.export.writing.as_ref()?.writer;
        Some(ExportProgress {
            structures_done: w.structures(),
            structures: self.doc.case.structures.len(),
            bytes: w.buffer_bytes(),
            triangles: w.triangles(),
        })
    }

    /// The case glTF written last, while the case is as it was written.
    pub fn written(&self) -> Option<&'a WrittenCase> {
        (self.export.written.as_ref()).filter(|w| w.state == case_state(self.doc))
    }

    /// Why the case glTF could not be written, the last time.
    pub fn error(&self) -> Option<&'a str> {
        self.export.error.as_deref()
    }
}
