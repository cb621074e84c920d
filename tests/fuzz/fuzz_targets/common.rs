//! What every target checks: a parser either refuses the input or returns a mesh whose indices
//! are in range and whose coordinates are finite, on which topology and the report can be built.

use meshsmooth::io::{load_as, Format};
use meshsmooth::mesh::{MeshReport, Topology};

pub fn check(data: &[u8], format: Format) {
    let Ok(mesh) = load_as(data, format) else {
        return;
    };
    let n = mesh.positions.len();
    assert!(!mesh.triangles.is_empty(), "a loaded mesh has triangles");
    assert!(
        mesh.triangles.iter().flatten().all(|&v| (v as usize) < n),
        "every index is in range"
    );
    assert!(
        mesh.positions.iter().flatten().all(|c| c.is_finite()),
        "every coordinate is finite"
    );
    let topology = Topology::build(&mesh);
    let report = MeshReport::new(&mesh, &topology);
    assert_eq!(report.faces, mesh.triangles.len());
}
