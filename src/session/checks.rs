//! The checks between the open case's structures, as the author asks for them after smoothing:
//! which structure that lay inside another has left it, and which surfaces that did not cross
//! now do. A worker checks the case as it stands (the CLI's `case build` reports the same);
//! the report says whether the case changed since.

use super::Session;
use crate::worker::{Reply, StructureJob};

/// The checks asked last, and their report once it came.
#[derive(Default)]
pub(super) struct Checks {
    job: Option<StructureJob>,
    /// The parameters' revision and the structures' version the checks were asked for.
    asked: (u64, u64),
    report: Option<serde_json::Value>,
}

impl Session {
    /// Starts checking the case as it stands (replacing checks under way).
    pub fn start_checks(&mut self) -> Result<(), String> {
        let case = self.to_case().ok_or("nothing is open")?;
        let job = self.cpu.check_case(case);
        self.checks = Checks {
            job: Some(job),
            asked: (self.revision, self.case_version),
            report: None,
        };
        Ok(())
    }

    /// Whether checks are under way.
    pub fn checking(&self) -> bool {
        self.checks.job.is_some()
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
        let report = match reply {
            Reply::Checked { report, .. } => serde_json::from_str(&report)
                .unwrap_or_else(|e| serde_json::json!({"error": e.to_string()})),
            Reply::Failed { why, .. } => serde_json::json!({ "error": why }),
            _ => serde_json::json!({ "error": "a worker answered something else" }),
        };
        self.checks.report = Some(report);
        true
    }

    /// The last checks: `{pairs, left_inside, new_crossings, text, flagged, ms, current}`
    /// (`current`: the case is as it was checked), or `{error}`.
    pub fn checks_json(&self) -> Option<serde_json::Value> {
        let mut report = self.checks.report.clone()?;
        report["current"] = (self.checks.asked == (self.revision, self.case_version)).into();
        Some(report)
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
