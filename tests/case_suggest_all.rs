//! "Suggest all" in the engine: each structure's own suggestion, cancelling, the surfaces
//! against the phantom's analytic truth, and the learned search against the full grid.

use meshsmooth::case::{self, suggest_all, SuggestAllOptions, SuggestAllSearch};
use serde_json::Value;

#[path = "common/label_maps.rs"]
mod label_maps;

use label_maps::{assert_relations_kept, inside_shape, phantom_case as phantom, read};

#[test]
fn suggest_all_gives_each_structure_its_own_parameters_and_can_be_cancelled() {
    let mut case = phantom();
    let before = case.clone();
    let options = SuggestAllOptions {
        tau: 0.5,
        filter: None,
        search: SuggestAllSearch::Local,
        max_volume_change: None,
    };
    let cancelled = suggest_all(&mut case, &options, &|_| false).expect("no error");
    assert!(cancelled.iter().all(Option::is_none));
    assert_eq!(
        case, before,
        "a cancelled run leaves every structure as it was"
    );

    let suggestions = suggest_all(&mut case, &options, &|_| true).expect("suggests");
    for (s, suggestion) in case.structures.iter().zip(&suggestions) {
        let suggestion = suggestion.as_ref().expect("every structure has vertices");
        assert_eq!(s.params, suggestion.params);
        assert_eq!(
            s.params.max_displacement,
            s.default_bound(),
            "the bound is kept"
        );
        let smoothed = s.smoothed.as_ref().expect("smoothed");
        assert_ne!(smoothed.positions, s.original.positions);
        assert_eq!(smoothed.metrics.score, suggestion.score, "{}", s.name);
    }
}

/// The phantom's truth: each label is its shape less the shapes listed after it.
struct Truth {
    shapes: Vec<Value>,
    affine: [[f64; 4]; 3],
    spacing: [f64; 3],
}

impl Truth {
    fn load() -> Self {
        let truth: Value =
            serde_json::from_slice(&read("labelmaps/case_phantom_shared.json")).expect("JSON");
        let a = &truth["affine_ras"];
        Self {
            shapes: truth["structures"].as_array().expect("structures").clone(),
            affine: std::array::from_fn(|r| std::array::from_fn(|c| a[r][c].as_f64().expect("n"))),
            spacing: std::array::from_fn(|k| truth["spacing_mm"][k].as_f64().expect("n")),
        }
    }

    /// Whether world point `w` lies in structure `index` (the affine is diagonal).
    fn inside(&self, index: usize, w: [f64; 3]) -> bool {
        let p: [f64; 3] = std::array::from_fn(|k| {
            (w[k] - self.affine[k][3]) / self.affine[k][k] * self.spacing[k]
        });
        inside_shape(&self.shapes[index]["shape"], p)
            && !self.shapes[index + 1..]
                .iter()
                .any(|later| inside_shape(&later["shape"], p))
    }

    /// Distance from `q` to the structure's true surface, by the nearest change of side along
    /// 26 directions (marched in 0.1 mm steps to 4 mm, then bisected): an upper bound, the
    /// same estimator before and after smoothing. Points farther than 4 mm count as 4 mm.
    fn distance(&self, index: usize, q: [f32; 3], directions: &[[f64; 3]]) -> f64 {
        let q = q.map(f64::from);
        let at = |d: &[f64; 3], t: f64| -> [f64; 3] { std::array::from_fn(|k| q[k] + t * d[k]) };
        let side = self.inside(index, q);
        let mut best: f64 = 4.0;
        for d in directions {
            let mut t = 0.1;
            while t < best {
                if self.inside(index, at(d, t)) != side {
                    let (mut lo, mut hi) = (t - 0.1, t);
                    for _ in 0..20 {
                        let mid = 0.5 * (lo + hi);
                        if self.inside(index, at(d, mid)) == side {
                            lo = mid;
                        } else {
                            hi = mid;
                        }
                    }
                    best = best.min(hi);
                    break;
                }
                t += 0.1;
            }
        }
        best
    }
}

/// The mean over (at most about 3000, evenly strided) vertices.
fn mean_true_error(truth: &Truth, index: usize, positions: &[[f32; 3]]) -> f64 {
    use rayon::prelude::*;
    let mut directions = Vec::new();
    for x in -1i32..=1 {
        for y in -1i32..=1 {
            for z in -1i32..=1 {
                let d = [x, y, z].map(f64::from);
                let n = d.iter().map(|c| c * c).sum::<f64>().sqrt();
                if n > 0.0 {
                    directions.push(d.map(|c| c / n));
                }
            }
        }
    }
    let stride = positions.len().div_ceil(3000);
    let sample: Vec<[f32; 3]> = positions.iter().step_by(stride).copied().collect();
    let sum: f64 = sample
        .par_iter()
        .map(|&q| truth.distance(index, q, &directions))
        .sum();
    sum / sample.len() as f64
}

/// `case build` at tau 0.5 on the phantom: every structure's surface comes closer to its
/// analytic shape than the staircase was, and the checks between structures hold.
#[test]
fn suggest_all_at_tau_half_brings_every_phantom_surface_closer_to_the_truth() {
    let truth = Truth::load();
    let mut case = phantom();
    let before = case::check(&case, false);
    let options = SuggestAllOptions {
        tau: 0.5,
        filter: None,
        search: SuggestAllSearch::Grid,
        max_volume_change: Some(0.05),
    };
    suggest_all(&mut case, &options, &|_| true).expect("suggests");
    let after = case::check(&case, true);
    println!(
        "{:<14} {:>5} {:>14} {:>14} {:>9}",
        "structure", "iter", "true error 0", "true error", "volume %"
    );
    for (index, s) in case.structures.iter().enumerate() {
        let smoothed = s.smoothed.as_ref().expect("smoothed");
        let e0 = mean_true_error(&truth, index, &s.original.positions);
        let e = mean_true_error(&truth, index, &smoothed.positions);
        let dv = smoothed.metrics.volume_change.expect("closed");
        println!(
            "{:<14} {:>5} {:>11.4} mm {:>11.4} mm {:>+9.2}",
            s.name,
            s.params.iterations,
            e0,
            e,
            100.0 * dv
        );
        assert!(e < e0, "{}: true error {e} mm, unsmoothed {e0} mm", s.name);
        assert!(dv.abs() <= 0.05, "{}: volume change {dv}", s.name);
    }
    let tumour_in_liver = before
        .iter()
        .find(|r| (r.a, r.b) == (0, 2))
        .expect("the liver and the tumour meet");
    assert!(tumour_in_liver.b_inside_a && !tumour_in_liver.a_inside_b);
    let changes = meshsmooth::case::relations::changes(&before, &after);
    println!("{}", case::checks_text(&case, &before, &after, &changes));
    assert_relations_kept(&changes);
}

/// The learned search (each structure's local search starting where smaller structures'
/// searches ended) finds each phantom structure's score within 1% of the full grid's minimum.
#[test]
fn the_learned_search_lands_within_one_percent_of_the_grid_on_the_phantom() {
    let run = |search| {
        let mut case = phantom();
        let options = SuggestAllOptions {
            tau: 0.5,
            filter: None,
            search,
            max_volume_change: Some(0.05),
        };
        let suggestions = suggest_all(&mut case, &options, &|_| true).expect("suggests");
        suggestions
            .into_iter()
            .map(|s| s.expect("every structure suggested"))
            .collect::<Vec<_>>()
    };
    let grid = run(SuggestAllSearch::Grid);
    let learned = run(SuggestAllSearch::Learned);
    let (grid_sets, learned_sets): (usize, usize) = (
        grid.iter().map(|s| s.evaluations).sum(),
        learned.iter().map(|s| s.evaluations).sum(),
    );
    for (g, l) in grid.iter().zip(&learned) {
        println!(
            "S grid {:.5} learned {:.5} {:?}",
            g.score, l.score, l.params
        );
        assert!(l.score <= g.score * 1.01, "{} above {}", l.score, g.score);
    }
    assert!(
        5 * learned_sets < grid_sets,
        "{learned_sets} sets against the grid's {grid_sets}"
    );
}
