//! The parsers and the topology compiled to wasm32 and run in a browser (`cargo test --target
//! wasm32-unknown-unknown`, headless Chromium as tests/run.sh sets it): the same code path the web app takes after a file is opened.
//!
//! Meshes come from `../shared/data` (see its README for the expected values); only the small
//! ones are embedded, to keep the test module's size sane.
#![cfg(target_arch = "wasm32")]

use meshsmooth::io::{self, LoadError};
use meshsmooth::mesh::{Mesh, MeshReport, Topology};
use wasm_bindgen_test::{wasm_bindgen_test, wasm_bindgen_test_configure};

wasm_bindgen_test_configure!(run_in_browser);

const SCALP_PLY: &[u8] = include_bytes!("../../shared/data/real/fsaverage_head_scalp_mne.ply");
const SCALP_STL: &[u8] = include_bytes!("../../shared/data/real/fsaverage_head_scalp_mne.stl");
const SCALP_OBJ: &[u8] = include_bytes!("../../shared/data/real/fsaverage_head_scalp_mne.obj");
const TUBE_PLY: &[u8] = include_bytes!("../../shared/data/synthetic/synthetic_bent_tube_r3.5.ply");
const TUBE_STL: &[u8] = include_bytes!("../../shared/data/synthetic/synthetic_bent_tube_r3.5.stl");

/// What the data README promises for one mesh.
struct Expected {
    vertices: usize,
    faces: usize,
    euler: i64,
    genus: i64,
    volume: f64,
    /// Allowed difference from `volume`: the README rounds to whole mm^3.
    volume_tolerance: f64,
}

const SCALP: Expected = Expected {
    vertices: 2033,
    faces: 4062,
    euler: 2,
    genus: 0,
    volume: 5_142_590.0,
    volume_tolerance: 1.0,
};

const TUBE: Expected = Expected {
    vertices: 2296,
    faces: 4588,
    euler: 2,
    genus: 0,
    volume: 2_571.0,
    volume_tolerance: 0.5,
};

fn report_of(mesh: &Mesh) -> MeshReport {
    MeshReport::new(mesh, &Topology::build(mesh))
}

fn load_and_check(bytes: &[u8], name: &str, expected: &Expected) -> MeshReport {
    let mesh = match io::load(bytes, name) {
        Ok(mesh) => mesh,
        Err(e) => panic!("{name} did not load: {e}"),
    };
    let r = report_of(&mesh);
    assert_eq!(
        (r.vertices, r.faces),
        (expected.vertices, expected.faces),
        "{name}"
    );
    assert_eq!(r.unreferenced_vertices, 0, "{name}");
    assert_eq!(r.degenerate_faces, 0, "{name}");
    assert_eq!(r.duplicate_faces, 0, "{name}");
    assert_eq!(r.boundary_edges, 0, "{name}");
    assert_eq!(r.nonmanifold_edges, 0, "{name}");
    assert_eq!(r.nonmanifold_vertices, 0, "{name}");
    assert_eq!(r.components, 1, "{name}");
    assert_eq!(r.euler, expected.euler, "{name}");
    assert_eq!(r.genus, Some(expected.genus), "{name}");
    assert!(r.closed, "{name}");
    let volume = r.volume.unwrap_or(f64::NAN);
    assert!(
        (volume - expected.volume).abs() <= expected.volume_tolerance,
        "{name}: volume {volume}, expected {} +- {}",
        expected.volume,
        expected.volume_tolerance
    );
    assert!(r.warnings().is_empty(), "{name}: {:?}", r.warnings());
    r
}

#[wasm_bindgen_test]
fn scalp_reads_the_same_from_ply_stl_and_obj() {
    let ply = load_and_check(SCALP_PLY, "fsaverage_head_scalp_mne.ply", &SCALP);
    let stl = load_and_check(SCALP_STL, "fsaverage_head_scalp_mne.stl", &SCALP);
    let obj = load_and_check(SCALP_OBJ, "fsaverage_head_scalp_mne.obj", &SCALP);
    // Binary PLY and STL hold the same float32 coordinates.
    assert_eq!((ply.bbox_min, ply.bbox_max), (stl.bbox_min, stl.bbox_max));
    assert_eq!(ply.bbox_min, [-83.23214, -122.95137, -163.96658]);
    // OBJ holds decimal text of the same coordinates (6 decimals).
    for k in 0..3 {
        assert!((obj.bbox_min[k] - ply.bbox_min[k]).abs() < 1e-5);
        assert!((obj.bbox_max[k] - ply.bbox_max[k]).abs() < 1e-5);
    }
}

#[wasm_bindgen_test]
fn bent_tube_reads_from_ply_and_stl() {
    for (bytes, name) in [
        (TUBE_PLY, "synthetic_bent_tube_r3.5.ply"),
        (TUBE_STL, "synthetic_bent_tube_r3.5.STL"),
    ] {
        let r = load_and_check(bytes, name, &TUBE);
        // Marching cubes on a 1 mm grid: the extremes sit on half-voxel planes.
        assert_eq!(
            (r.bbox_min, r.bbox_max),
            ([22.5, 7.5, 7.5], [52.5, 50.5, 32.5])
        );
    }
}

#[wasm_bindgen_test]
fn truncated_ply_is_an_error_not_a_panic() {
    let cut = &TUBE_PLY[..TUBE_PLY.len() / 2];
    assert!(io::load(cut, "tube.ply").is_err());
}

#[wasm_bindgen_test]
fn unknown_and_empty_files_are_errors() {
    assert_eq!(
        io::load(b"solid x", "mesh.vtk"),
        Err(LoadError::UnknownFormat {
            name: "mesh.vtk".into()
        })
    );
    assert!(matches!(
        io::load(b"", "empty.stl"),
        Err(LoadError::Empty { .. })
    ));
}

/// Unit cube, outward winding, 8 vertices and 12 triangles.
fn cube() -> Mesh {
    let positions = (0..8)
        .map(|i| [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32])
        .collect();
    // Two triangles per face, faces in the order z = 0, z = 1, y = 0, y = 1, x = 0, x = 1.
    let triangles = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    Mesh::new(positions, triangles)
}

#[wasm_bindgen_test]
fn hand_built_cube_topology_and_report() {
    let mesh = cube();
    let topology = Topology::build(&mesh);
    assert_eq!(topology.vertex_count(), 8);
    assert_eq!(topology.edge_count(), 18);
    assert!(!topology.has_boundary());
    // Corner 0 meets three cube edges and no diagonal; corner 6 also meets two diagonals.
    assert_eq!(topology.neighbors_of(0), &[1, 2, 4]);
    assert_eq!(topology.triangles_of(0), &[0, 4, 8]);
    assert_eq!(topology.neighbors_of(6), &[2, 3, 4, 5, 7]);
    assert_eq!(topology.triangles_of(6).len(), 5);

    let r = MeshReport::new(&mesh, &topology);
    assert_eq!((r.vertices, r.faces, r.components), (8, 12, 1));
    assert_eq!((r.euler, r.genus, r.closed), (2, Some(0), true));
    assert!((r.volume.unwrap_or(f64::NAN) - 1.0).abs() < 1e-12);
    assert_eq!((r.bbox_min, r.bbox_max), ([0.0; 3], [1.0; 3]));
    assert!(r.warnings().is_empty());
}

#[wasm_bindgen_test]
fn cube_without_its_top_is_open() {
    let mut mesh = cube();
    mesh.triangles.drain(2..4);
    let topology = Topology::build(&mesh);
    assert!(topology.has_boundary());
    let r = MeshReport::new(&mesh, &topology);
    assert_eq!(r.boundary_edges, 4);
    assert_eq!(
        (r.euler, r.closed, r.genus, r.volume),
        (1, false, None, None)
    );
    assert!(r.warnings().iter().any(|w| w.contains("boundary edges")));
}

/// The oblique CT series (tests/data/dicom_series) as its slices: `$folder/$prefix<hash>.dcm`.
macro_rules! oblique_slices {
    ($folder:literal, $prefix:literal) => {
        oblique_slices!(@ $folder, $prefix, "03cc5f9046", "13010f1ebe", "28ddc11211",
            "3026641af3", "50d501d659", "5553c51e9a", "5aaf62737a", "5d1dd86b7b", "7d66784147",
            "82209cdccc", "c7afef1b17", "f77138cc1e")
    };
    (@ $folder:literal, $prefix:literal, $($hash:literal),*) => {
        [$((
            $hash,
            include_bytes!(concat!("data/dicom_series/", $folder, "/", $prefix, $hash, ".dcm"))
                .as_slice(),
        )),*]
    };
}

/// DICOM slices compressed as RLE Lossless, as JPEG Lossless and deflated decode in the browser
/// to the voxels of the series' NIfTI twin.
#[wasm_bindgen_test]
fn compressed_dicom_series_read_as_their_nifti_twin() {
    let twin = include_bytes!("data/dicom_series/oblique.nii.gz");
    let want = io::load_image(twin, "oblique.nii.gz", usize::MAX).expect("the twin");
    for files in [
        oblique_slices!("oblique_rle", "rle_"),
        oblique_slices!("oblique_jpeg", "jpeg_"),
        oblique_slices!("oblique_deflated", "deflated_"),
    ] {
        let image = io::load_image_series(&files, usize::MAX).expect("the series");
        assert_eq!(image.dims, want.dims);
        assert_eq!(image.values, want.values);
    }
}
