//! Parameter suggestions and quality graphs on the real engine and the shared meshes.
//!
//! One grid per mesh and filter serves several checks: tau = 0 suggests no smoothing; along the
//! grid minimum K/K0 minus the accuracy term never increases with tau; the local search is
//! compared with it at tau 0.2, 0.5, 0.8 (table printed with `--nocapture`); on the synthetic
//! meshes the tau = 0.5 suggestion is checked against the analytic surfaces.
//!
//! Benchmark (printed, not asserted): `meshsmooth suggest FILE --filter F --search grid|local`
//! prints the seconds and the number of parameter sets evaluated.

#[path = "common_metrics/data.rs"]
mod data;
#[path = "common_metrics/ground_truth.rs"]
mod ground_truth;

use meshsmooth::metrics::{DriftingReference, Original};
use meshsmooth::smooth::{smooth, Filter, NoObserver, Params};
use meshsmooth::suggest::{
    run, EvaluatedGrid, Evaluator, GridMinimum, GridSearch, LocalSearch, MeshEvaluator,
    QualitySweep, Suggestion, Terms,
};
use std::time::Instant;

const TAUS: [f64; 3] = [0.2, 0.5, 0.8];

fn grid(original: &Original, filter: Filter) -> EvaluatedGrid {
    let mut ev = MeshEvaluator::new(original, None).expect("no weights");
    let task = GridSearch::new(filter, &Params::defaults(filter)).expect("valid base");
    run(task, &mut ev, &mut |_| true).expect("not cancelled")
}

fn minimum(original: &Original, filter: Filter, tau: f64) -> Suggestion {
    let mut ev = MeshEvaluator::new(original, None).expect("no weights");
    let task = GridMinimum::new(filter, &Params::defaults(filter), tau).expect("valid base");
    run(task, &mut ev, &mut |_| true).expect("not cancelled")
}

/// Answers from a measured grid instead of smoothing again: every local-search point is a grid
/// point, and measuring is deterministic, so this gives the local search's real result.
struct GridLookup<'a> {
    grid: &'a EvaluatedGrid,
}

impl Evaluator for GridLookup<'_> {
    fn measure(&mut self, params: &Params, at: &[u32]) -> Option<Vec<Terms>> {
        at.iter()
            .map(|&k| {
                let mut p = *params;
                p.iterations = k;
                let point = self.grid.space.point_of(&p).expect("a grid point");
                self.grid
                    .points
                    .iter()
                    .find(|(q, _)| *q == point)
                    .map(|&(_, t)| t)
                    .expect("measured by the grid")
            })
            .map(Some)
            .collect()
    }
}

fn local_on_grid(g: &EvaluatedGrid, tau: f64) -> Suggestion {
    let filter = g.space.filter;
    let task = LocalSearch::new(filter, &Params::defaults(filter), tau).expect("valid base");
    run(task, &mut GridLookup { grid: g }, &mut |_| true)
        .expect("not cancelled")
        .suggestion
}

fn local(original: &Original, filter: Filter, tau: f64) -> Suggestion {
    let mut ev = MeshEvaluator::new(original, None).expect("no weights");
    let task = LocalSearch::new(filter, &Params::defaults(filter), tau).expect("valid base");
    run(task, &mut ev, &mut |_| true)
        .expect("not cancelled")
        .suggestion
}

/// One line of the local-vs-grid report.
struct Comparison {
    mesh: String,
    filter: Filter,
    tau: f64,
    grid: Suggestion,
    local: Suggestion,
}

impl std::fmt::Display for Comparison {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let outcome = if self.grid.params == self.local.params {
            "same"
        } else if self.local.score == self.grid.score {
            "tie"
        } else {
            "MISS"
        };
        write!(
            f,
            "{:<34} {:<7} {:.1}  {:<4}  S grid {:.5} local {:.5} (+{:.1e})  evals {:>4} / {:>3} = {:>4.1}x",
            self.mesh,
            self.filter.name(),
            self.tau,
            outcome,
            self.grid.score,
            self.local.score,
            self.local.score - self.grid.score,
            self.grid.evaluations,
            self.local.evaluations,
            self.grid.evaluations as f64 / self.local.evaluations as f64
        )
    }
}

/// Grid and local search on one mesh for every filter, checking the properties that must hold.
fn check_mesh(name: &str) -> Vec<Comparison> {
    let (mesh, topology) = data::load(name);
    let original = Original::new(&mesh, &topology);
    let mut out = Vec::new();
    for filter in Filter::ALL {
        let start = Instant::now();
        let g = grid(&original, filter);
        let grid_seconds = start.elapsed().as_secs_f64();

        let zero = g.best(0.0).expect("grid not empty");
        assert!(
            zero.leaves_mesh_unchanged(),
            "{name} {filter}: tau 0 suggests {:?}",
            zero.params
        );
        assert_eq!(zero.score, 0.0);

        // S = accuracy + tau (K/K0 - accuracy): its minimiser's slope cannot grow with tau.
        let mut last = f64::INFINITY;
        for i in 0..=10 {
            let tau = i as f64 / 10.0;
            let t = g.best(tau).expect("grid not empty").terms;
            let slope = t.curvature_ratio - t.accuracy();
            assert!(
                slope <= last + 1e-12,
                "{name} {filter}: K/K0 - accuracy rose to {slope} at tau {tau} from {last}"
            );
            last = slope;
        }
        assert!(
            !g.best(1.0).expect("grid").leaves_mesh_unchanged(),
            "{name} {filter}: tau 1 must smooth"
        );

        // The grid minimum that measures the local error only where it can matter (the
        // engine's bounds are real here) is the full grid's.
        let bounded = minimum(&original, filter, 0.5);
        let full = g.best(0.5).expect("grid not empty");
        assert_eq!(
            (bounded.params, bounded.score, bounded.terms),
            (full.params, full.score, full.terms),
            "{name} {filter}"
        );

        for tau in TAUS {
            let l = local_on_grid(&g, tau);
            let gb = g.best(tau).expect("grid not empty");
            assert!(l.score >= gb.score, "local below the grid minimum");
            if g.space.dims() == 3 {
                assert!(
                    3 * l.evaluations <= gb.evaluations,
                    "{name} {filter} tau {tau}: local measured {} of {}",
                    l.evaluations,
                    gb.evaluations
                );
            }
            out.push(Comparison {
                mesh: name.rsplit('/').next().unwrap_or(name).to_string(),
                filter,
                tau,
                grid: gb,
                local: l,
            });
        }
        eprintln!("{name} {filter}: grid {grid_seconds:.2} s");
    }
    out
}

/// Where the tau = 0.5 suggestion leaves the volume more than 1 % off the exact one. The staircase
/// bent tube is already 1.04 % below it before smoothing, and S weighs the volume change against
/// the original (0.25 at tau = 0.5) less than the curvature (0.5). Measured: bent tube HC 2.01 %,
/// Taubin 1.87 %, sinc 1.57 %; torus Taubin 1.41 % (lambda 0.9, mu -1.0, the grid's strongest
/// Taubin pair).
const VOLUME_EXCEPTIONS: [(&str, Filter); 4] = [
    ("synthetic_bent_tube_r3.5", Filter::Hc),
    ("synthetic_bent_tube_r3.5", Filter::Taubin),
    ("synthetic_bent_tube_r3.5", Filter::Sinc),
    ("synthetic_torus_R24_r8", Filter::Taubin),
];

/// On a synthetic mesh: the tau = 0.5 grid suggestion of each filter against the analytic shape.
/// Every filter lowers the RMS distance below the staircase's 0.205 mm; HC, Taubin and sinc keep
/// the volume within 1 % of the exact volume, except [`VOLUME_EXCEPTIONS`].
fn check_synthetic(name: &str, shape: &str) -> Vec<Comparison> {
    let table = check_mesh(&format!("synthetic/{name}.ply"));
    let (mesh, topology) = data::load(&format!("synthetic/{name}.ply"));
    let truth = ground_truth::load();
    let shape = &truth.shapes[shape];
    let before = ground_truth::true_error(shape, &mesh.positions);
    let mut failures = Vec::new();
    for c in table.iter().filter(|c| c.tau == 0.5) {
        let smoothed = smooth(&mesh, &topology, &c.grid.params, None, &mut NoObserver);
        let after = ground_truth::true_error(shape, &smoothed);
        let volume = meshsmooth::mesh::signed_volume(&smoothed, &mesh.triangles);
        let volume_error = (volume - shape.volume).abs() / shape.volume;
        eprintln!(
            "{name} {}: {} -> RMS {:.4} mm (was {:.4}), volume off exact by {:.3} % (was {:.3} %)",
            c.filter,
            describe(&c.grid.params),
            after.rms,
            before.rms,
            100.0 * volume_error,
            100.0 * (mesh.signed_volume() - shape.volume).abs() / shape.volume
        );
        if after.rms >= 0.205 {
            failures.push(format!("{}: RMS {:.4} mm", c.filter, after.rms));
        }
        let exception = VOLUME_EXCEPTIONS.contains(&(name, c.filter));
        if c.filter != Filter::Laplace && !exception && volume_error >= 0.01 {
            failures.push(format!(
                "{}: volume off by {:.2} %",
                c.filter,
                100.0 * volume_error
            ));
        }
    }
    assert!(failures.is_empty(), "{name}: {failures:?}");
    table
}

/// The active filter's parameters, briefly.
fn describe(p: &Params) -> String {
    match p.filter {
        Filter::Laplace => format!("lambda {} iterations {}", p.lambda, p.iterations),
        Filter::Taubin => format!(
            "lambda {} mu {} iterations {}",
            p.lambda, p.mu, p.iterations
        ),
        Filter::Hc => format!(
            "alpha {} beta {} iterations {}",
            p.alpha, p.beta, p.iterations
        ),
        Filter::Sinc => format!("passband {} iterations {}", p.passband, p.iterations),
    }
}

fn print(table: &[Comparison]) {
    for c in table {
        eprintln!("{c}");
    }
}

#[test]
fn sphere() {
    print(&check_synthetic("synthetic_sphere_r20", "sphere_r20"));
}

#[test]
fn torus() {
    print(&check_synthetic("synthetic_torus_R24_r8", "torus_R24_r8"));
}

#[test]
fn bent_tube() {
    print(&check_synthetic(
        "synthetic_bent_tube_r3.5",
        "bent_tube_r3.5",
    ));
}

#[test]
fn ellipsoid() {
    print(&check_synthetic(
        "synthetic_ellipsoid_30_20_12",
        "ellipsoid_30_20_12",
    ));
}

#[test]
fn real_meshes() {
    let mut table = Vec::new();
    for name in [
        "real/fsaverage_head_scalp_mne.ply",
        "real/fsaverage5_pial_left.ply",
        "segmentations/seg_mni152_brainmask_2mm.ply",
    ] {
        table.extend(check_mesh(name));
    }
    print(&table);
}

#[test]
fn local_search_on_the_grid_matches_a_real_run() {
    let (mesh, topology) = data::load("synthetic/synthetic_bent_tube_r3.5.ply");
    let original = Original::new(&mesh, &topology);
    let g = grid(&original, Filter::Taubin);
    for tau in TAUS {
        assert_eq!(
            local_on_grid(&g, tau),
            local(&original, Filter::Taubin, tau)
        );
    }
}

#[test]
fn measuring_along_one_run_equals_separate_runs() {
    let (mesh, topology) = data::load("synthetic/synthetic_bent_tube_r3.5.ply");
    let original = Original::new(&mesh, &topology);
    let mut ev = MeshEvaluator::new(&original, None).expect("no weights");
    for filter in [Filter::Laplace, Filter::Taubin, Filter::Hc] {
        let p = Params::defaults(filter);
        let along = ev.measure(&p, &[0, 3, 10]).expect("measured at once");
        assert_eq!(along.len(), 3);
        assert_eq!(along[0].curvature_ratio, 1.0);
        assert_eq!(along[0].mean_error, 0.0);
        for (k, t) in [(3, along[1]), (10, along[2])] {
            let alone = ev.measure(&p, &[k]).expect("measured at once");
            assert_eq!(alone, vec![t], "{filter} {k}");
            // And the same as smoothing and measuring by hand.
            let mut q = p;
            q.iterations = k;
            let mut drift = DriftingReference::new(&original);
            let pos = smooth(&mesh, &topology, &q, None, &mut drift);
            let m = meshsmooth::metrics::measure(&original, &pos, drift.reference(), 0.5);
            let roughness = original.roughness_ratio(&pos);
            assert!(roughness < 1.0, "{filter} {k}: the defaults smooth");
            assert_eq!(meshsmooth::suggest::terms_of(&m, roughness), t);
            assert!((t.score(0.5) - m.score).abs() < 1e-12);
        }
        assert!(along[2].curvature_ratio < 1.0 && along[2].mean_error > 0.0);
    }
}

#[test]
fn weights_and_bound_reach_every_run() {
    let (mesh, topology) = data::load("synthetic/synthetic_bent_tube_r3.5.ply");
    let original = Original::new(&mesh, &topology);
    // All vertices locked: nothing can move, whatever the parameters.
    let locked = vec![0.0f32; mesh.vertex_count()];
    let mut ev = MeshEvaluator::new(&original, Some(&locked)).expect("weights fit");
    let task =
        LocalSearch::new(Filter::Laplace, &Params::defaults(Filter::Laplace), 0.9).expect("valid");
    let s = run(task, &mut ev, &mut |_| true)
        .expect("not cancelled")
        .suggestion;
    assert_eq!(s.terms.mean_error, 0.0);
    assert_eq!(s.terms.curvature_ratio, 1.0);
    // A displacement bound caps the error of every grid point.
    let mut bounded = Params::defaults(Filter::Laplace);
    bounded.max_displacement = Some(0.1);
    let mut ev = MeshEvaluator::new(&original, None).expect("no weights");
    let g = run(
        GridSearch::new(Filter::Laplace, &bounded).expect("valid"),
        &mut ev,
        &mut |_| true,
    )
    .expect("not cancelled");
    assert!(g.points.iter().all(|(_, t)| t.mean_error <= 0.1 + 1e-6));
    assert_eq!(
        g.best(0.5).expect("grid").params.max_displacement,
        Some(0.1)
    );
    // Weights that do not fit are refused.
    assert!(MeshEvaluator::new(&original, Some(&locked[1..])).is_err());
}

#[test]
fn quality_graphs_on_a_real_mesh() {
    let (mesh, topology) = data::load("real/fsaverage_head_scalp_mne.ply");
    let original = Original::new(&mesh, &topology);
    let mut ev = MeshEvaluator::new(&original, None).expect("no weights");
    let p = Params::defaults(Filter::Hc);
    let g = run(
        QualitySweep::new(&p, 0.5).expect("valid"),
        &mut ev,
        &mut |_| true,
    )
    .expect("not cancelled");
    assert_eq!(g.curves.len(), 3);
    let its = &g.curves[2];
    assert_eq!(its.samples.len(), 51);
    assert_eq!(its.samples[0].terms, Terms::UNCHANGED);
    // The sweep's iteration curve passes through the current setting's value.
    let at_current = ev.measure(&p, &[p.iterations]).expect("measured at once");
    assert_eq!(its.samples[p.iterations as usize].terms, at_current[0]);
    // More HC iterations smooth more here.
    assert!(its.samples[50].terms.curvature_ratio < its.samples[5].terms.curvature_ratio);
}

/// Smooths `name` with `params` (no drift) and returns R/R0.
fn roughness_after(original: &Original, params: &Params) -> f64 {
    let positions = smooth(
        original.mesh(),
        original.topology(),
        params,
        None,
        &mut NoObserver,
    );
    original.roughness_ratio(&positions)
}

fn with(filter: Filter, a: f32, b: f32, iterations: u32) -> Params {
    let mut p = Params::defaults(filter);
    p.iterations = iterations;
    match filter {
        Filter::Hc => (p.alpha, p.beta) = (a, b),
        _ => (p.lambda, p.mu) = (a, b),
    }
    p
}

/// HC with alpha = beta = 0 amplifies the highest frequencies of the umbrella operator
/// (`q <- q - L^2 q`), and so does Taubin with lambda 0.1 and mu -0.4 (its factor at the top of
/// the spectrum is 0.8 x 1.8): on every shared mesh they leave it rougher than it was, while
/// each filter at its defaults leaves it smoother.
#[test]
fn diverging_parameters_roughen_every_shared_mesh_and_the_defaults_never_do() {
    for (name, _) in data::CLOSED_MESHES {
        let (mesh, topology) = data::load(name);
        let original = Original::new(&mesh, &topology);
        for p in [
            with(Filter::Hc, 0.0, 0.0, 50),
            with(Filter::Taubin, 0.1, -0.4, 15),
        ] {
            let r = roughness_after(&original, &p);
            assert!(r > 1.0, "{name} {p:?}: R/R0 {r}");
        }
        for filter in Filter::ALL {
            let r = roughness_after(&original, &Params::defaults(filter));
            assert!(r < 1.0, "{name} {filter}: R/R0 {r}");
        }
    }
}

/// On the large staircase brain, HC at alpha = beta = 0 and 50 iterations blows the mesh up
/// (mean error tens of mm), yet its S at tau 0.5 beats that of the set the searches suggest
/// there: curvature falls as the mesh grows and E/(E+1) saturates. The rank puts it last.
#[test]
fn the_blown_up_brain_scores_lower_but_ranks_last() {
    let (mesh, topology) = data::load(data::LARGE);
    let original = Original::new(&mesh, &topology);
    let terms = |p: &Params| {
        let mut drift = DriftingReference::new(&original);
        let positions = smooth(&mesh, &topology, p, None, &mut drift);
        let m = meshsmooth::metrics::measure(&original, &positions, drift.reference(), 0.5);
        (m, original.roughness_ratio(&positions))
    };
    let (blown, blown_r) = terms(&with(Filter::Hc, 0.0, 0.0, 50));
    let (smoothed, smoothed_r) = terms(&with(Filter::Hc, 0.2, 0.7, 5));
    assert!(
        blown.mean_error > 10.0 && blown_r > 1000.0,
        "{blown:?} {blown_r}"
    );
    assert!(smoothed.mean_error < 0.1 && smoothed_r < 0.5);
    assert!(
        blown.score < smoothed.score,
        "the score alone would pick the blown-up mesh"
    );
    let rank = |m, r| meshsmooth::suggest::terms_of(m, r).rank(0.5);
    assert!(rank(&smoothed, smoothed_r) < rank(&blown, blown_r));
}
