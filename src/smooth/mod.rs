//! The CPU smoothing engine: the reference every other path is checked against, and the
//! fallback where WebGPU is missing. Definitions: ALGORITHMS.md (shared docs).
//!
//! Every filter is a Jacobi update (each step reads the previous step's positions), always starts
//! from the original positions, honours per-vertex weights (0 locks a vertex) and the optional
//! displacement bound `d_max` around the original position.
//!
//! Layout: `umbrella` (Laplace, Taubin), `hc`, `sinc` with `sinc_coefficients`; the shared
//! neighbourhood view and neighbour mean in `rings`; weights and the bound in `constraint`.
//! Every pass runs in parallel over vertices (rayon; on wasm32 without threads it runs on the
//! calling thread) on f32 buffers allocated once per run, four lanes per vertex with a zero
//! entry after the last (`rings::Field`), which the rings' unused slots name.

mod constraint;
mod hc;
mod params;
pub mod reference;
mod rings;
mod sinc;
mod sinc_coefficients;
mod umbrella;

pub use params::{shortest, Filter, ParamError, Params};
// The GPU engine evaluates the same windowed-sinc series.
#[cfg(feature = "gpu")]
pub(crate) use sinc_coefficients::sinc_coefficients;

use crate::mesh::{Mesh, Topology};
use constraint::{Constrain, Free, Limits};
use rings::{Fields, KernelRings};

/// Watches a smoothing run. The local-error measure drifts its reference vertices after every
/// step (as a [`Follower`], inside the step's pass); sweeps over iterations measure along one
/// run instead of restarting.
pub trait StepObserver {
    /// After every position update (Taubin: twice per iteration; HC: once per iteration).
    /// Windowed sinc's running sums between terms are not meshes, so it reports its result
    /// once per degree (one step per neighbour pass) after the last term.
    fn after_step(&mut self, _positions: &[[f32; 3]]) {}
    /// After iteration `iteration` (1-based) of a filter whose k-iteration result is the result
    /// of smoothing with k iterations (Laplace, Taubin, HC). Windowed sinc's intermediate terms
    /// are not a shorter filter's result, so it reports only its final iteration.
    fn after_iteration(&mut self, _iteration: u32, _positions: &[[f32; 3]]) {}
    /// False when the observer ignores every call: the engine then skips laying out the
    /// positions it would report (its kernels keep them in another layout).
    fn watches(&self) -> bool {
        true
    }
    /// Whether the observer wants the calls of iteration `iteration` (its steps and the
    /// iteration): one that measures at a few counts along a run says no to the others, and
    /// the engine skips laying out their positions. By default [`Self::watches`].
    fn watches_iteration(&self, _iteration: u32) -> bool {
        self.watches()
    }
    /// Work on the positions of every step that the engine does inside the step's own pass
    /// ([`Follower`]), before the step's calls. Asked for once per step.
    fn follower(&mut self) -> Option<&mut dyn Follower> {
        None
    }
}

/// Per-vertex work on the new positions of every step of a run (the drifting reference of the
/// local error), done by the step's own pass over the vertices, a run of them at a time, while
/// they are at hand: no pass of its own, and no laying out of positions for it.
pub trait Follower {
    /// One part per run of `run` vertices (the last may be shorter), in vertex order. Each part
    /// is handed the new positions of its run once, four lanes per vertex (the fourth 0).
    fn parts(&mut self, run: usize) -> Vec<FollowPart<'_>>;
}

/// A [`Follower`]'s work on one run of vertices.
pub type FollowPart<'a> = Box<dyn FnMut(&[[f32; 4]]) + Send + 'a>;

/// The observer's follower split into one part per chunk of `n` vertices for the next step
/// (`None` for every chunk when it has none).
pub(crate) fn follow_parts(
    observer: &mut dyn StepObserver,
    n: usize,
) -> Vec<Option<FollowPart<'_>>> {
    let chunks = n.div_ceil(rings::CHUNK);
    match observer.follower() {
        Some(follower) => {
            let parts = follower.parts(rings::CHUNK);
            assert_eq!(parts.len(), chunks, "one follower part per chunk");
            parts.into_iter().map(Some).collect()
        }
        None => (0..chunks).map(|_| None).collect(),
    }
}

/// An observer that watches nothing.
pub struct NoObserver;
impl StepObserver for NoObserver {
    fn watches(&self) -> bool {
        false
    }
}

/// Smooths `mesh` with `params` from its original positions and returns the new positions
/// (same vertex order). `weights`, when given, has one entry in [0, 1] per vertex.
///
/// Observer calls: Laplace and HC report `after_step` then `after_iteration` once per
/// iteration, Taubin `after_step` twice per iteration; windowed sinc reports `after_step` once
/// per term (`iterations` times) and `after_iteration(iterations, ..)` once at the end.
/// With zero iterations nothing is reported and the original positions come back.
///
/// Windowed sinc applies weights and `max_displacement` to its running estimate's total
/// displacement from the original (its recurrence must run unconstrained); the other filters
/// apply them after every step, as ALGORITHMS.md defines.
///
/// `params` should pass [`Params::validate`]; out-of-range values do not panic but give
/// results that mean little. `topology` must be built from `mesh`: if it describes a different
/// vertex count, nothing moves.
pub fn smooth(
    mesh: &Mesh,
    topology: &Topology,
    params: &Params,
    weights: Option<&[f32]>,
    observer: &mut dyn StepObserver,
) -> Vec<[f32; 3]> {
    run(mesh, topology, params, weights, None, observer)
}

/// Continues a run of Laplace, Taubin or HC: `current` is the result of `done` iterations of
/// `params` from `mesh`'s positions; returns the result of `done + more` iterations (the
/// observer sees iterations `done + 1 ..= done + more`), equal to [`smooth`] with that many
/// iterations. Lets a search go on from a run it kept instead of starting over. `None` for
/// windowed sinc, whose terms are not shorter filters' results (and for a `current` of the
/// wrong length).
#[allow(clippy::too_many_arguments)]
pub fn resume(
    mesh: &Mesh,
    topology: &Topology,
    params: &Params,
    weights: Option<&[f32]>,
    current: Vec<[f32; 3]>,
    done: u32,
    more: u32,
    observer: &mut dyn StepObserver,
) -> Option<Vec<[f32; 3]>> {
    if params.filter == Filter::Sinc || current.len() != mesh.vertex_count() {
        return None;
    }
    Some(run(
        mesh,
        topology,
        params,
        weights,
        Some((current, done, more)),
        observer,
    ))
}

/// A run from the original positions (`resume` None) or from a partial result.
fn run(
    mesh: &Mesh,
    topology: &Topology,
    params: &Params,
    weights: Option<&[f32]>,
    resume: Option<(Vec<[f32; 3]>, u32, u32)>,
    observer: &mut dyn StepObserver,
) -> Vec<[f32; 3]> {
    let original = &mesh.positions;
    let Some(rings) = KernelRings::new(topology, original.len()) else {
        return resume.map_or_else(|| original.clone(), |r| r.0);
    };
    if params.filter == Filter::Sinc {
        return match Limits::new(weights, params.max_displacement, original) {
            None => sinc::run(
                rings,
                original,
                params.passband,
                params.iterations,
                &Free,
                observer,
            ),
            Some(limits) => sinc::run(
                rings,
                original,
                params.passband,
                params.iterations,
                &limits,
                observer,
            ),
        };
    }
    // `None`: the run starts from the original positions, read in place.
    let (start, counts) = match resume {
        Some((current, done, more)) => (Some(current), (done, more)),
        None => (None, (0, params.iterations)),
    };
    if counts.1 == 0 {
        return start.unwrap_or_else(|| original.clone());
    }
    let mut fields = Fields::from_points(start.as_deref().unwrap_or(original));
    // `points` receives the 3-vectors the observer and the caller see (the start's
    // allocation, reused).
    let mut points = start.unwrap_or_default();
    let step = Advance {
        rings,
        original,
        params,
        weights,
    };
    if !step.advance(&mut fields, &mut points, counts, observer) {
        fields.q.write_points(&mut points);
    }
    points
}

/// One call's iterations of a Laplace, Taubin or HC run.
struct Advance<'a> {
    rings: KernelRings<'a>,
    original: &'a [[f32; 3]],
    params: &'a Params,
    weights: Option<&'a [f32]>,
}

impl Advance<'_> {
    /// Iterations `done + 1 ..= done + more` on `fields`; whether `points` holds the last.
    fn advance(
        &self,
        fields: &mut Fields,
        points: &mut Vec<[f32; 3]>,
        counts: (u32, u32),
        observer: &mut dyn StepObserver,
    ) -> bool {
        let p = self.params;
        match Limits::new(self.weights, p.max_displacement, self.original) {
            None => self.constrained(fields, points, counts, &Free, observer),
            Some(limits) => self.constrained(fields, points, counts, &limits, observer),
        }
    }

    fn constrained<C: Constrain>(
        &self,
        fields: &mut Fields,
        points: &mut Vec<[f32; 3]>,
        counts: (u32, u32),
        constraint: &C,
        observer: &mut dyn StepObserver,
    ) -> bool {
        let (p, rings) = (self.params, self.rings);
        match p.filter {
            Filter::Laplace => {
                let factors = [p.lambda];
                umbrella::advance(
                    rings, fields, points, &factors, counts, constraint, observer,
                )
            }
            Filter::Taubin => {
                let factors = [p.lambda, p.mu];
                umbrella::advance(
                    rings, fields, points, &factors, counts, constraint, observer,
                )
            }
            Filter::Hc => hc::advance(
                rings,
                self.original,
                fields,
                points,
                (p.alpha, p.beta),
                counts,
                constraint,
                observer,
            ),
            // Not resumable: `run` takes it whole.
            Filter::Sinc => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Records every step it sees.
    #[derive(Default)]
    struct Steps(Vec<Vec<[f32; 3]>>, Vec<u32>);
    impl StepObserver for Steps {
        fn after_step(&mut self, p: &[[f32; 3]]) {
            self.0.push(p.to_vec());
        }
        fn after_iteration(&mut self, k: u32, _: &[[f32; 3]]) {
            self.1.push(k);
        }
    }

    /// The bundled sample, its topology and uneven weights (0, 0.5, 1 in turn).
    fn sample_with_weights() -> (Mesh, Topology, Vec<f32>) {
        let mesh = crate::io::load(
            include_bytes!("../../tests/data/bent_tube_staircase.ply"),
            "tube.ply",
        )
        .unwrap();
        let topology = Topology::build(&mesh);
        let weights = (0..mesh.vertex_count())
            .map(|i| (i % 3) as f32 / 2.0)
            .collect();
        (mesh, topology, weights)
    }

    /// Seven iterations of `filter`'s defaults with a bound and `weights`: the parameters,
    /// the steps the observer saw, the result.
    fn seven_bounded(
        filter: Filter,
        mesh: &Mesh,
        topology: &Topology,
        weights: &[f32],
    ) -> (Params, Steps, Vec<[f32; 3]>) {
        let mut p = Params::defaults(filter);
        p.iterations = 7;
        p.max_displacement = Some(0.4);
        let mut whole = Steps::default();
        let expected = smooth(mesh, topology, &p, Some(weights), &mut whole);
        (p, whole, expected)
    }

    #[test]
    fn a_resumed_run_equals_the_whole_run() {
        let (mesh, topology, weights) = sample_with_weights();
        for filter in [Filter::Laplace, Filter::Taubin, Filter::Hc] {
            let (p, whole, expected) = seven_bounded(filter, &mesh, &topology, &weights);

            let mut parts = Steps::default();
            let mut current = mesh.positions.clone();
            for (done, more) in [(0, 1), (1, 4), (5, 0), (5, 2)] {
                current = resume(
                    &mesh,
                    &topology,
                    &p,
                    Some(&weights),
                    current,
                    done,
                    more,
                    &mut parts,
                )
                .expect("resumable");
            }
            assert_eq!(current, expected, "{filter}");
            assert_eq!(parts.0, whole.0, "{filter}: the same steps");
            assert_eq!(parts.1, (1..=7).collect::<Vec<_>>(), "{filter}");
        }
        let sinc = Params::defaults(Filter::Sinc);
        assert!(resume(
            &mesh,
            &topology,
            &sinc,
            None,
            mesh.positions.clone(),
            0,
            1,
            &mut NoObserver
        )
        .is_none());
        let p = Params::defaults(Filter::Hc);
        assert!(resume(
            &mesh,
            &topology,
            &p,
            None,
            vec![[0.0; 3]; 3],
            0,
            1,
            &mut NoObserver
        )
        .is_none());
    }
}
