//! An evaluator that spreads each smoothing run over several calls, each within a time budget,
//! so the web app (one thread on wasm32) can compute quality graphs and suggestions between
//! frames. Its results are those of [`MeshEvaluator`], bit for bit: the run is the same
//! iterations resumed in chunks ([`crate::smooth::resume`]; windowed sinc a few neighbour passes
//! and drift steps at a time, [`SincDrifting`]), measured at the same counts, each measure pass
//! a run of vertices at a time ([`MeasureInParts`]).

use super::mesh_evaluator::{terms_of, MeshEvaluator, WeightsError};
use super::{is_cumulative, Evaluator, Terms};
use crate::metrics::{DriftState, DriftingReference, MeasureInParts, Original, SincDrifting};
use crate::smooth::{Params, RunInParts};

/// A run under way between calls.
struct Partial {
    params: Params,
    at: Vec<u32>,
    /// The positions reached, without a `run`: the original's until a windowed sinc run ends.
    positions: Vec<[f32; 3]>,
    /// Laplace, Taubin or HC under way, its buffers kept between calls; its positions are the
    /// ones reached.
    run: Option<RunInParts>,
    drift: DriftState,
    done: u32,
    terms: Vec<Terms>,
    /// Windowed sinc's run towards the next count, under way.
    sinc: Option<SincDrifting>,
    /// The measure pass at the count reached, under way, and R/R0 there (taken first: a count
    /// that roughens the mesh needs no measure pass).
    measuring: Option<(MeasureInParts, f64)>,
}

/// The positions a partial run reached: its `run`'s (laid out from the run's buffers) when it
/// has one, else its `positions`.
fn reached<'a>(run: &'a mut Option<RunInParts>, positions: &'a [[f32; 3]]) -> &'a [[f32; 3]] {
    match run.as_mut() {
        Some(run) => run.positions(),
        None => positions,
    }
}

/// Vertices of the first part of a measure pass, before its speed is known; also the smallest.
const FIRST_MEASURE_PART: usize = MeasureInParts::SMALLEST_PART;

/// The triangle areas that begin a measure pass cost about this share of the whole pass.
const AREAS_SHARE: f64 = 0.2;

/// What a sliced evaluation keeps between calls: the run under way and how long work took so
/// far (to size the next chunk). Belongs to one model: [`SlicedRuns::reset`] when it changes.
#[derive(Default)]
pub struct SlicedRuns {
    partial: Option<Partial>,
    /// Milliseconds per smoothing iteration and per vertex of a measure pass, as last seen.
    iteration_ms: Option<f64>,
    vertex_ms: Option<f64>,
    /// Smoothing runs finished.
    pub runs: usize,
}

impl SlicedRuns {
    /// Forgets the run under way and the timings (another model, other weights).
    pub fn reset(&mut self) {
        *self = Self::default();
    }
}

/// One call's view of a sliced evaluation: the model, the state kept between calls, a clock
/// (milliseconds) and the moment this call must stop starting new work.
pub struct Sliced<'a> {
    evaluator: MeshEvaluator<'a>,
    original: &'a Original,
    weights: Option<&'a [f32]>,
    runs: &'a mut SlicedRuns,
    clock: &'a dyn Fn() -> f64,
    deadline: f64,
    /// Whether this call has done any work yet: the first piece always runs, so every call
    /// makes progress however small the budget.
    worked: bool,
}

impl<'a> Sliced<'a> {
    /// Work started by this evaluator ends near `clock() + budget_ms`: a piece of work is
    /// started only when its estimated time fits (or nothing was done yet in this call). One
    /// part of a measure pass is the smallest piece.
    pub fn new(
        original: &'a Original,
        weights: Option<&'a [f32]>,
        runs: &'a mut SlicedRuns,
        clock: &'a dyn Fn() -> f64,
        budget_ms: f64,
    ) -> Result<Self, WeightsError> {
        let deadline = clock() + budget_ms;
        Ok(Self {
            evaluator: MeshEvaluator::new(original, weights)?,
            original,
            weights,
            runs,
            clock,
            deadline,
            worked: false,
        })
    }

    /// Whether a piece estimated to take `estimate_ms` may start now.
    fn fits(&self, estimate_ms: Option<f64>) -> bool {
        if !self.worked {
            return true;
        }
        let now = (self.clock)();
        now + estimate_ms.unwrap_or(0.0) <= self.deadline
    }

    fn start(&self, params: &Params, at: &[u32]) -> Partial {
        // The run goes as far as the last count (or the parameters' own for `smoothed`).
        let mut run_params = *params;
        run_params.iterations = at.last().copied().unwrap_or(params.iterations);
        let mesh = self.original.mesh();
        let run = is_cumulative(params.filter)
            .then(|| RunInParts::new(mesh, &run_params))
            .flatten();
        Partial {
            params: *params,
            at: at.to_vec(),
            // A run holds its own positions.
            positions: match run {
                Some(_) => Vec::new(),
                None => mesh.positions.clone(),
            },
            run,
            drift: DriftState::start(self.original),
            done: 0,
            terms: Vec::with_capacity(at.len()),
            sinc: None,
            measuring: None,
        }
    }

    /// Measures `partial`'s positions, a part at a time while the parts fit the budget: the
    /// triangle areas, then runs of vertices sized by the speed seen so far. The terms once the
    /// pass is complete, `None` when the budget ran out first.
    fn measure_parts(&mut self, partial: &mut Partial) -> Option<Terms> {
        if partial.done == 0 {
            return Some(self.evaluator.unchanged());
        }
        let original = self.original;
        let n = original.mesh().vertex_count();
        loop {
            let Some((pass, roughness)) = partial.measuring.as_mut() else {
                let areas = self.runs.vertex_ms.map(|ms| ms * n as f64 * AREAS_SHARE);
                if !self.fits(areas) {
                    return None;
                }
                let roughness =
                    original.roughness_ratio(reached(&mut partial.run, &partial.positions));
                if roughness > 1.0 {
                    self.worked = true;
                    return Some(Terms::roughened(roughness));
                }
                let positions = reached(&mut partial.run, &partial.positions);
                let pass = MeasureInParts::new(original, positions, partial.drift.reference());
                partial.measuring = Some((pass, roughness));
                self.worked = true;
                continue;
            };
            let now = (self.clock)();
            let vertices = match self.runs.vertex_ms {
                Some(ms) if ms > 0.0 => ((self.deadline - now) / ms).max(0.0) as usize,
                // Work of unknown length comes first in a call or not at all.
                _ if self.worked => 0,
                _ => FIRST_MEASURE_PART,
            };
            // A part is whole chunks of vertices: less than one does not fit.
            if self.worked && vertices < FIRST_MEASURE_PART {
                return None;
            }
            let before = pass.measured();
            let positions = reached(&mut partial.run, &partial.positions);
            let complete = pass.advance(original, positions, partial.drift.reference(), vertices);
            let measured = (pass.measured() - before).max(1);
            self.runs.vertex_ms = Some(((self.clock)() - now) / measured as f64);
            self.worked = true;
            if complete {
                let roughness = *roughness;
                let (metrics, _) = partial.measuring.take()?.0.finish(original, 0.5);
                return Some(terms_of(&metrics, roughness));
            }
        }
    }

    /// Smooths `partial` towards `target` iterations, as many as fit in the budget (at least
    /// one). Windowed sinc, whose k-iteration result is no prefix of a longer run, runs from the
    /// original for each count, a few neighbour passes or drift steps per call.
    fn advance(&mut self, partial: &mut Partial, target: u32) {
        let t0 = (self.clock)();
        let left = self.deadline - t0;
        let fit = match self.runs.iteration_ms {
            Some(ms) if ms > 0.0 => (left / ms).floor().max(1.0) as u32,
            _ => 1,
        };
        let mut params = partial.params;
        let chunk = if let Some(run) = partial.run.as_mut() {
            let chunk = fit.clamp(1, target - partial.done);
            let state = std::mem::take(&mut partial.drift);
            let mut drift = DriftingReference::resume(self.original, state);
            let (mesh, topology) = (self.original.mesh(), self.original.topology());
            run.advance(mesh, topology, self.weights, chunk, &mut drift);
            partial.drift = drift.into_state();
            partial.done = run.done();
            chunk
        } else {
            params.iterations = target;
            let sinc = partial.sinc.take();
            match sinc.or_else(|| SincDrifting::new(self.original, &params)) {
                Some(mut sinc) => {
                    if sinc.advance(self.original, &params, self.weights, fit) {
                        (partial.positions, partial.drift) = sinc.into_result();
                        partial.done = target;
                    } else {
                        partial.sinc = Some(sinc);
                    }
                }
                None => partial.done = target,
            }
            fit
        };
        self.runs.iteration_ms = Some(((self.clock)() - t0) / f64::from(chunk.max(1)));
        self.worked = true;
    }
}

impl Sliced<'_> {
    /// The run under way if it is this request, else a new one.
    fn resume(&mut self, params: &Params, at: &[u32]) -> Partial {
        match self.runs.partial.take() {
            Some(p) if p.params == *params && p.at == at => p,
            _ => self.start(params, at),
        }
    }

    /// The positions after `params.iterations` iterations and their drifted reference vertices
    /// (as [`crate::metrics::smooth_drifting`] gives them), spread over calls like
    /// [`Evaluator::measure`]: `None` until the run is done.
    pub fn smoothed(&mut self, params: &Params) -> Option<(Vec<[f32; 3]>, Vec<u32>)> {
        // An empty `at` tells this run from a measured one with the same parameters.
        let mut partial = self.resume(params, &[]);
        while partial.done < params.iterations {
            if !self.fits(self.runs.iteration_ms) {
                self.runs.partial = Some(partial);
                return None;
            }
            self.advance(&mut partial, params.iterations);
        }
        self.runs.runs += 1;
        let positions = match partial.run {
            Some(run) => run.into_positions(),
            None => partial.positions,
        };
        Some((positions, partial.drift.into_reference()))
    }
}

impl Evaluator for Sliced<'_> {
    fn measure(&mut self, params: &Params, at: &[u32]) -> Option<Vec<Terms>> {
        if params.unchanged_counts(at) == at.len() {
            return Some(vec![self.evaluator.unchanged(); at.len()]);
        }
        let mut partial = self.resume(params, at);
        loop {
            let Some(&next) = partial.at.get(partial.terms.len()) else {
                self.runs.runs += 1;
                return Some(partial.terms);
            };
            if partial.done >= next {
                match self.measure_parts(&mut partial) {
                    Some(t) => partial.terms.push(t),
                    None => break,
                }
            } else {
                if !self.fits(self.runs.iteration_ms) {
                    break;
                }
                self.advance(&mut partial, next);
            }
        }
        self.runs.partial = Some(partial);
        None
    }
}

#[cfg(test)]
mod tests {
    use super::super::{run, GridSearch, LocalSearch, QualitySweep, Task};
    use super::*;
    use crate::io;
    use crate::mesh::Topology;
    use crate::metrics;
    use crate::smooth::Filter;
    use std::cell::Cell;

    const SAMPLE: &[u8] = include_bytes!("../../web/sample/bent_tube_staircase.ply");

    fn sample() -> Original {
        let mesh = io::load(SAMPLE, "sample.ply").expect("the sample loads");
        let topology = Topology::build(&mesh);
        Original::new(&mesh, &topology)
    }

    /// Runs `task` with a fresh [`Sliced`] per "frame" on a clock that ticks one millisecond
    /// per reading, so every frame stops after a few pieces; returns the output and the frames.
    fn sliced<T: Task>(
        original: &Original,
        weights: Option<&[f32]>,
        mut task: T,
        budget_ms: f64,
    ) -> (T::Output, usize) {
        let ticks = Cell::new(0.0);
        let clock = || {
            ticks.set(ticks.get() + 1.0);
            ticks.get()
        };
        let mut runs = SlicedRuns::default();
        let mut frames = 0;
        loop {
            frames += 1;
            let mut ev = Sliced::new(original, weights, &mut runs, &clock, budget_ms).unwrap();
            if task.step(&mut ev) {
                break;
            }
            assert!(frames < 100_000, "the task never finishes");
        }
        (task.into_output().unwrap(), frames)
    }

    fn whole<T: Task>(original: &Original, weights: Option<&[f32]>, task: T) -> T::Output {
        let mut ev = MeshEvaluator::new(original, weights).unwrap();
        run(task, &mut ev, &mut |_| true).unwrap()
    }

    #[test]
    fn sliced_quality_graphs_equal_whole_runs() {
        let original = sample();
        for filter in [Filter::Hc, Filter::Taubin] {
            let mut p = Params::defaults(filter);
            p.iterations = 6;
            let task = || QualitySweep::new(&p, 0.5).unwrap();
            let (graphs, frames) = sliced(&original, None, task(), 4.0);
            assert_eq!(graphs, whole(&original, None, task()), "{filter:?}");
            // At most a few pieces (an iteration chunk or a measure pass) per frame.
            let samples = task().progress().total;
            assert!(
                3 * frames >= samples,
                "{frames} frames for {samples} samples"
            );
        }
    }

    #[test]
    fn sliced_searches_equal_whole_runs_with_weights_and_a_bound() {
        let original = sample();
        let n = original.mesh().vertex_count();
        let weights: Vec<f32> = (0..n).map(|i| if i % 7 == 0 { 0.0 } else { 0.8 }).collect();
        let mut base = Params::defaults(Filter::Laplace);
        base.max_displacement = Some(0.3);
        let local = || LocalSearch::new(Filter::Laplace, &base, 0.6).unwrap();
        let (a, _) = sliced(&original, Some(&weights), local(), 3.0);
        assert_eq!(a, whole(&original, Some(&weights), local()));
        let grid = || GridSearch::new(Filter::Sinc, &Params::defaults(Filter::Sinc)).unwrap();
        let (a, _) = sliced(&original, None, grid(), 2.0);
        assert_eq!(a, whole(&original, None, grid()));
    }

    #[test]
    fn sliced_smoothing_equals_smooth_drifting() {
        let original = sample();
        let ticks = Cell::new(0.0);
        let clock = || {
            ticks.set(ticks.get() + 1.0);
            ticks.get()
        };
        for filter in [Filter::Hc, Filter::Sinc] {
            let mut p = Params::defaults(filter);
            p.iterations = 9;
            let mut runs = SlicedRuns::default();
            let mut calls = 0;
            let got = loop {
                calls += 1;
                let mut ev = Sliced::new(&original, None, &mut runs, &clock, 2.0).unwrap();
                if let Some(r) = ev.smoothed(&p) {
                    break r;
                }
            };
            assert_eq!(
                got,
                metrics::smooth_drifting(&original, &p, None),
                "{filter:?}"
            );
            let expected_calls = if filter == Filter::Sinc { 1 } else { 3 };
            assert!(calls >= expected_calls, "{filter:?}: {calls} calls");
        }
    }

    #[test]
    fn a_measure_pass_is_spread_over_calls_too() {
        let original = sample();
        assert_eq!(original.mesh().vertex_count().div_ceil(2048), 2);
        let ticks = Cell::new(0.0);
        let clock = || {
            ticks.set(ticks.get() + 1.0);
            ticks.get()
        };
        let p = Params::defaults(Filter::Hc);
        let mut runs = SlicedRuns::default();
        let mut calls = 0;
        let terms = loop {
            calls += 1;
            let mut ev = Sliced::new(&original, None, &mut runs, &clock, 0.0).unwrap();
            if let Some(t) = ev.measure(&p, &[2]) {
                break t;
            }
        };
        // Without budget, one piece per call: two iterations, the triangle areas, then the
        // measure pass's two runs of 2048 vertices.
        assert_eq!(calls, 5);
        let mut ev = MeshEvaluator::new(&original, None).unwrap();
        assert_eq!(Some(terms), ev.measure(&p, &[2]));
    }

    #[test]
    fn every_call_makes_progress_even_without_budget() {
        let original = sample();
        let mut p = Params::defaults(Filter::Laplace);
        p.iterations = 3;
        let (graphs, _) = sliced(&original, None, QualitySweep::new(&p, 0.5).unwrap(), 0.0);
        assert_eq!(
            graphs,
            whole(&original, None, QualitySweep::new(&p, 0.5).unwrap())
        );
    }
}
