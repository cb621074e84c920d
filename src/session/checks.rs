//! The checks between the open case's structures, as the author asks for them after smoothing:
//! which structure that lay inside another has left it, and which surfaces that did not cross
//! now do. A worker checks the case as it stands (the CLI's `case build` reports the same);
//! the report says whether the case changed since, and the view marks where the warnings are
//! while the surfaces are as checked.

use std::cell::Cell;

use super::{Background, Session};
use crate::worker::{Reply, StructureJob};

/// The checks asked last, and their report once it came.
#[derive(Default)]
pub(super) struct Checks {
    job: Option<StructureJob>,
    /// Each structure's surface as checked (positions; the triangles never change).
    checked: Vec<Vec<[f32; 3]>>,
    /// Whether the structures still show those surfaces, as last found, and for which
    /// parameters' revision, structures' version and model result it was found: selecting,
    /// hiding or recolouring a structure leaves them, smoothing one anew does not.
    same: Cell<Option<(SessionState, bool)>>,
    report: Option<serde_json::Value>,
    /// Per structure, the vertices of its surface as checked that make a warning.
    marks: Vec<Vec<u32>>,
    /// Counts the reports taken, so a view knows its marks are stale.
    reports: u64,
}

/// `(revision, case version, whether the model's result is in)`.
type SessionState = (u64, u64, bool);

impl Session {
    /// Starts checking the case as it stands (replacing checks under way).
    pub fn start_checks(&mut self) -> Result<(), String> {
        let case = self.doc.to_case().ok_or("nothing is open")?;
        let checked = (case.structures.iter())
            .map(|s| s.positions().to_vec())
            .collect();
        let job = self.cpu.check_case(case);
        self.checks = Checks {
            job: Some(job),
            checked,
            same: Cell::new(None),
            report: None,
            marks: Vec::new(),
            reports: self.checks.reports,
        };
        Ok(())
    }

    /// Takes the checks' report if it came; returns whether it did.
    pub fn step_checks(&mut self) -> bool {
        let Some(job) = self.checks.job else {
            return false;
        };
        let Some(reply) = self.cpu.take_structure_reply(job) else {
            return false;
        };
        self.checks.job = None;
        self.checks.reports += 1;
        let report = match reply {
            Reply::Checked { report, marks, .. } => {
                self.checks.marks = marks;
                serde_json::from_str(&report)
                    .unwrap_or_else(|e| serde_json::json!({"error": e.to_string()}))
            }
            Reply::Failed { why, .. } => serde_json::json!({ "error": why }),
            _ => serde_json::json!({ "error": "a worker answered something else" }),
        };
        self.checks.report = Some(report);
        true
    }
}

impl<'a> Background<'a> {
    /// The last checks' report as `case check --json` prints it (see
    /// [`Self::checks_current`]); `None` before any.
    pub fn checks_report(&self) -> Option<&'a serde_json::Value> {
        self.checks.report.as_ref()
    }

    /// Whether checks are under way.
    pub fn checking(&self) -> bool {
        self.checks.job.is_some()
    }

    /// Whether every structure shows the surface the last checks found (as [`CaseDocument::to_case`](super::CaseDocument::to_case)
    /// gives it: the model's current result, or its original while that is computed).
    pub fn checks_current(&self) -> bool {
        if self.checks.report.is_none() {
            return false;
        }
        let state = (
            self.doc.revision,
            self.doc.case_version,
            self.doc.result().is_some(),
        );
        if let Some((when, same)) = self.checks.same.get() {
            if when == state {
                return same;
            }
        }
        let current = self.doc.current_structure();
        let list = &self.doc.case.structures;
        let same = list.len() == self.checks.checked.len()
            && (list.iter().zip(&self.checks.checked).enumerate()).all(|(i, (s, checked))| {
                let shown = match self.doc.result() {
                    Some(r) if Some(i) == current => &r.positions,
                    _ if Some(i) == current => &s.original.positions,
                    _ => s.positions(),
                };
                shown == checked
            });
        self.checks.same.set(Some((state, same)));
        same
    }

    /// Which marks [`Self::marked_surfaces`] gives: changes when a report comes or the case
    /// changes since; `None` when there are none to show.
    pub fn marks_key(&self) -> Option<u64> {
        let any = self.checks.marks.iter().any(|m| !m.is_empty());
        (any && self.checks_current()).then_some(self.checks.reports)
    }

    /// Where the last checks' warnings are: per structure with marks, the patch of its surface
    /// around the vertices that left another or reach too deep into one. Nothing once the case
    /// changed since (the marks would point at surfaces no longer shown).
    pub fn marked_surfaces(&self) -> Vec<crate::mesh::Mesh> {
        if self.marks_key().is_none() {
            return Vec::new();
        }
        let Some(case) = self.doc.to_case() else {
            return Vec::new();
        };
        (case.structures.iter().zip(&self.checks.marks))
            .filter(|(s, marks)| s.visible && !marks.is_empty())
            .map(|(s, marks)| s.surface().patch(marks))
            .collect()
    }

    /// The structures of a warning of the last checks (one that left another, or crosses
    /// another anew), by index.
    pub fn flagged_structures(&self) -> Vec<usize> {
        let flagged = self
            .checks
            .report
            .as_ref()
            .and_then(|r| r["flagged"].as_array());
        (flagged.into_iter().flatten())
            .filter_map(|i| i.as_u64().and_then(|i| usize::try_from(i).ok()))
            .collect()
    }
}
