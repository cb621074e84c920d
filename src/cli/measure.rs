//! `meshsmooth measure ORIGINAL SMOOTHED [--tau T] [--exact] [--json]`.

use crate::mesh::Topology;
use crate::metrics::{self, DriftingReference, Metrics, Original, TriangleBvh};
use std::path::Path;

/// Reference hops allowed when the smoothing history is unknown (see `run`).
const MAX_DRIFT_STEPS: usize = 1000;

pub(super) fn run(
    original: &Path,
    smoothed: &Path,
    tau: f64,
    exact: bool,
    json: bool,
) -> Result<(), String> {
    super::check_tau(tau)?;
    let mesh = super::load_file(original)?;
    let other = super::load_file(smoothed)?;
    if other.vertex_count() != mesh.vertex_count() || other.triangles != mesh.triangles {
        return Err(format!(
            "{} and {} are not the same mesh: measure needs the same vertices in the same order \
             and the same triangles ({} vs {} vertices, {} vs {} triangles)",
            original.display(),
            smoothed.display(),
            mesh.vertex_count(),
            other.vertex_count(),
            mesh.triangle_count(),
            other.triangle_count()
        ));
    }
    let topology = Topology::build(&mesh);
    let reference_mesh = Original::new(&mesh, &topology);
    // The smoothing steps are unknown here, so the reference drifts one hop at a time towards
    // each vertex's final position until no reference moves.
    let mut drift = DriftingReference::new(&reference_mesh);
    for _ in 0..MAX_DRIFT_STEPS {
        let before = drift.reference().to_vec();
        drift.update(&other.positions);
        if drift.reference() == before.as_slice() {
            break;
        }
    }
    let mut m = metrics::measure(&reference_mesh, &other.positions, drift.reference(), tau);
    if exact {
        let bvh = TriangleBvh::new(&mesh.positions, &mesh.triangles);
        m = m.with_exact(metrics::exact_error(
            &bvh,
            &reference_mesh,
            &other.positions,
        ));
    }
    if json {
        outln!("{}", super::to_json(&m)?);
    } else {
        out!("{}", text(&m));
    }
    Ok(())
}

/// The measures as aligned text lines.
pub(super) fn text(m: &Metrics) -> String {
    let mut s = String::new();
    match (m.volume, m.volume0, m.volume_change) {
        (Some(v), Some(v0), Some(dv)) => {
            s += &format!(
                "volume        {v:.3} (original {v0:.3}, change {:+.3}%)\n",
                dv * 100.0
            )
        }
        _ => s += "volume        undefined: the mesh is open\n",
    }
    let ratio = if m.curvature0 > 0.0 {
        m.curvature / m.curvature0
    } else {
        f64::NAN
    };
    s += &format!(
        "curvature K   {:.6} (original {:.6}, K/K0 {ratio:.4})\n",
        m.curvature, m.curvature0
    );
    s += &format!(
        "local error   mean {:.4}, max {:.4}\n",
        m.mean_error, m.max_error
    );
    if let (Some(mean), Some(max)) = (m.exact_mean_error, m.exact_max_error) {
        s += &format!("exact error   mean {mean:.4}, max {max:.4}\n");
    }
    s += &format!("score S       {:.6}\n", m.score);
    s
}
