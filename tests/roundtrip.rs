//! Export then import: every format gives back what was written. PLY, GLB and OBJ keep the
//! vertex list bit for bit; STL is a triangle soup, so its triangles' corners are compared.

use meshsmooth::export::{write, ExportFormat, ExportOptions};
use meshsmooth::io::{load_as, Format};
use meshsmooth::mesh::{vertex_normals, Mesh};
use serde_json::json;

const SHARED: &[&str] = &[
    concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../shared/data/real/fsaverage_head_scalp_mne.ply"
    ),
    concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../shared/data/synthetic/synthetic_bent_tube_r3.5.ply"
    ),
    concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../shared/data/segmentations/seg_mni152_brainmask_2mm.ply"
    ),
    concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../shared/data/real/fsaverage5_pial_left.ply"
    ),
];

fn shared(path: &str) -> Mesh {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    load_as(&bytes, Format::Ply).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// A tetrahedron plus one vertex no triangle uses, with awkward coordinates (-0.0, a value
/// with no short decimal form, a tiny and a huge one).
fn hand_made() -> Mesh {
    Mesh::new(
        vec![
            [0.0, -0.0, 0.0],
            [1.0 / 3.0, 0.0, 0.0],
            [9.9, 99.0, 1.0e20],
            [0.1, 1.0e-30, 1.0],
            [5.0, 5.0, 5.0],
        ],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
}

fn colors(n: usize) -> Vec<[u8; 4]> {
    (0..n)
        .map(|i| [i as u8, (i >> 8) as u8, 200, 255])
        .collect()
}

fn bits(mesh: &Mesh) -> Vec<[u32; 3]> {
    mesh.positions.iter().map(|p| p.map(f32::to_bits)).collect()
}

fn soup(mesh: &Mesh) -> Vec<[[f32; 3]; 3]> {
    mesh.triangles
        .iter()
        .map(|t| t.map(|v| mesh.positions[v as usize]))
        .collect()
}

fn roundtrip(mesh: &Mesh, name: &str) {
    let normals = vertex_normals(&mesh.positions, &mesh.triangles);
    let colors = colors(mesh.vertex_count());
    let plain = ExportOptions::default();
    let full = ExportOptions {
        normals: Some(&normals),
        colors: Some(&colors),
        extras: Some(json!({"source": "roundtrip"})),
        millimetres: false,
    };
    for (export, import) in [
        (ExportFormat::Ply, Format::Ply),
        (ExportFormat::Glb, Format::Glb),
        (ExportFormat::Obj, Format::Obj),
    ] {
        for options in [&plain, &full] {
            let bytes = write(mesh, export, options).expect("writes");
            let back = load_as(&bytes, import).unwrap_or_else(|e| panic!("{name} {export:?}: {e}"));
            assert_eq!(back.triangles, mesh.triangles, "{name} {export:?}");
            assert!(
                bits(&back) == bits(mesh),
                "{name} {export:?}: positions differ"
            );
        }
    }

    let bytes = write(mesh, ExportFormat::Stl, &plain).expect("writes");
    let back = load_as(&bytes, Format::Stl).unwrap_or_else(|e| panic!("{name} STL: {e}"));
    // Float equality: the weld merges +0 and -0.
    assert!(
        soup(&back) == soup(mesh),
        "{name} STL: triangle soups differ"
    );
}

#[test]
fn hand_made_mesh_round_trips_in_every_format() {
    let mesh = hand_made();
    roundtrip(&mesh, "hand-made");
    // STL keeps only referenced vertices, numbered in order of first appearance.
    let bytes = write(&mesh, ExportFormat::Stl, &ExportOptions::default()).expect("writes");
    let back = load_as(&bytes, Format::Stl).expect("reads");
    let order = [0, 2, 1, 3];
    assert_eq!(back.positions, order.map(|i| mesh.positions[i]).to_vec());
}

#[test]
fn shared_meshes_round_trip_in_every_format() {
    for path in SHARED {
        let mesh = shared(path);
        assert!(mesh.triangle_count() > 1000, "{path}");
        roundtrip(&mesh, path);
    }
}

/// A binary STL whose header carries a patient's name, as scanners' exports often do.
fn stl_with_patient_header() -> Vec<u8> {
    let mut out = b"PATIENT John Doe 1970-01-01".to_vec();
    out.resize(80, 0);
    out.extend(2u32.to_le_bytes());
    let facets: [[[f32; 3]; 3]; 2] = [
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    ];
    for f in facets {
        out.extend([0u8; 12]);
        f.iter().flatten().for_each(|v| out.extend(v.to_le_bytes()));
        out.extend([0u8; 2]);
    }
    out
}

#[test]
fn exports_never_carry_the_input_header() {
    let mesh = load_as(&stl_with_patient_header(), Format::Stl).expect("reads");
    assert_eq!(mesh.triangle_count(), 2);
    for format in [
        ExportFormat::Stl,
        ExportFormat::Ply,
        ExportFormat::Obj,
        ExportFormat::Glb,
    ] {
        let bytes = write(&mesh, format, &ExportOptions::default()).expect("writes");
        for secret in [&b"John Doe"[..], b"PATIENT", b"1970"] {
            assert!(
                !bytes.windows(secret.len()).any(|w| w == secret),
                "{format:?} export carries the input's header"
            );
        }
        if format == ExportFormat::Stl {
            let mut header = b"meshsmooth binary STL".to_vec();
            header.resize(80, b' ');
            assert_eq!(&bytes[..80], &header[..]);
        }
    }
}

/// Bytes of a tightly packed accessor in the GLB's BIN chunk.
fn accessor_bytes<'a>(gltf: &'a gltf::Gltf, accessor: &gltf::Accessor) -> &'a [u8] {
    let view = accessor.view().expect("a buffer view");
    assert_eq!(view.stride(), None);
    let start = view.offset() + accessor.offset();
    let blob = gltf.blob.as_deref().expect("a BIN chunk");
    &blob[start..start + accessor.count() * accessor.size()]
}

#[test]
fn glb_normals_colours_and_extras_survive() {
    let mesh = shared(SHARED[1]);
    let normals = vertex_normals(&mesh.positions, &mesh.triangles);
    let colors = colors(mesh.vertex_count());
    let extras = json!({"filter": "taubin", "lambda": 0.5, "iterations": [10, 20]});
    let options = ExportOptions {
        normals: Some(&normals),
        colors: Some(&colors),
        extras: Some(extras.clone()),
        ..Default::default()
    };
    let bytes = write(&mesh, ExportFormat::Glb, &options).expect("writes");

    // The gltf crate validates the document against the specification.
    let gltf = gltf::Gltf::from_slice(&bytes).expect("a valid glTF");
    let primitive = gltf
        .meshes()
        .next()
        .and_then(|m| m.primitives().next())
        .expect("one primitive");
    assert_eq!(primitive.mode(), gltf::mesh::Mode::Triangles);
    let normal = primitive
        .get(&gltf::Semantic::Normals)
        .expect("a NORMAL accessor");
    assert_eq!(normal.data_type(), gltf::accessor::DataType::F32);
    let normal_bytes: Vec<u8> = normals
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    assert_eq!(accessor_bytes(&gltf, &normal), &normal_bytes[..]);
    let color = primitive
        .get(&gltf::Semantic::Colors(0))
        .expect("a COLOR_0 accessor");
    assert_eq!(color.data_type(), gltf::accessor::DataType::U8);
    assert_eq!(color.dimensions(), gltf::accessor::Dimensions::Vec4);
    assert!(color.normalized());
    assert_eq!(accessor_bytes(&gltf, &color), colors.as_flattened());

    let glb = gltf::Glb::from_slice(&bytes).expect("a GLB container");
    let doc: serde_json::Value = serde_json::from_slice(&glb.json).expect("JSON");
    assert_eq!(doc["meshes"][0]["extras"], extras);
    assert_eq!(doc["asset"]["generator"], "meshsmooth");
    // Metres with +Y up for viewers (superior up, anterior towards +Z) on a root node; the mesh
    // keeps millimetres, so reading it back here gives the positions written (above).
    assert_eq!(doc["nodes"][0]["matrix"][6], 0.001);
    assert_eq!(doc["nodes"][0]["matrix"][9], 0.001);
    assert_eq!(doc["nodes"][0]["children"], json!([1]));
    let raw = write(
        &mesh,
        ExportFormat::Glb,
        &ExportOptions {
            millimetres: true,
            ..Default::default()
        },
    )
    .expect("writes");
    let raw = gltf::Glb::from_slice(&raw).expect("a GLB container");
    let raw: serde_json::Value = serde_json::from_slice(&raw.json).expect("JSON");
    assert!(raw["nodes"][0].get("matrix").is_none());
    let text = String::from_utf8_lossy(&glb.json);
    assert!(!text.contains("\"name\""), "no names are written: {text}");
}
