//! Searching a large surface on patches of it first. A search smooths the surface some sixty
//! times; on a structure of a quarter million vertices that is most of a whole-body case's
//! time. Its measures are means over the surface (curvature, local error) and a volume change,
//! which a few patches spread over the surface estimate well: the search runs on the patches,
//! and the search on the whole surface then starts where theirs ended, so it measures few sets
//! before it stops at a local minimum of the whole.
//!
//! A patch is every vertex within a number of edge rings of a seed, the seeds spread by
//! farthest-point sampling. Smoothing moves information a few rings per iteration at most, so
//! the patches' rims get weight 0 and only the vertices well inside them are measured
//! ([`Original::standing_in`]): the rims hold the patches in place, and what reaches the
//! measured vertices from them in the grid's iterations is small for the smoothing the
//! searches pick.

use crate::mesh::{cross, dot, sub, to_f64, Mesh, Topology};
use crate::metrics::Original;

/// Surfaces with more vertices than this are searched on patches.
pub const PATCHES_ABOVE: usize = 30_000;

/// Patches taken, and their size in edge rings around the seed: measured, then only smoothed.
const PATCHES: usize = 8;
const MEASURED_RINGS: u32 = 10;
const MARGIN_RINGS: u32 = 8;

/// Patches of a surface, ready to be searched on in its stead.
pub struct Patches {
    /// The patches as one open surface, measured as standing in for the whole.
    pub original: Original,
    /// The surface's weights on the patches, 0 on their rims.
    pub weights: Vec<f32>,
}

impl Patches {
    /// Patches of `original` (with per-vertex `weights`, when given) when it is a closed
    /// surface of more than [`PATCHES_ABOVE`] vertices; `None` otherwise.
    pub fn of(original: &Original, weights: Option<&[f32]>) -> Option<Patches> {
        let (mesh, topology) = (original.mesh(), original.topology());
        let volume0 = original.volume()?;
        if mesh.vertex_count() <= PATCHES_ABOVE || original.is_standing_in() {
            return None;
        }
        let rings = ring_distances(topology, &seeds(mesh, topology, PATCHES));
        let keep = |v: u32| rings[v as usize] <= MEASURED_RINGS + MARGIN_RINGS;
        let (part, kept) = mesh.part(|t| t.iter().all(|&v| keep(v)));
        let part_topology = Topology::build(&part);
        let measured: Vec<bool> = (kept.iter().enumerate())
            .map(|(j, &v)| rings[v as usize] <= MEASURED_RINGS && !part_topology.is_boundary[j])
            .collect();
        if !measured.contains(&true) {
            return None;
        }
        let weights = (kept.iter().enumerate())
            .map(|(j, &v)| match part_topology.is_boundary[j] {
                true => 0.0,
                false => weights.map_or(1.0, |w| w[v as usize]),
            })
            .collect();
        let whole = (volume0, area(mesh));
        let original = Original::standing_in(&part, &part_topology, &measured, whole);
        Some(Patches { original, weights })
    }
}

/// `count` vertices some triangle uses, spread over the surface: each the farthest (straight
/// line) from those before it, the first the farthest from the vertices' centroid.
fn seeds(mesh: &Mesh, topology: &Topology, count: usize) -> Vec<u32> {
    let used: Vec<u32> = (0..mesh.vertex_count() as u32)
        .filter(|&v| !topology.triangles_of(v as usize).is_empty())
        .collect();
    let p = |v: u32| to_f64(mesh.positions[v as usize]);
    let d2 = |a: [f64; 3], b: [f64; 3]| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>();
    let n = used.len().max(1) as f64;
    let centroid =
        (used.iter().map(|&v| p(v))).fold([0.0; 3], |c, q| [0, 1, 2].map(|k| c[k] + q[k] / n));
    let mut nearest: Vec<f64> = used.iter().map(|&v| d2(p(v), centroid)).collect();
    let mut seeds = Vec::with_capacity(count);
    while seeds.len() < count {
        let farthest = (nearest.iter().enumerate())
            .filter(|(_, d)| **d > 0.0)
            .max_by(|a, b| a.1.total_cmp(b.1));
        let Some((k, _)) = farthest else {
            break;
        };
        let seed = p(used[k]);
        seeds.push(used[k]);
        for (d, &v) in nearest.iter_mut().zip(&used) {
            *d = d.min(d2(p(v), seed));
        }
    }
    seeds
}

/// Each vertex's distance in edges from the nearest seed (`u32::MAX` where none reaches).
fn ring_distances(topology: &Topology, seeds: &[u32]) -> Vec<u32> {
    let mut rings = vec![u32::MAX; topology.vertex_count()];
    let mut front: Vec<u32> = seeds.to_vec();
    for &s in seeds {
        rings[s as usize] = 0;
    }
    let mut ring = 0;
    while !front.is_empty() && ring < MEASURED_RINGS + MARGIN_RINGS {
        ring += 1;
        let mut next = Vec::new();
        for &v in &front {
            for &w in topology.neighbors_of(v as usize) {
                if rings[w as usize] == u32::MAX {
                    rings[w as usize] = ring;
                    next.push(w);
                }
            }
        }
        front = next;
    }
    rings
}

/// The surface's area.
fn area(mesh: &Mesh) -> f64 {
    let doubled = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|v| to_f64(mesh.positions[v as usize]));
        let n = cross(sub(b, a), sub(c, a));
        dot(n, n).sqrt()
    };
    mesh.triangles.iter().map(doubled).sum::<f64>() / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::{Affine, LabelLayer, LabelMap};
    use crate::metrics::{measure, smooth_drifting};
    use crate::segmentation::{extract, ExtractOptions};
    use crate::smooth::{Filter, Params};

    /// The staircase surface of a voxel ellipsoid with semi-axes `r` (voxels).
    fn ellipsoid(r: [f64; 3]) -> Mesh {
        let dims = r.map(|x| 2 * x.ceil() as usize + 4);
        let inside = |i: usize, j: usize, k: usize| {
            let d = [i, j, k].into_iter().zip(dims).zip(r);
            d.map(|((x, n), a)| ((x as f64 - n as f64 / 2.0) / a).powi(2))
                .sum::<f64>()
                <= 1.0
        };
        let mut codes = Vec::with_capacity(dims.iter().product());
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    codes.push(u16::from(inside(i, j, k)));
                }
            }
        }
        let map = LabelMap {
            dims,
            affine: Affine::scaled([1.0; 3], [0.0; 3]),
            layers: vec![LabelLayer {
                codes,
                values: vec![0, 1],
            }],
            segments: Vec::new(),
            conventional: Vec::new(),
        };
        let options = ExtractOptions::default();
        let mut structures = extract(&map, &[], &options).expect("extracted");
        structures.remove(0).mesh
    }

    fn original(mesh: &Mesh) -> Original {
        Original::new(mesh, &Topology::build(mesh))
    }

    #[test]
    fn small_or_open_surfaces_are_searched_whole() {
        let small = ellipsoid([10.0, 8.0, 6.0]);
        assert!(small.vertex_count() < PATCHES_ABOVE);
        assert!(Patches::of(&original(&small), None).is_none());
        let large = ellipsoid([80.0, 64.0, 48.0]);
        let half = large.patch(&(0..large.vertex_count() as u32 / 2).collect::<Vec<_>>());
        assert!(half.vertex_count() > PATCHES_ABOVE);
        assert!(
            Patches::of(&original(&half), None).is_none(),
            "open: no volume"
        );
    }

    #[test]
    fn patches_are_a_small_part_with_their_rims_locked() {
        let mesh = ellipsoid([80.0, 64.0, 48.0]);
        let whole = original(&mesh);
        assert!(
            mesh.vertex_count() > 2 * PATCHES_ABOVE,
            "{}",
            mesh.vertex_count()
        );
        let mut weights = vec![1.0; mesh.vertex_count()];
        weights[..100].iter_mut().for_each(|w| *w = 0.5);
        let p = Patches::of(&whole, Some(&weights)).expect("patches");
        let part = p.original.mesh();
        assert!(
            part.vertex_count() < PATCHES_ABOVE / 2,
            "{}",
            part.vertex_count()
        );
        assert!(p.original.is_standing_in());
        assert_eq!(p.original.volume(), whole.volume());
        let rim = &p.original.topology().is_boundary;
        assert!(rim.contains(&true));
        for (j, &w) in p.weights.iter().enumerate() {
            assert!(if rim[j] { w == 0.0 } else { w > 0.0 }, "vertex {j}: {w}");
        }
        // The whole's weights carried over: its vertices keep them, found by position.
        for (j, q) in part.positions.iter().enumerate() {
            let v = mesh
                .positions
                .iter()
                .position(|p| p == q)
                .expect("a vertex of the whole");
            if !rim[j] {
                assert_eq!(p.weights[j], weights[v]);
            }
        }
        // The unchanged patches measure the unchanged whole.
        let unchanged = measure(
            &p.original,
            &part.positions,
            &crate::metrics::identity(part.vertex_count()),
            0.5,
        );
        assert_eq!(unchanged.volume_change, Some(0.0));
        assert_eq!(unchanged.curvature, unchanged.curvature0);
    }

    /// The patches' measures of a smoothing estimate the whole's.
    #[test]
    fn patches_measure_like_the_whole() {
        let mesh = ellipsoid([80.0, 64.0, 48.0]);
        let whole = original(&mesh);
        let p = Patches::of(&whole, None).expect("patches");
        let hc = |alpha, beta, iterations| Params {
            alpha,
            beta,
            iterations,
            ..Params::defaults(Filter::Hc)
        };
        let laplace = Params {
            iterations: 30,
            ..Params::defaults(Filter::Laplace)
        };
        for params in [
            hc(0.0, 0.5, 10),
            hc(0.1, 0.6, 30),
            hc(0.3, 0.3, 50),
            laplace,
        ] {
            let measured = |o: &Original, weights: Option<&[f32]>| {
                let (positions, reference) = smooth_drifting(o, &params, weights);
                measure(o, &positions, &reference, 0.5)
            };
            let (a, b) = (
                measured(&whole, None),
                measured(&p.original, Some(&p.weights)),
            );
            let near = |x: f64, y: f64, by: f64| (x - y).abs() <= by * x.abs();
            let k = |m: &crate::metrics::Metrics| m.curvature / m.curvature0;
            let said = format!("{params:?}: whole {a:?}\npatches {b:?}");
            // The curvature is the noisiest: its mean over a staircase leans on few vertices.
            assert!(near(k(&a), k(&b), 0.3), "K/K0: {said}");
            assert!(near(a.score, b.score, 0.15), "S: {said}");
            assert!(near(a.mean_error, b.mean_error, 0.2), "E: {said}");
            let (va, vb) = (a.volume_change.unwrap(), b.volume_change.unwrap());
            assert!(
                (va - vb).abs() <= 0.001 + 0.15 * va.abs(),
                "volume change: {said}"
            );
        }
    }

    /// Suggest all's search of a large structure: on its patches, then on the whole from where
    /// that one ended. It ends at a local minimum of the whole, as good as the whole's own
    /// local search from the corners, and counts the sets measured on both.
    #[test]
    fn a_large_structure_is_searched_on_its_patches_then_whole() {
        use crate::case::{suggest_structure, CaseStructure, SuggestAllOptions};
        use crate::suggest::SearchMethod;
        use crate::suggest::{search_evaluator, suggest_for_goal, suggest_from, Goal};
        let mesh = ellipsoid([80.0, 64.0, 48.0]);
        let goal = Goal {
            tau: 0.5,
            max_volume_change: Some(0.05),
        };
        let options = SuggestAllOptions {
            tau: goal.tau,
            filter: None,
            search: crate::case::SuggestAllSearch::Learned,
            max_volume_change: goal.max_volume_change,
        };
        let base = Params::defaults(Filter::Hc);
        let mut s = CaseStructure::from_mesh("ellipsoid", mesh.clone(), [1.0; 3]);
        s.set_params(base);
        let found = suggest_structure(&mut s, &options, &[], &mut |_| true);
        let found = found.expect("suggested").expect("not empty");
        assert_eq!(s.params, found.params);

        let whole = original(&mesh);
        let method = SearchMethod::Local;
        let mut evaluator = search_evaluator(&whole, None, Filter::Hc, method).expect("evaluator");
        let own = suggest_for_goal(&mut evaluator, &base, goal, method, &mut |_| true);
        let own = own.expect("the whole's own search");
        assert!(
            found.score <= own.score * 1.01,
            "{found:?}\nthe whole's own: {own:?}"
        );
        let again = suggest_from(&mut evaluator, &base, goal, &[found.params], &mut |_| true);
        let again = again.expect("a search from there");
        assert_eq!(again.params, found.params, "a local minimum of the whole");
        assert!(
            found.evaluations > again.evaluations,
            "the patches' sets counted too"
        );
    }
}
