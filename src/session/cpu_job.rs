//! The CPU engine's run for the current parameters, spread over calls so a page without threads
//! keeps drawing frames: the smoothing a few iterations at a time, then the measure pass a run
//! of vertices at a time, each call within a time budget.

use super::{Model, Smoothed, Timings};
use crate::metrics::{DriftState, DriftingReference, MeasureInParts, SincDrifting};
use crate::smooth::{Filter, Params, RunInParts};

/// How far a run got (see [`super::Session::progress`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CpuProgress {
    /// Iterations done of the run's iterations.
    Smoothing { done: u32, total: u32 },
    /// Parts of the measure pass done of all parts (runs of vertices).
    Measuring { done: usize, total: usize },
}

impl CpuProgress {
    /// Done as a fraction of the whole run, counting the measure pass as one iteration more
    /// (about what it costs).
    pub fn fraction(&self) -> f32 {
        match *self {
            CpuProgress::Smoothing { done, total } => done as f32 / (total + 1) as f32,
            CpuProgress::Measuring { done, total } => {
                let iterations_share = 1.0 - 1.0 / (total.max(1) as f32 + 1.0);
                iterations_share.max(done as f32 / total.max(1) as f32)
            }
        }
    }

    /// What the progress bar says.
    pub fn describe(&self) -> String {
        match *self {
            CpuProgress::Smoothing { done, total } => format!("smoothing {done}/{total}"),
            CpuProgress::Measuring { .. } => "measuring".to_string(),
        }
    }
}

/// A CPU run in progress, kept between calls.
pub(super) struct CpuJob {
    pub revision: u64,
    /// The result once the smoothing is done (the original positions until then).
    positions: Vec<[f32; 3]>,
    /// Laplace, Taubin or HC under way, its buffers kept between calls.
    run: Option<RunInParts>,
    drift: DriftState,
    done: u32,
    smooth_ms: f64,
    /// Windowed sinc under way (its terms are not shorter runs' results, so it cannot be
    /// resumed like the others).
    sinc: Option<SincDrifting>,
    /// The measure pass, once the smoothing is done.
    measure: Option<MeasureInParts>,
    measure_ms: f64,
}

/// The CPU engine's milliseconds per iteration on the open model, with the filter that took
/// them: a call sizes its first piece of iterations by it, rather than starting with one. The
/// session keeps it across runs, and forgets it with the model.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Pace(Option<(Filter, f64)>);

impl Pace {
    /// The iterations of `filter` that fit in `ms_left` (at least one; one when unknown).
    fn iterations_in(&self, filter: Filter, ms_left: f64) -> usize {
        match self.0 {
            Some((f, ms)) if f == filter && ms > 0.0 => (ms_left / ms).max(1.0) as usize,
            _ => 1,
        }
    }
}

/// Vertices of the first part of a measure pass, before its speed is known.
const FIRST_MEASURE_PART: usize = MeasureInParts::SMALLEST_PART;

impl CpuJob {
    pub fn new(revision: u64, model: &Model) -> Self {
        Self {
            revision,
            positions: model.mesh().positions.clone(),
            run: None,
            drift: DriftState::start(&model.original),
            done: 0,
            smooth_ms: 0.0,
            sinc: None,
            measure: None,
            measure_ms: 0.0,
        }
    }

    pub fn progress(&self, params: &Params) -> CpuProgress {
        match &self.measure {
            Some(m) => {
                let (done, total) = m.progress();
                CpuProgress::Measuring { done, total }
            }
            None => CpuProgress::Smoothing {
                done: match &self.sinc {
                    // Its passes and drift steps, as a share of the iterations.
                    Some(sinc) => {
                        let (done, pieces) = sinc.progress();
                        (u64::from(done) * u64::from(params.iterations) / u64::from(pieces.max(1)))
                            as u32
                    }
                    None => self.done,
                },
                total: params.iterations,
            },
        }
    }

    /// Works for about `budget_ms` (at least one iteration, or one part of the measure pass);
    /// the result and its timings once the run is measured (the job is spent then).
    pub fn step(
        &mut self,
        model: &Model,
        (params, weights, tau): (&Params, Option<&[f32]>, f64),
        clock: &dyn Fn() -> f64,
        budget_ms: f64,
        pace: &mut Pace,
    ) -> Option<(Smoothed, Timings)> {
        let start = clock();
        if self.done < params.iterations {
            self.smooth(model, params, weights, (clock, start + budget_ms), pace);
            self.smooth_ms += clock() - start;
            if self.done < params.iterations || clock() - start >= budget_ms {
                return None;
            }
        }
        let measure_start = clock();
        let finished = self.measure(model, clock, start + budget_ms);
        self.measure_ms += clock() - measure_start;
        if !finished {
            return None;
        }
        let measure = self.measure.take()?;
        let (metrics, vertex) = measure.finish(&model.original, tau);
        let timings = Timings {
            smooth_ms: self.smooth_ms,
            measure_ms: self.measure_ms,
        };
        let smoothed = Smoothed {
            revision: self.revision,
            params: *params,
            positions: std::mem::take(&mut self.positions),
            metrics,
            vertex,
        };
        Some((smoothed, timings))
    }

    /// Iterations until `deadline` (at least one).
    fn smooth(
        &mut self,
        model: &Model,
        params: &Params,
        weights: Option<&[f32]>,
        (clock, deadline): (&dyn Fn() -> f64, f64),
        pace: &mut Pace,
    ) {
        if params.filter == Filter::Sinc {
            self.smooth_sinc(model, params, weights, clock, deadline);
            return;
        }
        let Some(mut run) = self
            .run
            .take()
            .or_else(|| RunInParts::new(model.mesh(), params))
        else {
            return;
        };
        let first = pace.iterations_in(params.filter, deadline - clock());
        let finished = in_pieces(clock, deadline, first, |n| {
            let start = clock();
            let before = run.done();
            let mut drift =
                DriftingReference::resume(&model.original, std::mem::take(&mut self.drift));
            let more = n.try_into().unwrap_or(u32::MAX);
            let finished = run.advance(model.mesh(), model.topology(), weights, more, &mut drift);
            self.drift = drift.into_state();
            let chunk = run.done() - before;
            *pace = Pace(Some((
                params.filter,
                (clock() - start) / f64::from(chunk.max(1)),
            )));
            finished
        });
        self.done = run.done();
        if finished {
            self.positions = run.into_positions();
        } else {
            self.run = Some(run);
        }
    }

    /// Windowed sinc until `deadline`: its neighbour passes, then the drift's steps (at least
    /// one piece).
    fn smooth_sinc(
        &mut self,
        model: &Model,
        params: &Params,
        weights: Option<&[f32]>,
        clock: &dyn Fn() -> f64,
        deadline: f64,
    ) {
        let original = &model.original;
        let Some(mut sinc) = self
            .sinc
            .take()
            .or_else(|| SincDrifting::new(original, params))
        else {
            return;
        };
        let finished = in_pieces(clock, deadline, 1, |n| {
            sinc.advance(original, params, weights, n.try_into().unwrap_or(u32::MAX))
        });
        if finished {
            (self.positions, self.drift) = sinc.into_result();
            self.done = params.iterations;
        } else {
            self.sinc = Some(sinc);
        }
    }

    /// Parts of the measure pass until `deadline` (at least one); whether it is complete.
    fn measure(&mut self, model: &Model, clock: &dyn Fn() -> f64, deadline: f64) -> bool {
        let original = &model.original;
        let (positions, reference) = (&self.positions, self.drift.reference());
        let pass = self
            .measure
            .get_or_insert_with(|| MeasureInParts::new(original, positions, reference));
        in_pieces(clock, deadline, FIRST_MEASURE_PART, |vertices| {
            pass.advance(original, positions, reference, vertices)
        })
    }
}

/// Runs `work(n)` (`n` pieces of work; whether everything is done) until everything is done
/// or `deadline` has passed, at least once: `first` pieces, then as many as the time per piece
/// so far lets fit. Returns whether everything is done.
fn in_pieces(
    clock: &dyn Fn() -> f64,
    deadline: f64,
    first: usize,
    mut work: impl FnMut(usize) -> bool,
) -> bool {
    let mut n = first.max(1);
    loop {
        let start = clock();
        if work(n) {
            return true;
        }
        let now = clock();
        if now >= deadline {
            return false;
        }
        let per_piece = ((now - start) / n as f64).max(1e-9);
        n = ((deadline - now) / per_piece).max(1.0) as usize;
    }
}
