//! glTF import: hand-built .gltf (data-URI buffers) and .glb files covering node transforms,
//! merging, index types, strips and fans, and a corpus of broken files that must each fail
//! cleanly, saying where.

#[path = "common/glb.rs"]
mod glb_file;
use base64::Engine as _;
use glb_file::glb;
use meshsmooth::io::{load, load_as, Format, LoadError, Location};
use meshsmooth::mesh::{bounding_box, Mesh};
use serde_json::{json, Value};

const FLOAT: u32 = 5126;
const UNSIGNED_BYTE: u32 = 5121;
const UNSIGNED_SHORT: u32 = 5123;
const UNSIGNED_INT: u32 = 5125;

/// Builds a glTF asset: one buffer, one view per array.
#[derive(Default)]
struct Asset {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    /// Top-level properties besides the buffers, views and accessors (meshes, nodes, scenes).
    doc: serde_json::Map<String, Value>,
}

impl Asset {
    fn view(&mut self, bytes: &[u8]) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.views
            .push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()}));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    fn positions(&mut self, points: &[[f32; 3]]) -> usize {
        let bytes: Vec<u8> = points
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let view = self.view(&bytes);
        let (lo, hi) = bounding_box(points).unwrap_or_default();
        self.accessors
            .push(json!({"bufferView": view, "componentType": FLOAT,
            "count": points.len(), "type": "VEC3", "min": lo, "max": hi}));
        self.accessors.len() - 1
    }

    fn indices(&mut self, component_type: u32, values: &[u32]) -> usize {
        let bytes: Vec<u8> = values
            .iter()
            .flat_map(|&v| match component_type {
                UNSIGNED_BYTE => vec![v as u8],
                UNSIGNED_SHORT => (v as u16).to_le_bytes().to_vec(),
                _ => v.to_le_bytes().to_vec(),
            })
            .collect();
        let view = self.view(&bytes);
        self.accessors
            .push(json!({"bufferView": view, "componentType": component_type,
            "count": values.len(), "type": "SCALAR"}));
        self.accessors.len() - 1
    }

    fn set(&mut self, key: &str, value: Value) -> &mut Self {
        self.doc.insert(key.into(), value);
        self
    }

    fn json(&self, buffer: Value) -> Value {
        let mut doc = json!({
            "asset": {"version": "2.0"},
            "accessors": self.accessors,
            "bufferViews": self.views,
            "buffers": [buffer],
        });
        for (k, v) in &self.doc {
            doc[k] = v.clone();
        }
        doc
    }

    fn gltf(&self) -> Vec<u8> {
        let uri = format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&self.bin)
        );
        self.json(json!({"byteLength": self.bin.len(), "uri": uri}))
            .to_string()
            .into_bytes()
    }

    fn glb(&self) -> Vec<u8> {
        glb(&self.json(json!({"byteLength": self.bin.len()})), &self.bin)
    }
}

const TRIANGLE: [[f32; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// One triangle (u16 indices) on node 0, without transform.
fn single_triangle() -> Asset {
    let mut a = Asset::default();
    let p = a.positions(&TRIANGLE);
    let i = a.indices(UNSIGNED_SHORT, &[0, 1, 2]);
    a.set(
        "meshes",
        json!([{"primitives": [{"attributes": {"POSITION": p}, "indices": i}]}]),
    )
    .set("nodes", json!([{"mesh": 0}]))
    .set("scenes", json!([{"nodes": [0]}]));
    a
}

/// Reads the asset as .gltf and as .glb, checks both agree, and returns the mesh.
fn both(a: &Asset) -> Mesh {
    let from_gltf = load(&a.gltf(), "x.gltf").expect("the .gltf reads");
    let from_glb = load(&a.glb(), "x.glb").expect("the .glb reads");
    assert_eq!(from_gltf, from_glb);
    from_glb
}

fn assert_close(got: &[[f32; 3]], want: &[[f32; 3]]) {
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(want) {
        for k in 0..3 {
            assert!((g[k] - w[k]).abs() < 1e-5, "{got:?} != {want:?}");
        }
    }
}

#[test]
fn untransformed_triangle_keeps_exact_bits() {
    let mesh = both(&single_triangle());
    assert_eq!(mesh.positions, TRIANGLE.to_vec());
    assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
}

#[test]
fn nested_translate_rotate_scale_accumulate_down_the_hierarchy() {
    let mut a = single_triangle();
    let h = std::f32::consts::FRAC_1_SQRT_2;
    // Parent translates; child scales by 2 then turns a quarter about z.
    a.set(
        "nodes",
        json!([
            {"translation": [10.0, 0.0, 0.0], "children": [1]},
            {"scale": [2.0, 2.0, 2.0], "rotation": [0.0, 0.0, h, h], "mesh": 0}
        ]),
    );
    let want = [[10.0, 2.0, 0.0], [8.0, 0.0, 0.0], [10.0, 0.0, 2.0]];
    let mesh = both(&a);
    assert_close(&mesh.positions, &want);
    assert_eq!(mesh.triangles, vec![[0, 1, 2]]);

    // The same placement as a column-major matrix on the child.
    a.set(
        "nodes",
        json!([
            {"translation": [10.0, 0.0, 0.0], "children": [1]},
            {"matrix": [0.0, 2.0, 0.0, 0.0,  -2.0, 0.0, 0.0, 0.0,  0.0, 0.0, 2.0, 0.0,  0.0, 0.0, 0.0, 1.0],
             "mesh": 0}
        ]),
    );
    assert_close(&both(&a).positions, &want);
}

#[test]
fn a_mirroring_transform_keeps_triangles_counter_clockwise() {
    let mut a = single_triangle();
    a.set("nodes", json!([{"scale": [-1.0, 1.0, 1.0], "mesh": 0}]));
    let mesh = both(&a);
    assert_eq!(mesh.positions[0], [-1.0, 0.0, 0.0]);
    assert_eq!(mesh.triangles, vec![[0, 2, 1]]);
}

#[test]
fn meshes_and_primitives_merge_in_traversal_then_accessor_order() {
    let mut a = Asset::default();
    let quad = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let p0 = a.positions(&quad);
    let i8 = a.indices(UNSIGNED_BYTE, &[0, 1, 2, 0, 2, 3]);
    let p1 = a.positions(&TRIANGLE);
    let i32 = a.indices(UNSIGNED_INT, &[2, 1, 0]);
    let p2 = a.positions(&[[5.0, 0.0, 0.0], [6.0, 0.0, 0.0], [5.0, 1.0, 0.0]]);
    let lines = a.indices(UNSIGNED_SHORT, &[0, 1]);
    a.set(
        "meshes",
        json!([
            {"primitives": [
                {"attributes": {"POSITION": p0}, "indices": i8},
                {"attributes": {"POSITION": p1}, "indices": lines, "mode": 1},
                {"attributes": {"POSITION": p1}, "indices": i32}
            ]},
            {"primitives": [{"attributes": {"POSITION": p2}}]}
        ]),
    )
    // Node 1 is visited first (the scene lists it first); node 2 is node 1's child.
    .set(
        "nodes",
        json!([{"mesh": 0}, {"mesh": 1, "children": [2]}, {"mesh": 0, "translation": [0.0, 0.0, 7.0]}]),
    )
    .set("scenes", json!([{"nodes": [1, 0]}]));
    let mesh = both(&a);
    assert_eq!(mesh.vertex_count(), 3 + 2 * (4 + 3));
    assert_eq!(mesh.positions[0], [5.0, 0.0, 0.0]);
    assert_eq!(mesh.positions[3], [0.0, 0.0, 7.0]);
    assert_eq!(mesh.positions[10], quad[0]);
    assert_eq!(
        mesh.triangles,
        vec![
            [0, 1, 2],
            [3, 4, 5],
            [3, 5, 6],
            [9, 8, 7],
            [10, 11, 12],
            [10, 12, 13],
            [16, 15, 14]
        ]
    );
}

#[test]
fn strips_and_fans_become_triangles() {
    let mut a = Asset::default();
    let pts: Vec<[f32; 3]> = (0..5).map(|i| [i as f32, (i % 2) as f32, 0.0]).collect();
    let p = a.positions(&pts);
    // A repeated index joins two strips; that degenerate triangle is not part of the surface.
    let strip = a.indices(UNSIGNED_SHORT, &[0, 1, 2, 3, 3, 4]);
    a.set(
        "meshes",
        json!([{"primitives": [
            {"attributes": {"POSITION": p}, "mode": 5},
            {"attributes": {"POSITION": p}, "indices": strip, "mode": 5},
            {"attributes": {"POSITION": p}, "mode": 6},
            {"attributes": {"POSITION": p}, "mode": 0}
        ]}]),
    )
    .set("nodes", json!([{"mesh": 0}]));
    // No scenes: every root node is drawn.
    let mesh = both(&a);
    assert_eq!(mesh.vertex_count(), 15);
    assert_eq!(
        mesh.triangles,
        vec![
            [0, 1, 2],
            [1, 3, 2],
            [2, 3, 4],
            [5, 6, 7],
            [6, 8, 7],
            [11, 12, 10],
            [12, 13, 10],
            [13, 14, 10]
        ]
    );
}

#[test]
fn the_default_scene_is_the_one_drawn() {
    let mut a = single_triangle();
    a.set(
        "nodes",
        json!([{"mesh": 0}, {"mesh": 0, "translation": [0.0, 5.0, 0.0]}]),
    )
    .set("scenes", json!([{"nodes": [0]}, {"nodes": [1]}]))
    .set("scene", json!(1));
    assert_eq!(both(&a).positions[0], [1.0, 5.0, 0.0]);
}

#[test]
fn strided_and_quantised_positions_read() {
    let mut a = Asset::default();
    // Interleaved: xyz then 4 bytes of something else.
    let mut bytes = Vec::new();
    for p in TRIANGLE {
        p.iter().for_each(|v| bytes.extend(v.to_le_bytes()));
        bytes.extend([9, 9, 9, 9]);
    }
    let view = a.view(&bytes);
    a.views[view]["byteStride"] = json!(16);
    a.accessors.push(
        json!({"bufferView": view, "componentType": FLOAT, "count": 3,
        "type": "VEC3", "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 1.0]}),
    );
    // Normalised unsigned shorts (KHR_mesh_quantization), padded to 8 bytes per element.
    let q: Vec<u8> = [[65535u16, 0, 0, 0], [0, 65535, 0, 0], [0, 0, 65535, 0]]
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let qview = a.view(&q);
    a.views[qview]["byteStride"] = json!(8);
    a.accessors.push(
        json!({"bufferView": qview, "componentType": UNSIGNED_SHORT, "normalized": true,
        "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [65535, 65535, 65535]}),
    );
    a.set(
        "meshes",
        json!([{"primitives": [{"attributes": {"POSITION": 0}}, {"attributes": {"POSITION": 1}}]}]),
    )
    .set("nodes", json!([{"mesh": 0}]))
    .set("extensionsUsed", json!(["KHR_mesh_quantization"]))
    .set("extensionsRequired", json!(["KHR_mesh_quantization"]));
    let mesh = both(&a);
    assert_eq!(mesh.positions[..3], TRIANGLE);
    assert_eq!(mesh.positions[3..], TRIANGLE);
}

/// Loads `bytes` and returns the error, checking that its message names `place`.
fn fails(bytes: &[u8], format: Format, place: &str) -> LoadError {
    let err = load_as(bytes, format).expect_err("a broken file must not load");
    let message = err.to_string();
    assert!(
        message.contains(place),
        "'{message}' does not say '{place}'"
    );
    err
}

#[test]
fn broken_containers() {
    let good = single_triangle().glb();
    let err = fails(&good[..good.len() / 2], Format::Glb, "byte");
    assert!(matches!(err, LoadError::Truncated { .. }), "{err:?}");
    let err = fails(&good[..7], Format::Glb, "byte 7");
    assert!(matches!(err, LoadError::Truncated { .. }), "{err:?}");

    let mut bad = good.clone();
    bad[0] = b'x';
    assert!(matches!(
        fails(&bad, Format::Glb, "glTF"),
        LoadError::BadMagic { .. }
    ));

    // The JSON chunk claims more bytes than the file has.
    let mut bad = good.clone();
    let json_len = u32::from_le_bytes([good[12], good[13], good[14], good[15]]);
    bad[12..16].copy_from_slice(&(json_len + 4096).to_le_bytes());
    let err = fails(&bad, Format::Glb, "chunk at byte 12");
    assert!(matches!(err, LoadError::Truncated { .. }), "{err:?}");

    let mut bad = good.clone();
    bad[4] = 1;
    assert!(matches!(
        fails(&bad, Format::Glb, "version 1"),
        LoadError::Unsupported { .. }
    ));
}

#[test]
fn invalid_json_says_where() {
    let text = b"{\n  \"asset\": {\"version\": \"2.0\"},\n  \"nodes\": [ oops ]\n}";
    let err = fails(text, Format::Gltf, "line 3");
    assert!(
        matches!(
            err,
            LoadError::Syntax {
                location: Location::Line(3),
                ..
            }
        ),
        "{err:?}"
    );
    let err = fails(&glb(&json!("not an object"), &[]), Format::Glb, "byte");
    assert!(
        matches!(
            err,
            LoadError::Syntax {
                location: Location::Byte(_),
                ..
            }
        ),
        "{err:?}"
    );
}

#[test]
fn broken_accessors_and_buffers() {
    // Accessor reaching past its view.
    let mut a = single_triangle();
    a.accessors[0]["count"] = json!(4);
    let err = fails(&a.glb(), Format::Glb, "accessor 0");
    assert!(matches!(
        err,
        LoadError::Syntax {
            location: Location::Item("accessor", 0),
            ..
        }
    ));

    // View reaching past the buffer.
    let mut a = single_triangle();
    a.views[1]["byteLength"] = json!(4096);
    fails(&a.gltf(), Format::Gltf, "buffer view 1");

    // The buffer claims more bytes than the BIN chunk holds.
    let a = single_triangle();
    let doc = a.json(json!({"byteLength": a.bin.len() + 64}));
    let err = fails(&glb(&doc, &a.bin), Format::Glb, "buffer 0");
    assert!(matches!(
        err,
        LoadError::Syntax {
            location: Location::Item("buffer", 0),
            ..
        }
    ));

    // Stride smaller than the element.
    let mut a = single_triangle();
    a.views[0]["byteStride"] = json!(8);
    fails(&a.gltf(), Format::Gltf, "byteStride 8");

    let mut a = single_triangle();
    a.accessors[0]["sparse"] = json!({"count": 1,
        "indices": {"bufferView": 1, "componentType": UNSIGNED_SHORT},
        "values": {"bufferView": 0}});
    assert!(matches!(
        fails(&a.gltf(), Format::Gltf, "sparse"),
        LoadError::Unsupported { .. }
    ));
}

#[test]
fn index_out_of_range_names_the_index_accessor() {
    let mut a = single_triangle();
    a.accessors.pop();
    a.indices(UNSIGNED_SHORT, &[0, 1, 3]);
    let err = fails(&a.glb(), Format::Glb, "accessor 1");
    let LoadError::IndexOutOfRange { index, count, .. } = err else {
        panic!("{err:?}");
    };
    assert_eq!((index, count), (3, 3));
}

#[test]
fn external_and_non_base64_uris_are_refused() {
    let a = single_triangle();
    let doc = a.json(json!({"byteLength": a.bin.len(), "uri": "scan.bin"}));
    let err = fails(
        doc.to_string().as_bytes(),
        Format::Gltf,
        "external file 'scan.bin'",
    );
    assert!(matches!(err, LoadError::Unsupported { .. }));
    let doc =
        a.json(json!({"byteLength": a.bin.len(), "uri": "data:application/octet-stream,abc"}));
    fails(doc.to_string().as_bytes(), Format::Gltf, "base64");
    let doc = a.json(
        json!({"byteLength": a.bin.len(), "uri": "data:application/octet-stream;base64,@@@@"}),
    );
    fails(doc.to_string().as_bytes(), Format::Gltf, "buffer 0");
}

#[test]
fn nan_positions_and_files_without_triangles() {
    let mut a = single_triangle();
    a.bin[4..8].copy_from_slice(&f32::NAN.to_le_bytes());
    let err = fails(&a.glb(), Format::Glb, "accessor 0");
    assert!(matches!(err, LoadError::NonFinite { .. }), "{err:?}");

    let mut a = single_triangle();
    a.set(
        "meshes",
        json!([{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": 1}]}]),
    );
    assert!(matches!(
        fails(&a.glb(), Format::Glb, "no triangles"),
        LoadError::NoTriangles { .. }
    ));
    let mut a = single_triangle();
    a.set("nodes", json!([{}]));
    assert!(matches!(
        load_as(&a.gltf(), Format::Gltf),
        Err(LoadError::NoTriangles { .. })
    ));
}

#[test]
fn the_document_itself_is_validated() {
    // POSITION without its required min and max: the crate's validation says where.
    let mut a = single_triangle();
    a.accessors[0].as_object_mut().map(|o| o.remove("min"));
    let err = fails(&a.gltf(), Format::Gltf, "mesh 0");
    assert!(matches!(err, LoadError::Syntax { .. }));
    assert!(err.to_string().contains("min"), "{err}");

    // A POSITION accessor that does not exist.
    let mut a = single_triangle();
    a.set(
        "meshes",
        json!([{"primitives": [{"attributes": {"POSITION": 9}}]}]),
    );
    fails(&a.glb(), Format::Glb, "mesh 0");

    // A node that is its own grandchild.
    let mut a = single_triangle();
    a.set(
        "nodes",
        json!([{"mesh": 0, "children": [1]}, {"children": [0]}]),
    )
    .set("scenes", json!([{"nodes": [0]}]));
    fails(&a.glb(), Format::Glb, "node 0");

    let mut a = single_triangle();
    a.set("extensionsRequired", json!(["KHR_draco_mesh_compression"]))
        .set("extensionsUsed", json!(["KHR_draco_mesh_compression"]));
    assert!(matches!(
        fails(&a.glb(), Format::Glb, "KHR_draco_mesh_compression"),
        LoadError::Unsupported { .. }
    ));
}

/// Deterministic xorshift64.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

#[test]
fn mutated_files_never_panic() {
    let mut a = Asset::default();
    let pts: Vec<[f32; 3]> = (0..6).map(|i| [i as f32, (i * i) as f32, 1.0]).collect();
    let p = a.positions(&pts);
    let i = a.indices(UNSIGNED_SHORT, &[0, 1, 2, 2, 1, 3, 3, 4, 5]);
    a.set(
        "meshes",
        json!([{"primitives": [{"attributes": {"POSITION": p}, "indices": i}]}]),
    )
    .set(
        "nodes",
        json!([{"children": [1], "rotation": [0.0, 0.6, 0.0, 0.8]}, {"mesh": 0}]),
    )
    .set("scenes", json!([{"nodes": [0]}]));
    let seeds = [(a.glb(), Format::Glb), (a.gltf(), Format::Gltf)];
    for (seed, format) in &seeds {
        load_as(seed, *format).expect("the seed file reads");
    }
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut loaded = 0;
    for case in 0..4000 {
        let (seed, format) = &seeds[case % 2];
        let mut bytes = seed.clone();
        for _ in 0..1 + rng.below(4) {
            let at = rng.below(bytes.len());
            match rng.below(4) {
                0 => bytes[at] ^= 1 << rng.below(8),
                1 => bytes[at] = rng.next() as u8,
                // Small digits and extreme lengths are what JSON numbers and headers hold.
                2 => bytes[at] = b"0123456789"[rng.below(10)],
                _ => bytes.truncate(at.max(1)),
            }
        }
        if load_as(&bytes, *format).is_ok() {
            loaded += 1;
        }
    }
    // Some mutations (inside padding, or to coordinates) still leave a valid file.
    assert!(loaded > 0);
}
