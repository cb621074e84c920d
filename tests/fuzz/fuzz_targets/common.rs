//! What every target checks: a parser either refuses the input or returns a mesh whose indices
//! are in range and whose coordinates are finite, on which topology and the report can be built.

use meshsmooth::io::{load_as, Format};
use meshsmooth::mesh::{MeshReport, Topology};

#[allow(dead_code)]
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

/// What the label-map targets check: a label map with finite affine and codes in range, whose
/// small enough maps give closed, manifold surfaces (or are refused).
#[allow(dead_code)]
pub fn check_label_map(map: &meshsmooth::io::LabelMap) {
    let voxels = map.voxel_count();
    assert!(
        map.affine.0.iter().flatten().all(|v| v.is_finite()),
        "a finite affine"
    );
    assert!(!map.layers.is_empty(), "at least one layer");
    for layer in &map.layers {
        assert_eq!(layer.codes.len(), voxels, "a code per voxel");
        assert_eq!(layer.values[0], 0, "code 0 is background");
        assert!(
            layer
                .codes
                .iter()
                .all(|&c| (c as usize) < layer.values.len()),
            "codes in range"
        );
    }
    assert!(
        map.segments.iter().all(|s| s.layer < map.layers.len()),
        "segments in a layer"
    );
    if voxels <= 1 << 16 {
        if let Ok(structures) = meshsmooth::segmentation::extract(map, &[], &Default::default()) {
            for s in &structures {
                let report = MeshReport::new(&s.mesh, &Topology::build(&s.mesh));
                assert_eq!(report.boundary_edges, 0, "a closed surface");
                assert_eq!(report.nonmanifold_edges, 0, "a manifold surface");
            }
        }
    }
}

/// Reads `data` as the image `name`: refused, or one value per voxel of a grid no larger than
/// asked.
#[allow(dead_code)]
pub fn check_image(data: &[u8], name: &str) {
    if let Ok(image) = meshsmooth::io::load_image(data, name, 4096) {
        let voxels: usize = image.dims.iter().product();
        assert!(voxels <= 4096 && voxels > 0, "{:?}", image.dims);
        assert_eq!(image.values.len(), voxels);
    }
}
