//! Laplace+HC after Vollmer, Mencl and Mueller (1999), one iteration in two Jacobi passes:
//!
//! 1. `p_i = mean_{N(i)} q`, `b_i = p_i - (alpha o_i + (1 - alpha) q_i)`
//! 2. `q_i <- p_i - (beta b_i + (1 - beta) mean_{N(i)} b)`
//!
//! Pass 2 rebuilds `p_i` as `b_i + alpha o_i + (1 - alpha) q_i` instead of storing it, which
//! saves a buffer and its traffic.
//!
//! Two ways to run an iteration, the same arithmetic per vertex (so the same bits):
//! - [`Plan::Sweep`]: one sweep over the vertices in order, pass 1 running `lead` chunks ahead
//!   of pass 2. A ring reaches at most [`PaddedRing::span`] vertices away in vertex order, so
//!   pass 2 of a chunk finds every `b` it reads already made, still in the cache: the rings,
//!   the originals and `q` come from memory once per iteration instead of twice, and `b` is
//!   read back before it leaves the cache. Each thread sweeps a run of chunks with its own `b`, making the `lead` chunks on
//!   either side of its run itself. Pass 2 writes into a second buffer (pass 1 further on
//!   still reads this iteration's `q`).
//! - [`Plan::TwoPass`]: pass 1 over every vertex, then pass 2 over every vertex, in place;
//!   for meshes whose rings reach too far in vertex order for the sweep to pay.
//!
//! [`PaddedRing::span`]: crate::mesh::PaddedRing::span

use rayon::prelude::*;

use super::constraint::Constrain;
use super::rings::{xyz0, Field, Fields, KernelRings, Ring, CHUNK};
use super::{follow_parts, FollowPart, StepObserver};

/// How an iteration runs (see the module's documentation).
#[derive(Clone, Debug, PartialEq)]
enum Plan {
    TwoPass,
    /// `runs`: the chunk ranges the threads sweep, in order, covering every chunk; pass 1
    /// runs `lead` chunks ahead of pass 2.
    Sweep {
        runs: Vec<std::ops::Range<usize>>,
        lead: usize,
    },
}

impl Plan {
    /// The sweep with `threads` runs when the pass-1 work done twice (the `lead` chunks on
    /// either side of each run's edge) stays under an eighth of an iteration's; else two passes.
    fn choose(rings: KernelRings, threads: usize) -> Plan {
        let chunks = rings.vertex_count().div_ceil(CHUNK);
        let lead = (rings.span() as usize).div_ceil(CHUNK).max(1);
        let threads = threads.clamp(1, chunks.max(1));
        if 2 * lead * (threads - 1) * 8 > chunks {
            return Plan::TwoPass;
        }
        Plan::sweep(chunks, threads, lead)
    }

    /// The sweep over `chunks` in `runs` runs of nearly equal length.
    fn sweep(chunks: usize, runs: usize, lead: usize) -> Plan {
        let runs = runs.clamp(1, chunks.max(1));
        Plan::Sweep {
            runs: (0..runs)
                .map(|r| chunks * r / runs..chunks * (r + 1) / runs)
                .collect(),
            lead,
        }
    }
}

/// Runs HC iterations `done + 1 ..= done + more` on `fields` (the result of `done`
/// iterations); one step (and report) per iteration, the positions the observer sees laid out
/// in `points`. Returns whether `points` holds the last iteration's positions.
#[allow(clippy::too_many_arguments)]
pub(crate) fn advance<C: Constrain>(
    rings: KernelRings,
    original: &[[f32; 3]],
    fields: &mut Fields,
    points: &mut Vec<[f32; 3]>,
    alpha_beta: (f32, f32),
    counts: (u32, u32),
    constraint: &C,
    observer: &mut dyn StepObserver,
) -> bool {
    let plan = Plan::choose(rings, rayon::current_num_threads());
    advance_planned(
        rings, original, fields, points, alpha_beta, counts, constraint, observer, &plan,
    )
}

#[allow(clippy::too_many_arguments)]
fn advance_planned<C: Constrain>(
    rings: KernelRings,
    original: &[[f32; 3]],
    fields: &mut Fields,
    points: &mut Vec<[f32; 3]>,
    alpha_beta: (f32, f32),
    (done, more): (u32, u32),
    constraint: &C,
    observer: &mut dyn StepObserver,
    plan: &Plan,
) -> bool {
    let n = rings.vertex_count();
    assert!(original.len() == n && fields.q.vertices().len() == n);
    // Two passes: one `b`, `q` updated in place. The sweep: a `b` per run and the next
    // positions.
    let (q, next, bs) = fields.with_scratch(match plan {
        Plan::TwoPass => 1,
        Plan::Sweep { runs, .. } => runs.len(),
    });
    // The originals as the kernel reads them: one aligned four-lane load per vertex.
    let original: Vec<[f32; 4]> = original.iter().map(|&o| xyz0(o)).collect();
    let kernel = Kernel {
        rings,
        original: &original,
        alpha_beta,
    };
    let mut written = false;
    for iteration in done + 1..=done + more {
        let mut parts = follow_parts(observer, n);
        match plan {
            Plan::Sweep { runs, lead } => {
                kernel.sweep(q, next, bs, runs, *lead, constraint, &mut parts);
                std::mem::swap(q, next);
            }
            Plan::TwoPass => {
                kernel.differences(q, &mut bs[0]);
                kernel.correct(&bs[0], q, constraint, &mut parts);
            }
        }
        drop(parts);
        written = observer.watches_iteration(iteration);
        if written {
            q.write_points(points);
            observer.after_step(points);
            observer.after_iteration(iteration, points);
        }
    }
    written
}

/// What both passes read besides the fields: the rings, the original positions and
/// `(alpha, beta)`.
struct Kernel<'a> {
    rings: KernelRings<'a>,
    original: &'a [[f32; 4]],
    alpha_beta: (f32, f32),
}

impl Kernel<'_> {
    /// Pass 1 for one vertex, its ring over `q`: `mean_{N(i)} q - (alpha o_i + (1 - alpha) q_i)`;
    /// 0 for an isolated vertex (no ring reads it).
    #[inline(always)]
    fn difference(&self, ring: Ring, qi: [f32; 4], oi: [f32; 4]) -> [f32; 4] {
        if ring.is_empty() {
            return [0.0; 4];
        }
        let alpha = self.alpha_beta.0;
        let keep = 1.0 - alpha;
        let p = self.rings.mean(ring);
        std::array::from_fn(|k| p[k] - (alpha * oi[k] + keep * qi[k]))
    }

    /// Pass 2 for one vertex, its ring over `b`, before the constraint: `p_i - (beta b_i + (1 -
    /// beta) mean b)` (`None` for an isolated vertex: it keeps its place).
    #[inline(always)]
    fn corrected(&self, ring: Ring, bi: [f32; 4], oi: [f32; 4], qi: [f32; 4]) -> Option<[f32; 4]> {
        if ring.is_empty() {
            return None;
        }
        let (alpha, beta) = self.alpha_beta;
        let (keep, spread) = (1.0 - alpha, 1.0 - beta);
        let mb = self.rings.mean(ring);
        Some(std::array::from_fn(|k| {
            let p = bi[k] + alpha * oi[k] + keep * qi[k];
            p - (beta * bi[k] + spread * mb[k])
        }))
    }

    /// The original positions of chunk `c`.
    fn originals(&self, c: usize) -> &[[f32; 4]] {
        let n = self.original.len();
        &self.original[(c * CHUNK).min(n)..((c + 1) * CHUNK).min(n)]
    }

    /// Pass 1 of chunk `c` into its entries of `b`.
    fn differences_of_chunk(&self, c: usize, q: &Field, b: &mut [[f32; 4]]) {
        let own = &q.vertices()[c * CHUNK..];
        let rows = b.iter_mut().zip(own).zip(self.originals(c));
        for (((bi, &qi), &oi), ring) in rows.zip(self.rings.chunk(c, q)) {
            *bi = self.difference(ring, qi, oi);
        }
    }

    /// Pass 1 over every vertex.
    fn differences(&self, q: &Field, b: &mut Field) {
        b.vertices_mut()
            .par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(c, b)| self.differences_of_chunk(c, q, b));
    }

    /// Pass 2 over every vertex, in place; each chunk then goes to its follower part.
    fn correct<C: Constrain>(
        &self,
        b: &Field,
        q: &mut Field,
        constraint: &C,
        parts: &mut [Option<FollowPart>],
    ) {
        q.vertices_mut()
            .par_chunks_mut(CHUNK)
            .zip(parts.par_iter_mut())
            .enumerate()
            .for_each(|(c, (q, part))| {
                let own_b = &b.vertices()[c * CHUNK..];
                let rows = q.iter_mut().zip(own_b).zip(self.originals(c));
                for (k, (((qi, &bi), &oi), ring)) in rows.zip(self.rings.chunk(c, b)).enumerate() {
                    if let Some(proposed) = self.corrected(ring, bi, oi, *qi) {
                        let i = c * CHUNK + k;
                        *qi = constraint.apply4(i, *qi, proposed);
                    }
                }
                if let Some(follow) = part {
                    follow(q);
                }
            });
    }

    /// Pass 2 of chunk `c` from `q` into `out` (its entries of the next positions); then the
    /// chunk goes to its follower part.
    fn correct_chunk<C: Constrain>(
        &self,
        c: usize,
        (q, b): (&Field, &Field),
        out: &mut [[f32; 4]],
        constraint: &C,
        part: &mut Option<FollowPart>,
    ) {
        let own_q = &q.vertices()[c * CHUNK..];
        let own_b = &b.vertices()[c * CHUNK..];
        let rows = out
            .iter_mut()
            .zip(own_q.iter().zip(own_b))
            .zip(self.originals(c));
        for (k, (((o, (&qi, &bi)), &oi), ring)) in rows.zip(self.rings.chunk(c, b)).enumerate() {
            *o = match self.corrected(ring, bi, oi, qi) {
                Some(proposed) => constraint.apply4(c * CHUNK + k, qi, proposed),
                None => qi,
            };
        }
        if let Some(follow) = part {
            follow(out);
        }
    }

    /// One iteration as a sweep per run of chunks (see [`Plan::Sweep`]), from `q` into `next`.
    #[allow(clippy::too_many_arguments)]
    fn sweep<C: Constrain>(
        &self,
        q: &Field,
        next: &mut Field,
        bs: &mut [Field],
        runs: &[std::ops::Range<usize>],
        lead: usize,
        constraint: &C,
        parts: &mut [Option<FollowPart>],
    ) {
        let chunks = self.rings.vertex_count().div_ceil(CHUNK);
        // Each run's share of the next positions and of the follower parts.
        let mut work = Vec::with_capacity(runs.len());
        let (mut out, mut parts) = (next.vertices_mut(), parts);
        for (run, b) in runs.iter().zip(bs.iter_mut()) {
            let vertices = (run.len() * CHUNK).min(out.len());
            let (here, rest) = out.split_at_mut(vertices);
            let (run_parts, rest_parts) = parts.split_at_mut(run.len());
            work.push((run.clone(), here, run_parts, b));
            (out, parts) = (rest, rest_parts);
        }
        work.into_par_iter().for_each(|(run, out, parts, b)| {
            // Pass 1 of chunk `j` into this run's `b` (`j` past the last chunk: nothing).
            let differences = |b: &mut Field, j: usize| {
                if j < chunks {
                    let n = b.vertices().len();
                    let entries = &mut b.vertices_mut()[j * CHUNK..((j + 1) * CHUNK).min(n)];
                    self.differences_of_chunk(j, q, entries);
                }
            };
            for j in run.start.saturating_sub(lead)..run.start + lead {
                differences(b, j);
            }
            let chunks_out = out.chunks_mut(CHUNK).zip(parts.iter_mut());
            for (c, (out, part)) in run.clone().zip(chunks_out) {
                differences(b, c + lead);
                self.correct_chunk(c, (q, b), out, constraint, part);
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Topology;
    use crate::smooth::constraint::{Free, Limits};

    /// Records every iteration's positions.
    #[derive(Default)]
    struct Iterations(Vec<Vec<[f32; 3]>>);
    impl StepObserver for Iterations {
        fn after_iteration(&mut self, _: u32, p: &[[f32; 3]]) {
            self.0.push(p.to_vec());
        }
    }

    fn brainmask() -> crate::mesh::Mesh {
        let path = "../shared/data/segmentations/seg_mni152_brainmask_2mm.ply";
        let bytes = std::fs::read(path).expect("the shared meshes lie beside the checkout");
        crate::io::load(&bytes, path).expect("a mesh")
    }

    #[test]
    fn the_sweep_gives_the_two_passes_bits_with_any_runs_and_constraints() {
        let mesh = brainmask();
        let topology = Topology::build(&mesh);
        let n = mesh.vertex_count();
        let rings = KernelRings::new(&topology, n).expect("built for this mesh");
        let chunks = n.div_ceil(CHUNK);
        let lead = (rings.span() as usize).div_ceil(CHUNK);
        // A mesh from a volume reaches a few slices along, far less than its vertex count.
        assert!(
            lead >= 1 && 8 * lead < chunks,
            "lead {lead} of {chunks} chunks"
        );
        let weights: Vec<f32> = (0..n).map(|i| (i % 5) as f32 / 4.0).collect();
        let limits = Limits::new(Some(&weights), Some(0.3), &mesh.positions).expect("limits");
        let run = |plan: &Plan, limited: bool| {
            let mut seen = Iterations::default();
            let mut fields = Fields::from_points(&mesh.positions);
            let mut last = Vec::new();
            let (o, ab) = (&mesh.positions, (0.2, 0.6));
            // In two calls, the second on the buffers the first left.
            for counts in [(0, 3), (3, 1)] {
                let (f, seen) = (&mut fields, &mut seen);
                let written = if limited {
                    advance_planned(rings, o, f, &mut last, ab, counts, &limits, seen, plan)
                } else {
                    advance_planned(rings, o, f, &mut last, ab, counts, &Free, seen, plan)
                };
                assert!(written, "the observer watches every iteration");
            }
            (last, seen.0)
        };
        for limited in [false, true] {
            let (expected, steps) = run(&Plan::TwoPass, limited);
            assert_eq!(steps.len(), 4);
            assert_ne!(expected, mesh.positions);
            // One run; several; runs shorter than the lead; a lead longer than needed.
            for (runs, lead) in [
                (1, lead),
                (2, lead),
                (3, lead),
                (chunks, lead),
                (4, lead + 3),
            ] {
                let plan = Plan::sweep(chunks, runs, lead);
                let (got, got_steps) = run(&plan, limited);
                assert_eq!(got, expected, "{runs} runs, lead {lead}, limited {limited}");
                assert_eq!(got_steps, steps);
            }
        }
    }

    #[test]
    fn the_plan_sweeps_where_rings_reach_near_and_threads_are_few() {
        let mesh = brainmask();
        let topology = Topology::build(&mesh);
        let rings = KernelRings::new(&topology, mesh.vertex_count()).expect("built for this mesh");
        let runs = |plan| match plan {
            Plan::Sweep { runs, .. } => runs.len(),
            Plan::TwoPass => 0,
        };
        assert_eq!(runs(Plan::choose(rings, 1)), 1);
        assert_eq!(runs(Plan::choose(rings, 2)), 2);
        assert_eq!(Plan::choose(rings, 64), Plan::TwoPass);
        // The sample tube has three chunks: one thread sweeps them, more take two passes.
        let tube = crate::io::load(
            include_bytes!("../../tests/data/bent_tube_staircase.ply"),
            "tube.ply",
        )
        .expect("the sample");
        let tube_topology = Topology::build(&tube);
        let tube_rings = KernelRings::new(&tube_topology, tube.vertex_count()).expect("rings");
        assert_eq!(runs(Plan::choose(tube_rings, 1)), 1);
        assert_eq!(Plan::choose(tube_rings, 2), Plan::TwoPass);
    }
}
