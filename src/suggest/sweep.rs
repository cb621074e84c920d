//! Model quality graphs (paper section 5.2): for each parameter of the active filter, K/K0, E,
//! |V-V0|/V0 and S over its range with the other parameters at their current values. The sweep
//! over iterations is one run measured after every iteration (windowed sinc: one run per count,
//! since its k-iteration result is not a prefix of a longer run).

use super::space::{Param, ParamSpace};
use super::{is_cumulative, Evaluator, Progress, Request, Task, Terms};
use crate::smooth::{ParamError, Params};
use serde::{Deserialize, Serialize};

/// One measured sample of a curve (equal as [`Terms`] are: NaN equal to NaN).
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct Sample {
    pub value: f64,
    pub terms: Terms,
    /// S(tau) at the sweep's tau.
    pub score: f64,
}

impl PartialEq for Sample {
    fn eq(&self, other: &Self) -> bool {
        self.value == other.value
            && self.terms == other.terms
            && super::same(self.score, other.score)
    }
}

/// One parameter's graph.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Curve {
    pub param: Param,
    /// The parameter's current value (the dashed line).
    pub current: f64,
    /// Ascending by value; only values valid with the others held (Taubin: mu < -lambda).
    pub samples: Vec<Sample>,
    /// Index of the lowest [`Terms::rank`] (the lowest S among the samples that do not roughen
    /// the mesh; ties: the weaker smoothing): this parameter's suggestion given the others.
    /// `None` for an empty curve.
    pub best: Option<usize>,
}

impl Curve {
    /// The curve of `value` as runs of `[parameter value, value]` points: it breaks off at each
    /// sample without a finite value (not measured, or where the filter diverges).
    pub fn runs(&self, value: impl Fn(&Sample) -> Option<f64>) -> Vec<Vec<[f64; 2]>> {
        let mut runs: Vec<Vec<[f64; 2]>> = vec![Vec::new()];
        for s in &self.samples {
            match value(s).filter(|v| v.is_finite()) {
                Some(v) => runs.last_mut().expect("never empty").push([s.value, v]),
                None if runs.last().is_some_and(|r| !r.is_empty()) => runs.push(Vec::new()),
                None => {}
            }
        }
        runs.retain(|r| !r.is_empty());
        runs
    }

    /// The suggested value of this parameter with the others held.
    pub fn suggestion(&self) -> Option<f64> {
        self.best.map(|i| self.samples[i].value)
    }

    fn rescore(&mut self, tau: f64, larger_is_stronger: bool) {
        for s in &mut self.samples {
            s.score = s.terms.score(tau);
        }
        let n = self.samples.len();
        // Weaker first, so the first of equal scores is the weaker smoothing.
        let order: Vec<usize> = if larger_is_stronger {
            (0..n).collect()
        } else {
            (0..n).rev().collect()
        };
        let rank = |i: usize| self.samples[i].terms.rank(tau);
        self.best = order
            .into_iter()
            .reduce(|a, b| if rank(b) < rank(a) { b } else { a });
    }
}

/// The quality graphs of one filter at one parameter set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct QualityGraphs {
    /// The current parameters the curves vary around.
    pub current: Params,
    pub tau: f64,
    pub curves: Vec<Curve>,
}

impl QualityGraphs {
    /// What `sweep --json` prints and the web API's `sweep()` resolves with; `seconds` is how
    /// long the sweep took.
    pub fn to_json(&self, seconds: f64) -> serde_json::Value {
        serde_json::json!({
            "filter": self.current.filter,
            "tau": self.tau,
            "current": self.current.to_json(),
            "curves": self.curves,
            "seconds": seconds,
        })
    }

    /// Recomputes S and each curve's minimum for another tau (no smoothing needed).
    pub fn rescored(mut self, tau: f64) -> Self {
        let space = ParamSpace::of(self.current.filter);
        for (curve, axis) in self.curves.iter_mut().zip(&space.axes) {
            curve.rescore(tau, axis.larger_is_stronger);
        }
        self.tau = tau;
        self
    }
}

/// One smoothing run of the sweep: parameters and the samples it fills.
struct Job {
    curve: usize,
    params: Params,
    /// (sample index, iteration count) pairs, ascending.
    at: Vec<(usize, u32)>,
}

impl Job {
    /// Iterations the run smooths, and so about how long it takes.
    fn run_length(&self) -> u32 {
        self.at.last().map_or(0, |&(_, k)| k)
    }
}

/// Computes the quality graphs one smoothing run per [`Task::step`].
pub struct QualitySweep {
    graphs: QualityGraphs,
    jobs: Vec<Job>,
    next: usize,
    done: usize,
    total: usize,
}

impl QualitySweep {
    /// `current` must be valid; it also carries the displacement bound passed to every run.
    pub fn new(current: &Params, tau: f64) -> Result<Self, ParamError> {
        current.validate()?;
        let space = ParamSpace::of(current.filter);
        let mut jobs = Vec::new();
        let mut curves = Vec::new();
        for (c, axis) in space.axes.iter().enumerate() {
            let mut values = Vec::new();
            for &v in &axis.sweep {
                let mut p = *current;
                axis.param.set(&mut p, v);
                if p.validate().is_ok() {
                    values.push((v, p));
                }
            }
            if axis.param == Param::Iterations && is_cumulative(current.filter) {
                if let Some(&(_, p)) = values.first() {
                    let at = values
                        .iter()
                        .enumerate()
                        .map(|(i, (_, q))| (i, q.iterations))
                        .collect();
                    jobs.push(Job {
                        curve: c,
                        params: p,
                        at,
                    });
                }
            } else {
                jobs.extend(values.iter().enumerate().map(|(i, &(_, p))| Job {
                    curve: c,
                    params: p,
                    at: vec![(i, p.iterations)],
                }));
            }
            curves.push(Curve {
                param: axis.param,
                current: axis.param.get(current),
                samples: values
                    .iter()
                    .map(|&(value, _)| Sample {
                        value,
                        terms: Terms {
                            curvature_ratio: f64::NAN,
                            mean_error: f64::NAN,
                            volume_change: None,
                            roughness_ratio: f64::NAN,
                        },
                        score: f64::NAN,
                    })
                    .collect(),
                best: None,
            });
        }
        // Longest runs first: handed out last, the iteration curve's one long run would keep a
        // worker busy while the others have nothing left to do.
        jobs.sort_by_key(|job| std::cmp::Reverse(job.run_length()));
        let total = curves.iter().map(|c| c.samples.len()).sum();
        Ok(Self {
            graphs: QualityGraphs {
                current: *current,
                tau,
                curves,
            },
            jobs,
            next: 0,
            done: 0,
            total,
        })
    }
}

impl Task for QualitySweep {
    type Output = QualityGraphs;

    fn step(&mut self, evaluator: &mut dyn Evaluator) -> bool {
        if evaluator.wants_prefetch() {
            let later: Vec<Request> = self
                .jobs
                .iter()
                .skip(self.next + 1)
                .map(|job| (job.params, job.at.iter().map(|&(_, k)| k).collect()))
                .collect();
            evaluator.prefetch(&later);
        }
        if let Some(job) = self.jobs.get(self.next) {
            let counts: Vec<u32> = job.at.iter().map(|&(_, k)| k).collect();
            let Some(terms) = evaluator.measure(&job.params, &counts) else {
                return false;
            };
            let curve = &mut self.graphs.curves[job.curve];
            for (&(i, _), t) in job.at.iter().zip(terms) {
                curve.samples[i].terms = t;
                self.done += 1;
            }
            self.next += 1;
        }
        self.next >= self.jobs.len()
    }

    fn progress(&self) -> Progress {
        Progress {
            done: self.done,
            total: self.total,
        }
    }

    fn into_output(self) -> Option<QualityGraphs> {
        (self.next >= self.jobs.len()).then(|| {
            let tau = self.graphs.tau;
            self.graphs.rescored(tau)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::synthetic::{smoothing_model, FnEvaluator, Slow};
    use super::*;
    use crate::smooth::Filter;
    use crate::suggest::run;

    fn sweep(p: &Params, tau: f64, ev: &mut dyn Evaluator) -> QualityGraphs {
        run(QualitySweep::new(p, tau).unwrap(), ev, &mut |_| true).unwrap()
    }

    #[test]
    fn an_evaluator_that_answers_later_gets_the_same_graphs() {
        for filter in Filter::ALL {
            let p = Params::defaults(filter);
            let now = sweep(&p, 0.5, &mut FnEvaluator::new(smoothing_model(filter)));
            let mut slow = Slow::new(FnEvaluator::new(smoothing_model(filter)), 3);
            assert_eq!(sweep(&p, 0.5, &mut slow), now, "{filter:?}");
        }
    }

    #[test]
    fn the_longest_runs_are_handed_out_first() {
        for filter in Filter::ALL {
            let task = QualitySweep::new(&Params::defaults(filter), 0.5).unwrap();
            let lengths: Vec<u32> = task.jobs.iter().map(Job::run_length).collect();
            assert!(
                lengths.is_sorted_by(|a, b| a >= b),
                "{filter:?}: {lengths:?}"
            );
            let longest = match filter {
                Filter::Sinc => 100,
                _ => crate::suggest::space::MAX_ITERATIONS,
            };
            assert_eq!(lengths[0], longest, "{filter:?}");
        }
    }

    #[test]
    fn one_curve_per_parameter_with_the_specified_samples() {
        let p = Params::defaults(Filter::Hc);
        let mut ev = FnEvaluator::new(smoothing_model(Filter::Hc));
        let g = sweep(&p, 0.5, &mut ev);
        let names: Vec<_> = g.curves.iter().map(|c| c.param).collect();
        assert_eq!(names, [Param::Alpha, Param::Beta, Param::Iterations]);
        assert_eq!(g.curves[0].samples.len(), 21);
        assert_eq!(g.curves[0].samples[1].value, 0.05);
        assert_eq!(g.curves[2].samples.len(), 51);
        assert_eq!(g.curves[0].current, 0.1);
        // 21 + 21 weight runs, one cumulative run for the 51 iteration samples.
        assert_eq!(ev.runs, 43);
        for c in &g.curves {
            for s in &c.samples {
                assert!(s.terms.curvature_ratio.is_finite());
                assert_eq!(s.score, s.terms.score(0.5));
            }
        }
    }

    #[test]
    fn a_curve_breaks_off_where_a_sample_has_no_value() {
        let sample = |value: f64, ratio: f64| Sample {
            value,
            terms: Terms {
                roughness_ratio: ratio,
                ..Terms::UNCHANGED
            },
            score: 0.0,
        };
        let roughened = |value: f64| Sample {
            value,
            terms: Terms::roughened(2.0),
            score: f64::NAN,
        };
        let curve = Curve {
            param: Param::Lambda,
            current: 0.5,
            samples: vec![
                roughened(0.0),
                sample(0.1, 0.5),
                sample(0.2, 0.4),
                roughened(0.3),
                sample(0.4, 0.3),
            ],
            best: None,
        };
        let runs = curve.runs(|s| Some(s.terms.curvature_ratio));
        assert_eq!(runs, vec![vec![[0.1, 1.0], [0.2, 1.0]], vec![[0.4, 1.0]]]);
    }

    #[test]
    fn the_minimum_of_each_curve_is_its_suggestion() {
        let p = Params::defaults(Filter::Laplace);
        let mut ev = FnEvaluator::new(|q: &Params| Terms {
            curvature_ratio: 1.0
                + (q.lambda as f64 - 0.35).powi(2)
                + ((q.iterations as f64) - 17.0).powi(2) / 100.0,
            mean_error: 0.0,
            volume_change: Some(0.0),
            roughness_ratio: 0.5,
        });
        let g = sweep(&p, 0.5, &mut ev);
        assert_eq!(g.curves[0].suggestion(), Some(0.35));
        assert_eq!(g.curves[1].suggestion(), Some(17.0));
        assert_eq!(g.curves[1].current, 10.0);
        // At tau = 0 every sample ties at S = 0; the weaker smoothing wins.
        let g0 = g.rescored(0.0);
        assert_eq!(g0.curves[0].suggestion(), Some(0.0));
        assert_eq!(g0.curves[1].suggestion(), Some(0.0));
    }

    #[test]
    fn taubin_curves_keep_mu_below_minus_lambda() {
        let p = Params::defaults(Filter::Taubin); // lambda 0.5, mu -0.53
        let g = sweep(
            &p,
            0.5,
            &mut FnEvaluator::new(smoothing_model(Filter::Taubin)),
        );
        let lambdas: Vec<f64> = g.curves[0].samples.iter().map(|s| s.value).collect();
        assert_eq!(lambdas.first(), Some(&0.05));
        assert_eq!(lambdas.last(), Some(&0.5));
        let mus: Vec<f64> = g.curves[1].samples.iter().map(|s| s.value).collect();
        assert_eq!(mus.first(), Some(&-1.0));
        assert_eq!(mus.last(), Some(&-0.55));
    }

    #[test]
    fn sinc_restarts_for_every_iteration_count() {
        let p = Params::defaults(Filter::Sinc);
        let mut ev = FnEvaluator::new(smoothing_model(Filter::Sinc));
        let g = sweep(&p, 0.5, &mut ev);
        assert_eq!(g.curves[0].samples.len(), 10);
        assert_eq!(g.curves[1].samples.len(), 100);
        assert_eq!(ev.runs, 110);
        assert_eq!(ev.iterations_run, 10 * 20 + (1..=100).sum::<u64>());
    }

    #[test]
    fn progress_counts_samples_and_cancel_stops() {
        let p = Params::defaults(Filter::Laplace);
        let mut ev = FnEvaluator::new(smoothing_model(Filter::Laplace));
        let mut seen = Vec::new();
        sweep_with(&p, &mut ev, &mut |pr| {
            seen.push(pr);
            true
        });
        assert_eq!(seen.last().map(|p| (p.done, p.total)), Some((72, 72)));
        let mut ev = FnEvaluator::new(smoothing_model(Filter::Laplace));
        // The iteration curve's one run fills its 51 samples first, then a run per sample.
        let r = run(QualitySweep::new(&p, 0.5).unwrap(), &mut ev, &mut |pr| {
            pr.done < 51 + 4
        });
        assert!(r.is_err());
        assert_eq!(ev.runs, 5);
        assert!(QualitySweep::new(&Params { lambda: 2.0, ..p }, 0.5).is_err());
    }

    fn sweep_with(
        p: &Params,
        ev: &mut dyn Evaluator,
        f: &mut dyn FnMut(Progress) -> bool,
    ) -> QualityGraphs {
        run(QualitySweep::new(p, 0.5).unwrap(), ev, f).unwrap()
    }
}
