//! One measure pass over a smoothed mesh and the report it yields: volume, curvature, local
//! error and the score, plus per-vertex arrays for colour-coding.

use super::curvature::{triangle_shapes, triangle_shapes_into, CornerShape, VertexCurvature};
use super::exact_distance::TriangleBvh;
use super::local_error::{local_errors, vertex_local_error};
use super::score::ScoreTerms;
use super::Original;
use crate::mesh::to_f64;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::cell::RefCell;

/// Vertices per parallel work item. Partial sums are combined in chunk order, so every result
/// is bit-for-bit the same whatever the thread count (ties in parameter searches stay ties).
const CHUNK: usize = 2048;

/// The measures of a smoothed mesh against its original. Serialises to the keys of
/// `meshsmooth measure --json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    /// Enclosed volume V (mesh units cubed); `null` for an open mesh.
    pub volume: Option<f64>,
    /// V0 of the original; `null` for an open mesh.
    pub volume0: Option<f64>,
    /// Signed relative change `(V - V0) / V0`; `null` where V0 is undefined or 0.
    pub volume_change: Option<f64>,
    /// K: mean `|K_G|` over interior vertices (1 / mesh units squared).
    pub curvature: f64,
    /// K0 of the original.
    pub curvature0: f64,
    /// E: mean local error over the vertices some triangle uses (mesh units).
    pub mean_error: f64,
    pub max_error: f64,
    /// S(tau), lower is better.
    pub score: f64,
    /// Mean exact distance to the original, when asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exact_mean_error: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exact_max_error: Option<f64>,
}

impl Metrics {
    /// The two halves of the score, for scoring the same result at another `tau`.
    pub fn score_terms(&self) -> ScoreTerms {
        ScoreTerms::new(
            self.curvature,
            self.curvature0,
            self.mean_error,
            self.volume,
            self.volume0,
        )
    }

    /// Adds the exact distances (see [`exact_error`]).
    pub fn with_exact(mut self, exact: ErrorSummary) -> Self {
        self.exact_mean_error = Some(exact.mean);
        self.exact_max_error = Some(exact.max);
        self
    }
}

/// Per-vertex measures for colour-coding, one entry per vertex of the mesh.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct VertexMeasures {
    /// Local error (mesh units); 0 for vertices no triangle uses.
    pub local_error: Vec<f32>,
    /// `K_G`; 0 where it is left out of K (boundary, unreferenced, no area).
    pub gaussian_curvature: Vec<f32>,
}

/// Mean and maximum of a per-vertex distance.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ErrorSummary {
    pub mean: f64,
    pub max: f64,
}

/// Measures `positions` (the smoothed mesh M', one per original vertex) against the original.
/// `reference` holds each vertex's drifted reference vertex ([`super::DriftingReference`]);
/// `tau` weighs the score.
pub fn measure(
    original: &Original,
    positions: &[[f32; 3]],
    reference: &[u32],
    tau: f64,
) -> Metrics {
    let sums = measure_pass(original, positions, Some(reference));
    metrics(original, &sums, tau)
}

/// The curvature and volume measures of `positions` without the local error, which needs the
/// drifting reference along the run and costs about half of a pass: `mean_error` and
/// `max_error` are 0, below their true values, and every other field is exactly [`measure`]'s.
/// So the score is a lower bound of the full measure's, for searches that rule parameter sets
/// out before measuring them fully.
pub fn measure_shape(original: &Original, positions: &[[f32; 3]], tau: f64) -> Metrics {
    let sums = measure_pass(original, positions, None);
    metrics(original, &sums, tau)
}

/// [`measure`], also filling the per-vertex arrays, in the same pass.
pub fn measure_vertices(
    original: &Original,
    positions: &[[f32; 3]],
    reference: &[u32],
    tau: f64,
) -> (Metrics, VertexMeasures) {
    let n = check_arrays(original, positions, Some(reference));
    let (corners, volume6) = triangle_shapes(positions, &original.mesh().triangles);
    let pass = Pass {
        original,
        positions,
        reference: Some(reference),
        corners: &corners,
    };
    let mut vertex = VertexMeasures {
        local_error: vec![0.0; n],
        gaussian_curvature: vec![0.0; n],
    };
    let partial: Vec<Sums> = vertex
        .local_error
        .par_chunks_mut(CHUNK)
        .zip(vertex.gaussian_curvature.par_chunks_mut(CHUNK))
        .enumerate()
        .map(|(c, (e, k))| pass.chunk(c * CHUNK, Some((e, k))))
        .collect();
    let sums = total_of(volume6, &partial);
    (metrics(original, &sums, tau), vertex)
}

/// Exact distance from each vertex of `positions` to the original mesh, summarised over the same
/// vertices as the local error. `bvh` is `TriangleBvh::new` over the original mesh.
pub fn exact_error(bvh: &TriangleBvh, original: &Original, positions: &[[f32; 3]]) -> ErrorSummary {
    let topology = original.topology();
    let distances = exact_distances(bvh, original, positions);
    let (mut sum, mut max) = (0.0, 0.0f64);
    for (i, d) in distances.iter().enumerate() {
        if !topology.triangles_of(i).is_empty() {
            sum += d;
            max = max.max(*d);
        }
    }
    ErrorSummary {
        mean: mean(sum, original.referenced_vertices()),
        max,
    }
}

/// Exact distance from each vertex of `positions` to the original mesh, in parallel; 0 for
/// vertices no triangle uses (they never move). The distance to the vertex's own original fan
/// (the local error with the reference at home) is a distance to part of the mesh, so it bounds
/// each search from above and lets it skip most of the tree.
pub fn exact_distances(bvh: &TriangleBvh, original: &Original, positions: &[[f32; 3]]) -> Vec<f64> {
    let n = original.mesh().vertex_count();
    assert_eq!(
        positions.len(),
        n,
        "positions must belong to the original mesh"
    );
    let topology = original.topology();
    (0..n)
        .into_par_iter()
        .with_min_len(256)
        .map(|i| {
            if topology.triangles_of(i).is_empty() {
                return 0.0;
            }
            let q = to_f64(positions[i]);
            // A little slack: both distances are rounded, along different formulas.
            let bound = vertex_local_error(original, positions[i], i);
            let bound = bound * (1.0 + 1e-9) + 1e-12;
            bvh.closest_within(q, bound)
                .or_else(|| bvh.closest(q))
                .map_or(0.0, |c| c.distance)
        })
        .collect()
}

/// The report of a measure pass's totals (the GPU engine builds its totals from per-workgroup
/// partial sums and reports through here, so both engines derive the numbers alike).
pub(crate) fn metrics(original: &Original, sums: &Sums, tau: f64) -> Metrics {
    let volume0 = original.volume();
    let volume = match original.stand_in() {
        Some(s) => volume0.map(|v0| v0 + s.volume_change(sums.swept)),
        None => volume0.map(|_| sums.volume()),
    };
    let volume_change = match (volume, volume0) {
        (Some(v), Some(v0)) if v0 != 0.0 => Some((v - v0) / v0),
        _ => None,
    };
    let curvature = sums.curvature();
    let curvature0 = original.curvature();
    let mean_error = mean(sums.error_sum, sums.error_count);
    let score = ScoreTerms::new(curvature, curvature0, mean_error, volume, volume0).score(tau);
    Metrics {
        volume,
        volume0,
        volume_change,
        curvature,
        curvature0,
        mean_error,
        max_error: sums.error_max,
        score,
        exact_mean_error: None,
        exact_max_error: None,
    }
}

fn mean(sum: f64, count: usize) -> f64 {
    if count > 0 {
        sum / count as f64
    } else {
        0.0
    }
}

/// Partial sums of one measure pass.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Sums {
    volume6: f64,
    curvature_sum: f64,
    curvature_count: usize,
    error_sum: f64,
    error_max: f64,
    error_count: usize,
    /// The volume the measured vertices swept, standing in for a larger surface.
    swept: f64,
}

impl Sums {
    /// Totals summed elsewhere (the GPU engine's measure pass).
    #[cfg(feature = "gpu")]
    pub(crate) fn from_totals(
        volume6: f64,
        (curvature_sum, curvature_count): (f64, usize),
        (error_sum, error_max, error_count): (f64, f64, usize),
    ) -> Self {
        Self {
            volume6,
            curvature_sum,
            curvature_count,
            error_sum,
            error_max,
            error_count,
            swept: 0.0,
        }
    }

    fn add(&mut self, o: &Sums) {
        self.volume6 += o.volume6;
        self.curvature_sum += o.curvature_sum;
        self.curvature_count += o.curvature_count;
        self.error_sum += o.error_sum;
        self.error_max = self.error_max.max(o.error_max);
        self.error_count += o.error_count;
        self.swept += o.swept;
    }

    pub(crate) fn volume(&self) -> f64 {
        self.volume6 / 6.0
    }

    pub(crate) fn curvature(&self) -> f64 {
        mean(self.curvature_sum, self.curvature_count)
    }
}

/// Volume, curvature and local error in one pass over the vertices (`reference`: `None` leaves
/// the local error out), without per-vertex arrays ([`measure_vertices`] fills those).
pub(crate) fn measure_pass(
    original: &Original,
    positions: &[[f32; 3]],
    reference: Option<&[u32]>,
) -> Sums {
    thread_local! {
        /// The triangles' corners of the last pass on this thread: searches measure hundreds of
        /// times, and fresh memory each time costs its page faults.
        static CORNERS: RefCell<Vec<CornerShape>> = const { RefCell::new(Vec::new()) };
    }
    let n = check_arrays(original, positions, reference);
    let mut corners = CORNERS.take();
    let volume6 = triangle_shapes_into(positions, &original.mesh().triangles, &mut corners);
    let pass = Pass {
        original,
        positions,
        reference,
        corners: &corners,
    };
    let partial: Vec<Sums> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| pass.chunk(c * CHUNK, None))
        .collect();
    CORNERS.set(corners);
    total_of(volume6, &partial)
}

/// The vertex count, after checking that `positions` (and `reference`) have one entry per
/// vertex of the original.
fn check_arrays(original: &Original, positions: &[[f32; 3]], reference: Option<&[u32]>) -> usize {
    let n = original.mesh().vertex_count();
    assert_eq!(
        positions.len(),
        n,
        "positions must belong to the original mesh"
    );
    if let Some(r) = reference {
        assert_eq!(r.len(), n, "one reference vertex per vertex");
    }
    n
}

/// The volume plus the chunks' partial sums, added in chunk order (the same bit for bit
/// whatever the thread count).
fn total_of(volume6: f64, partial: &[Sums]) -> Sums {
    let mut total = Sums {
        volume6,
        ..Sums::default()
    };
    for p in partial {
        total.add(p);
    }
    total
}

/// What every chunk of a measure pass reads.
struct Pass<'a> {
    original: &'a Original,
    positions: &'a [[f32; 3]],
    /// Each vertex's drifted reference; `None`: no local error.
    reference: Option<&'a [u32]>,
    corners: &'a [CornerShape],
}

impl Pass<'_> {
    /// Curvature and local error of the vertices `start..start + CHUNK`.
    fn chunk(&self, start: usize, mut out: Option<(&mut [f32], &mut [f32])>) -> Sums {
        let mesh = self.original.mesh();
        let topology = self.original.topology();
        let end = (start + CHUNK).min(mesh.vertex_count());
        let mut s = Sums::default();
        let stand_in = self.original.stand_in();
        let measured = |i: usize| stand_in.is_none_or(|p| p.measures(i));
        for i in start..end {
            let fan = topology.triangles_of(i);
            if fan.is_empty() || !measured(i) {
                continue;
            }
            if let Some(p) = stand_in {
                s.swept += p.swept(i, mesh.positions[i], self.positions[i]);
            }
            let codes = self.original.corner_codes(i).iter();
            let c = VertexCurvature::of_fan(self.corners, codes.map(|c| c.index()));
            let mut k_g = 0.0;
            if !topology.is_boundary[i] {
                // A fan without area, or of vanishing area, has no meaningful curvature.
                if let Some(k) = c.gaussian() {
                    k_g = k;
                    s.curvature_sum += k.abs();
                    s.curvature_count += 1;
                }
            }
            if let Some((_, curvature)) = out.as_mut() {
                curvature[i - start] = k_g as f32;
            }
        }
        if let Some(reference) = self.reference {
            local_errors(
                self.original,
                self.positions,
                reference,
                start..end,
                |i, e| {
                    if !measured(i) {
                        return;
                    }
                    s.error_sum += e;
                    // A select, not `f64::max`, which wasm calls a function for (`error_max`
                    // is never NaN, so a NaN `e` is passed over as `max` does).
                    s.error_max = if e > s.error_max { e } else { s.error_max };
                    s.error_count += 1;
                    if let Some((error, _)) = out.as_mut() {
                        error[i - start] = e as f32;
                    }
                },
            );
        }
        s
    }
}

/// Serde for [`Metrics`] as its JSON text, for binary formats (postcard): its optional
/// exact-error fields are left out when absent, which a binary format cannot express. Use with
/// `#[serde(with = "crate::metrics::as_json_text")]`.
pub mod as_json_text {
    use super::Metrics;
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(metrics: &Metrics, serializer: S) -> Result<S::Ok, S::Error> {
        let text = serde_json::to_string(metrics).map_err(serde::ser::Error::custom)?;
        serializer.serialize_str(&text)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Metrics, D::Error> {
        let text = String::deserialize(deserializer)?;
        serde_json::from_str(&text).map_err(serde::de::Error::custom)
    }
}
