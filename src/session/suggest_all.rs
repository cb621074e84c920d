//! "Suggest all" in the page: every structure of the open case gets the suggestion at
//! one target smoothness with its own filter and bound, then is smoothed with it, one
//! structure per engine worker (the CLI's `case build` does the same on its threads). Progress
//! and cancel; the structure that is the model takes its suggestion as new parameters.

use super::{Background, Session};
use crate::case::{Smoothed, SuggestAllOptions, SuggestAllPlan, SuggestAllSearch};
use crate::metrics::Metrics;
use crate::smooth::Params;
use crate::worker::{metrics_of, Reply, StructureJob};

/// A "Suggest all" under way, or its outcome: its plan ([`SuggestAllPlan`], the CLI's too) and
/// the workers' jobs carrying it out.
#[derive(Clone, Debug, Default)]
pub struct SuggestAll {
    plan: Option<SuggestAllPlan>,
    /// Each structure's job still to answer.
    waiting: Vec<(usize, StructureJob)>,
    /// Per structure, what it got (`None` until it answers).
    outcome: Vec<Option<StructureOutcome>>,
    /// Per structure, its share of the work ([`structure_work`]); 0 for those not asked.
    work: Vec<f64>,
    /// When it started, in the caller's milliseconds (the session keeps no clock).
    started_ms: f64,
    /// How many structures other than the model took their new surface: each a new version of
    /// the case's looks that came from here.
    applied: u64,
}

/// A structure's expected share of the work, in vertices: its vertices plus as many again as a
/// search costs on any structure, however small (a search measures about as many parameter
/// sets on a vessel as on the liver), fitted to the whole-body CT map's searches.
pub fn structure_work(vertices: usize) -> f64 {
    const PER_SEARCH: f64 = 2000.0;
    vertices as f64 + PER_SEARCH
}

/// Seconds still to come, from `elapsed` seconds for `done` of the work (a fraction): the work
/// left at the pace so far. `None` before any work is done.
fn seconds_left(elapsed: f64, done: f64) -> Option<f64> {
    (done > 0.0 && elapsed.is_finite()).then(|| elapsed * (1.0 - done.min(1.0)) / done)
}

/// What one structure got from "Suggest all", under its name.
#[derive(Clone, Debug, PartialEq)]
pub enum StructureOutcome {
    /// Its suggestion: the parameters, how many sets the search measured and the measures of
    /// the structure smoothed with them.
    Suggested {
        name: String,
        params: Params,
        evaluations: usize,
        metrics: Metrics,
    },
    Failed {
        name: String,
        why: String,
    },
}

/// The last "Suggest all" as it stands.
#[derive(Clone, Copy, Debug)]
pub struct SuggestAllReport<'a> {
    pub options: SuggestAllOptions,
    /// Per structure of the case, what it got so far.
    pub structures: &'a [Option<StructureOutcome>],
    pub done: usize,
    pub total: usize,
    pub cancelled: bool,
}

impl Session {
    /// Starts "Suggest all" at `tau` with `search` for the structures `which` of the open case
    /// (indices; `None`: every one), each from its own filter and parameters (bound included).
    /// Replaces one under way. `now_ms` is the caller's clock, which the time left is measured
    /// by.
    pub fn start_suggest_all(
        &mut self,
        tau: f64,
        search: SuggestAllSearch,
        which: Option<&[usize]>,
        now_ms: f64,
    ) -> Result<(), String> {
        let count = self.doc.case.structures.len();
        if let Some(i) = which.into_iter().flatten().find(|&&i| i >= count) {
            return Err(format!(
                "structure {i} does not exist: the case has {count}"
            ));
        }
        if !(0.0..=1.0).contains(&tau) {
            return Err(format!("tau = {tau} is out of range: [0, 1]"));
        }
        self.cancel_suggest_all();
        self.doc.model().ok_or("no mesh is open")?;
        let options = SuggestAllOptions::new(tau, search);
        let plan = SuggestAllPlan::new(&self.doc.case, which, options);
        let mut shares = vec![0.0; count];
        for &i in plan.order() {
            shares[i] = structure_work(self.doc.case.structures[i].original.vertex_count());
        }
        self.suggest_all = SuggestAll {
            plan: Some(plan),
            outcome: vec![None; count],
            work: shares,
            started_ms: now_ms,
            ..SuggestAll::default()
        };
        self.hand_out_structures();
        Ok(())
    }

    /// Gives the workers each structure's part the plan lets start now.
    fn hand_out_structures(&mut self) {
        let Some(plan) = self.suggest_all.plan.as_mut() else {
            return;
        };
        let case = &self.doc.case;
        while let Some(job) = plan.next_job(case) {
            let Some(s) = case.structures.get(job.structure) else {
                plan.finish(job.structure, None);
                continue;
            };
            let (mesh, weights) = (s.original.clone(), s.weights.clone());
            let options = *plan.options();
            let sent = (self.cpu).suggest_structure(mesh, s.params, weights, options, job.starts);
            self.suggest_all.waiting.push((job.structure, sent));
        }
    }

    /// Stops "Suggest all": structures already done keep what they got.
    pub fn cancel_suggest_all(&mut self) {
        let jobs: Vec<StructureJob> = self.suggest_all.waiting.iter().map(|w| w.1).collect();
        let Some(plan) = self.suggest_all.plan.as_mut() else {
            return;
        };
        if !plan.is_over() {
            plan.cancel();
        }
        // The forgotten jobs never answer: they end here, with nothing.
        for (i, _) in self.suggest_all.waiting.drain(..) {
            plan.finish(i, None);
        }
        if !jobs.is_empty() {
            self.cpu.forget_structures(&jobs);
        }
    }

    /// Takes the structures' answers that came and hands out the next; returns whether this
    /// step ended "Suggest all" (its last answer came).
    pub fn step_suggest_all(&mut self) -> bool {
        let Some(tau) = self.suggest_all.plan.as_ref().map(|p| p.options().tau) else {
            return false;
        };
        let mut came = Vec::new();
        let mut waiting = std::mem::take(&mut self.suggest_all.waiting);
        waiting.retain(|&(i, job)| match self.cpu.take_structure_reply(job) {
            Some(reply) => {
                came.push((i, reply));
                false
            }
            None => true,
        });
        self.suggest_all.waiting = waiting;
        let any = !came.is_empty();
        for (i, reply) in came {
            let outcome = self.take_structure_suggestion(i, reply, tau);
            let params = match &outcome {
                StructureOutcome::Suggested { params, .. } => Some(*params),
                StructureOutcome::Failed { .. } => None,
            };
            if let Some(plan) = self.suggest_all.plan.as_mut() {
                plan.finish(i, params);
            }
            if let Some(slot) = self.suggest_all.outcome.get_mut(i) {
                *slot = Some(outcome);
            }
        }
        self.hand_out_structures();
        any && !self.background().suggesting_all()
    }

    /// Applies structure `i`'s answer: the model's structure takes the parameters (its result
    /// follows), another keeps them with its smoothed surface.
    fn take_structure_suggestion(&mut self, i: usize, reply: Reply, tau: f64) -> StructureOutcome {
        let name = self
            .doc
            .case
            .structures
            .get(i)
            .map_or(String::new(), |s| s.name.clone());
        let failed = |why: &str| StructureOutcome::Failed {
            name: name.clone(),
            why: why.to_string(),
        };
        let suggested = match reply {
            Reply::Suggested {
                suggested: Some(s), ..
            } => s,
            Reply::Suggested {
                suggested: None, ..
            } => return failed("nothing to smooth"),
            Reply::Failed { why, .. } => return failed(&why),
            _ => return failed("another reply"),
        };
        let metrics = match metrics_of(&suggested.metrics) {
            Ok(m) => m,
            Err(why) => return failed(&why),
        };
        let summary = StructureOutcome::Suggested {
            name,
            params: suggested.params,
            evaluations: suggested.evaluations,
            metrics: metrics.clone(),
        };
        if self.doc.current_structure() == Some(i) {
            // The engines smooth it again for the view, to the same surface.
            let _ = self.doc.set_params(suggested.params);
            let _ = self.doc.set_tau(tau);
        } else if let Some(s) = self.doc.case.structures.get_mut(i) {
            s.set_params(suggested.params);
            s.set_tau(tau);
            s.keep(Smoothed::new(
                suggested.positions,
                metrics,
                Some(suggested.local_error),
            ));
            self.doc.case_version += 1;
            self.suggest_all.applied += 1;
        }
        summary
    }
}

impl<'a> Background<'a> {
    /// Whether "Suggest all" is under way.
    pub fn suggesting_all(&self) -> bool {
        (self.suggest_all.plan.as_ref()).is_some_and(|p| !p.is_over())
    }

    /// Structures that answered.
    fn suggest_all_answered(&self) -> usize {
        self.suggest_all
            .outcome
            .iter()
            .filter(|o| o.is_some())
            .count()
    }

    /// Structures done and in all, while "Suggest all" is under way.
    pub fn suggest_all_progress(&self) -> Option<(usize, usize)> {
        let s = &self.suggest_all;
        self.suggesting_all().then(|| {
            (
                self.suggest_all_answered(),
                s.plan.as_ref().map_or(0, |p| p.total()),
            )
        })
    }

    /// How many structures besides the model the last "Suggest all" gave a new surface (each a
    /// new case version): a view may show them in groups while it runs.
    pub fn suggest_all_applied(&self) -> u64 {
        self.suggest_all.applied
    }

    /// The fraction of the work of "Suggest all" done, by [`structure_work`], while it is under
    /// way: what a time estimate goes by.
    pub fn suggest_all_work_done(&self) -> Option<f64> {
        let s = self.suggest_all;
        let total: f64 = s.work.iter().sum();
        let done: f64 = (s.work.iter().zip(&s.outcome))
            .filter(|(_, o)| o.is_some())
            .map(|(w, _)| w)
            .sum();
        (self.suggesting_all() && total > 0.0).then(|| done / total)
    }

    /// Seconds left of "Suggest all" at `now_ms` (the clock it was started by): the work left
    /// at the pace so far; `None` before the first structure answers and after the last.
    pub fn suggest_all_seconds_left(&self, now_ms: f64) -> Option<f64> {
        let done = self.suggest_all_work_done()?;
        seconds_left((now_ms - self.suggest_all.started_ms) / 1000.0, done)
    }

    /// The last "Suggest all" since the case opened, as far as it got.
    pub fn suggest_all(&self) -> Option<SuggestAllReport<'a>> {
        let s = self.suggest_all;
        let plan = s.plan.as_ref()?;
        Some(SuggestAllReport {
            options: *plan.options(),
            structures: &s.outcome,
            done: self.suggest_all_answered(),
            total: plan.total(),
            cancelled: plan.cancelled(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_time_left_is_the_work_left_at_the_pace_so_far() {
        assert_eq!(seconds_left(10.0, 0.25), Some(30.0));
        assert_eq!(seconds_left(10.0, 1.0), Some(0.0));
        assert_eq!(seconds_left(10.0, 0.0), None);
        assert_eq!(seconds_left(f64::NAN, 0.5), None);
        // A small structure weighs more than its vertices: its search costs about as much.
        assert!(structure_work(100) / structure_work(200_000) > 100.0 / 200_000.0);
    }
}
