//! An original that stands in for a larger closed surface: a part of it (patches cut out of
//! the whole), smoothed with the part's rim locked and measured over its inner vertices only,
//! so that its measures estimate the whole's. The curvature and the local error are means,
//! which the inner vertices estimate directly. The volume change is not: the part encloses
//! nothing. It is taken to first order from the inner vertices' displacement along their area
//! vectors (a third of their triangles' cross products), scaled from their area to the whole's
//! and set against the whole's volume.

use super::Original;
use crate::mesh::{cross, dot, sub, to_f64, Mesh, Topology};
use serde::{Deserialize, Serialize};

/// What an original standing in for a whole surface measures with.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub(crate) struct StandIn {
    /// 1 for the vertices measured, 0 for those only smoothed.
    #[serde(with = "crate::mesh::flat_bytes")]
    measured: Vec<u8>,
    /// Per vertex, a third of the sum of its triangles' `(b - a) x (c - a) / 2` on the
    /// original: the volume a unit displacement sweeps, to first order.
    #[serde(with = "crate::mesh::flat_bytes")]
    area_vectors: Vec<[f32; 3]>,
    /// The whole surface's area over the measured vertices' area.
    scale: f64,
}

impl StandIn {
    #[inline]
    pub(crate) fn measures(&self, i: usize) -> bool {
        self.measured[i] != 0
    }

    /// The measured vertex `i`'s volume swept, moved from `o` to `q`.
    #[inline]
    pub(crate) fn swept(&self, i: usize, o: [f32; 3], q: [f32; 3]) -> f64 {
        let a = self.area_vectors[i];
        (0..3)
            .map(|k| f64::from(a[k]) * f64::from(q[k] - o[k]))
            .sum()
    }

    /// The whole's volume change from the measured vertices' swept volume.
    pub(crate) fn volume_change(&self, swept: f64) -> f64 {
        swept * self.scale
    }
}

impl Original {
    /// The original of `part` (a piece of a closed surface whose volume is `volume0` and area
    /// `area`), measured over the vertices `measured` marks and reporting the whole's volume
    /// estimated from them. `topology` must be `Topology::build(part)`.
    ///
    /// # Panics
    /// When `measured` has not one entry per vertex of `part`.
    pub fn standing_in(
        part: &Mesh,
        topology: &Topology,
        measured: &[bool],
        (volume0, area): (f64, f64),
    ) -> Self {
        assert_eq!(measured.len(), part.vertex_count(), "one flag per vertex");
        let (area_vectors, areas) = vertex_areas(part);
        let inner: f64 = (measured.iter().zip(&areas))
            .filter(|(m, _)| **m)
            .map(|(_, a)| a)
            .sum();
        let stand_in = StandIn {
            measured: measured.iter().map(|&m| u8::from(m)).collect(),
            area_vectors,
            scale: if inner > 0.0 { area / inner } else { 0.0 },
        };
        Original::build(part, topology, Some((stand_in, volume0)))
    }
}

/// Each vertex's area vector (a third of its triangles' vector areas) and area (a third of
/// theirs).
fn vertex_areas(mesh: &Mesh) -> (Vec<[f32; 3]>, Vec<f64>) {
    let n = mesh.vertex_count();
    let (mut vectors, mut areas) = (vec![[0.0f64; 3]; n], vec![0.0f64; n]);
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|v| to_f64(mesh.positions[v as usize]));
        let cross = cross(sub(b, a), sub(c, a));
        let area = dot(cross, cross).sqrt() / 2.0;
        for &i in t {
            let i = i as usize;
            for k in 0..3 {
                vectors[i][k] += cross[k] / 6.0;
            }
            areas[i] += area / 3.0;
        }
    }
    (vectors.iter().map(|s| s.map(|x| x as f32)).collect(), areas)
}
