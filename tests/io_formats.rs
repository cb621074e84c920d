//! Every test mesh loads in every format it is given with the counts, topology and volume of the
//! data README; small hand-made files exercise each format feature with exact expectations.

use meshsmooth::io::{load, load_as, weld_exact, Format};
use meshsmooth::mesh::{Mesh, MeshReport, Topology};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data/");

/// One row of the data README's table.
struct Expected {
    stem: &'static str,
    formats: &'static [&'static str],
    vertices: usize,
    faces: usize,
    euler: i64,
    genus: i64,
    /// As printed in the README (rounded to 1 mm^3).
    volume: f64,
}

const MESHES: &[Expected] = &[
    Expected {
        stem: "real/fsaverage5_pial_left",
        formats: &["ply", "stl", "obj"],
        vertices: 10_242,
        faces: 20_480,
        euler: 2,
        genus: 0,
        volume: 500_036.0,
    },
    Expected {
        stem: "real/fsaverage_head_scalp_mne",
        formats: &["ply", "stl", "obj"],
        vertices: 2_033,
        faces: 4_062,
        euler: 2,
        genus: 0,
        volume: 5_142_590.0,
    },
    Expected {
        stem: "segmentations/seg_mni152_brainmask_2mm",
        formats: &["ply", "stl"],
        vertices: 32_626,
        faces: 65_248,
        euler: 2,
        genus: 0,
        volume: 1_882_235.0,
    },
    Expected {
        stem: "segmentations/seg_mni152_gm_plus_wm_p0.5_1mm",
        formats: &["ply"],
        vertices: 206_512,
        faces: 414_236,
        euler: -606,
        genus: 304,
        volume: 1_749_777.0,
    },
    Expected {
        stem: "synthetic/synthetic_sphere_r20",
        formats: &["ply", "stl"],
        vertices: 7_554,
        faces: 15_104,
        euler: 2,
        genus: 0,
        volume: 33_499.0,
    },
    Expected {
        stem: "synthetic/synthetic_torus_R24_r8",
        formats: &["ply", "stl"],
        vertices: 11_276,
        faces: 22_552,
        euler: 0,
        genus: 1,
        volume: 30_265.0,
    },
    Expected {
        stem: "synthetic/synthetic_bent_tube_r3.5",
        formats: &["ply", "stl"],
        vertices: 2_296,
        faces: 4_588,
        euler: 2,
        genus: 0,
        volume: 2_571.0,
    },
    Expected {
        stem: "synthetic/synthetic_ellipsoid_30_20_12",
        formats: &["ply", "stl"],
        vertices: 7_788,
        faces: 15_572,
        euler: 2,
        genus: 0,
        volume: 30_096.0,
    },
];

fn read_data(name: &str) -> Vec<u8> {
    let path = format!("{DATA}{name}");
    std::fs::read(&path).unwrap_or_else(|e| panic!("cannot read {path}: {e}"))
}

fn load_data(name: &str) -> Mesh {
    load(&read_data(name), name).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn report(mesh: &Mesh) -> MeshReport {
    MeshReport::new(mesh, &Topology::build(mesh))
}

#[test]
fn every_data_mesh_matches_the_readme_in_every_format() {
    for m in MESHES {
        let ply = load_data(&format!("{}.ply", m.stem));
        let ply_volume = ply.signed_volume();
        for ext in m.formats {
            let name = format!("{}.{ext}", m.stem);
            let mesh = if *ext == "ply" {
                ply.clone()
            } else {
                load_data(&name)
            };
            let r = report(&mesh);
            assert_eq!((r.vertices, r.faces), (m.vertices, m.faces), "{name}");
            assert_eq!(r.euler, m.euler, "{name}");
            assert_eq!(r.genus, Some(m.genus), "{name}");
            assert!(r.closed && r.components == 1, "{name}: {r:?}");
            assert_eq!(r.unreferenced_vertices, 0, "{name}");
            let volume = r.volume.unwrap_or(f64::NAN);
            // The README rounds to whole mm^3; the formats must agree with each other far closer.
            assert!(
                (volume - m.volume).abs() <= 0.5 + 1e-6 * m.volume,
                "{name}: {volume}"
            );
            assert!(
                ((volume - ply_volume) / ply_volume).abs() < 1e-6,
                "{name}: {volume} vs PLY {ply_volume}"
            );
        }
    }
}

#[test]
fn stl_welds_back_to_the_ply_triangle_for_triangle() {
    for m in MESHES.iter().filter(|m| m.formats.contains(&"stl")) {
        let ply = load_data(&format!("{}.ply", m.stem));
        let stl = load_data(&format!("{}.stl", m.stem));
        assert_eq!(stl.vertex_count(), ply.vertex_count(), "{}", m.stem);
        for (ts, tp) in stl.triangles.iter().zip(&ply.triangles) {
            for k in 0..3 {
                let a = stl.positions[ts[k] as usize].map(f32::to_bits);
                let b = ply.positions[tp[k] as usize].map(f32::to_bits);
                assert_eq!(a, b, "{}", m.stem);
            }
        }
        // First-appearance numbering: the corners in file order never skip a new number.
        let mut next = 0u32;
        for &v in stl.triangles.iter().flatten() {
            assert!(v <= next);
            next = next.max(v + 1);
        }
    }
}

#[test]
fn obj_keeps_the_ply_vertex_order_and_faces() {
    for m in MESHES.iter().filter(|m| m.formats.contains(&"obj")) {
        let ply = load_data(&format!("{}.ply", m.stem));
        let obj = load_data(&format!("{}.obj", m.stem));
        assert_eq!(obj.triangles, ply.triangles, "{}", m.stem);
        // The OBJ text carries a handful of significant digits; positions agree to that.
        for (a, b) in obj.positions.iter().zip(&ply.positions) {
            for k in 0..3 {
                assert!(
                    (a[k] - b[k]).abs() <= 1e-4 * (1.0 + b[k].abs()),
                    "{a:?} {b:?}"
                );
            }
        }
    }
}

#[test]
fn stl_weld_equals_weld_exact_of_the_soup() {
    let ply = load_data("synthetic/synthetic_torus_R24_r8.ply");
    let soup: Vec<[f32; 3]> = ply
        .triangles
        .iter()
        .flatten()
        .map(|&v| ply.positions[v as usize])
        .collect();
    let welded = weld_exact(&soup);
    let stl = load_data("synthetic/synthetic_torus_R24_r8.stl");
    assert_eq!(welded, stl);
}

// ---------------------------------------------------------------- STL

/// Binary STL of the given triangles with the given 80-byte header text.
fn binary_stl(header: &[u8], tris: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut b = header.to_vec();
    b.resize(80, b' ');
    b.extend_from_slice(&(tris.len() as u32).to_le_bytes());
    for t in tris {
        b.extend_from_slice(&[0u8; 12]);
        for c in t.iter().flatten() {
            b.extend_from_slice(&c.to_le_bytes());
        }
        b.extend_from_slice(&[0, 0]);
    }
    b
}

/// Two triangles sharing the edge (1,0,0)-(0,1,0): a unit square's halves.
const SQUARE: [[[f32; 3]; 3]; 2] = [
    [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
    [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
];

fn square_mesh() -> Mesh {
    Mesh::new(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
        ],
        vec![[0, 1, 2], [1, 3, 2]],
    )
}

fn ascii_stl(name: &str, newline: &str) -> Vec<u8> {
    let mut s = format!("solid {name}{newline}");
    for t in SQUARE {
        s += &format!("  facet normal 0 0 1{newline}    outer loop{newline}");
        for p in t {
            s += &format!("      vertex {} {} {}{newline}", p[0], p[1], p[2]);
        }
        s += &format!("    endloop{newline}  endfacet{newline}");
    }
    s += &format!("endsolid {name}{newline}");
    s.into_bytes()
}

#[test]
fn ascii_stl_with_every_line_ending_and_spaced_names() {
    for newline in ["\n", "\r\n", "\r"] {
        let bytes = ascii_stl("left hippocampus (mm)", newline);
        assert_eq!(
            load_as(&bytes, Format::Stl),
            Ok(square_mesh()),
            "{newline:?}"
        );
    }
}

#[test]
fn ascii_stl_uppercase_tabs_exponents_and_several_solids() {
    let text = "SOLID part one\n\tFACET NORMAL 0 0 1\n\t\tOUTER LOOP\n\
        \t\t\tVERTEX 0e0 0.0 -0.0\n\t\t\tVERTEX 1.0E+00 0 0\n\t\t\tVERTEX 0 1 0\n\t\tENDLOOP\n\tENDFACET\n\
        ENDSOLID part one\nsolid two\nfacet normal 0 0 0\nouter loop\nvertex 1 0 0\nvertex 1 1 0\n\
        vertex 0 1 0\nendloop\nendfacet\nendsolid\n";
    let mesh = load_as(text.as_bytes(), Format::Stl).expect("valid STL");
    assert_eq!(mesh.triangles, square_mesh().triangles);
    assert_eq!(mesh.positions.len(), 4);
    // The first appearance of the origin was written "-0.0"; it is kept as read.
    assert_eq!(mesh.positions[0][2].to_bits(), (-0.0f32).to_bits());
}

#[test]
fn binary_stl_whose_header_says_solid_is_read_as_binary() {
    let bytes = binary_stl(b"solid exported by a scanner", &SQUARE);
    assert_eq!(load_as(&bytes, Format::Stl), Ok(square_mesh()));
    let bytes = binary_stl(b"", &SQUARE);
    assert_eq!(load(&bytes, "square.STL"), Ok(square_mesh()));
}

#[test]
fn binary_stl_welds_signed_zeros_and_ignores_trailing_bytes() {
    let mut tris = SQUARE;
    tris[1][2] = [-0.0, 1.0, -0.0];
    let mut bytes = binary_stl(b"binary", &tris);
    bytes.extend_from_slice(&[0xAB; 7]);
    let mesh = load_as(&bytes, Format::Stl).expect("valid STL");
    assert_eq!(mesh, square_mesh());
}

// ---------------------------------------------------------------- OBJ

#[test]
fn obj_polygons_negative_indices_and_every_corner_form() {
    let text = "# a comment\nmtllib part.mtl\no part\ng shell\ns 1\nusemtl bone\n\
        v 0 0 0\nv 1 0 0 1.0\nv 1 1 0 0.5 0.2 0.1\nv 0 1 0\n\
        vt 0 0\nvt 1 0\nvn 0 0 1\nvp 0.5\n\
        f 1/1/1 2/2/1 3//1 4/1\n\
        v 2 0 0\nv 2 1 0\nv 3 0.5 0\n\
        f -3 -1 -2 # inline comment\n\
        f 2 5 7 6 3\n\
        v 9 9 9\n";
    let mesh = load_as(text.as_bytes(), Format::Obj).expect("valid OBJ");
    let expect = Mesh::new(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
            [3.0, 0.5, 0.0],
            [9.0, 9.0, 9.0],
        ],
        vec![
            [0, 1, 2],
            [0, 2, 3],
            [4, 6, 5],
            [1, 4, 6],
            [1, 6, 5],
            [1, 5, 2],
        ],
    );
    assert_eq!(mesh, expect);
}

#[test]
fn obj_crlf_byte_order_mark_and_forward_references() {
    let text = "\u{feff}f 1 2 3\r\nv 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\n";
    let mesh = load_as(text.as_bytes(), Format::Obj).expect("valid OBJ");
    assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
    assert_eq!(mesh.positions[2], [0.0, 1.0, 0.0]);
}

// ---------------------------------------------------------------- PLY

#[test]
fn ascii_ply_with_extra_properties_elements_and_polygons() {
    let text = "ply\nformat ascii 1.0\ncomment made by hand\nobj_info anything\n\
        element vertex 5\nproperty float x\nproperty float y\nproperty float z\n\
        property float nx\nproperty uchar red\nproperty list uchar float weights\n\
        element edge 2\nproperty list int int vertex_indices\nproperty short flag\n\
        element face 2\nproperty uint8 tag\nproperty list uchar int vertex_indices\n\
        end_header\n\
        0 0 0 0 255 0\n1 0 0 0 1 2 0.5 0.5\n1 1 0 0 1 0\n0 1 0 0 1 1 1.0\n7.5 -2 1e1 0 0 0\n\
        2 0 1 -1\n3 1 2 3 0\n\
        9 4 0 1 2 3\n3 3 3 2 1\n";
    let mesh = load_as(text.as_bytes(), Format::Ply).expect("valid PLY");
    assert_eq!(
        mesh.positions,
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [7.5, -2.0, 10.0]
        ]
    );
    assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3], [3, 2, 1]]);
}

/// Appends big- or little-endian bytes of each value.
trait Put {
    fn put(&mut self, big: bool, v: impl Into<Value>);
}

enum Value {
    U8(u8),
    I8(i8),
    U16(u16),
    I16(i16),
    U32(u32),
    I32(i32),
    F32(f32),
    F64(f64),
}

macro_rules! value_from {
    ($($t:ty => $v:ident),*) => {$(impl From<$t> for Value { fn from(x: $t) -> Self { Value::$v(x) } })*};
}
value_from!(u8 => U8, i8 => I8, u16 => U16, i16 => I16, u32 => U32, i32 => I32, f32 => F32, f64 => F64);

impl Put for Vec<u8> {
    fn put(&mut self, big: bool, v: impl Into<Value>) {
        macro_rules! bytes {
            ($x:expr) => {
                if big {
                    self.extend_from_slice(&$x.to_be_bytes())
                } else {
                    self.extend_from_slice(&$x.to_le_bytes())
                }
            };
        }
        match v.into() {
            Value::U8(x) => bytes!(x),
            Value::I8(x) => bytes!(x),
            Value::U16(x) => bytes!(x),
            Value::I16(x) => bytes!(x),
            Value::U32(x) => bytes!(x),
            Value::I32(x) => bytes!(x),
            Value::F32(x) => bytes!(x),
            Value::F64(x) => bytes!(x),
        }
    }
}

#[test]
fn big_endian_ply_with_doubles_extra_properties_and_elements() {
    let header = "ply\r\nformat binary_big_endian 1.0\r\ncomment doubles\r\n\
        element material 2\r\nproperty uchar r\r\nproperty float shininess\r\n\
        element vertex 4\r\nproperty double x\r\nproperty int16 label\r\nproperty double y\r\n\
        property list ushort float64 history\r\nproperty double z\r\n\
        element face 2\r\nproperty list ushort uint vertex_index\r\nproperty list uchar float texcoord\r\n\
        property int flags\r\n\
        element edge 1\r\nproperty int a\r\nproperty int b\r\nend_header\r\n";
    let mut b = header.as_bytes().to_vec();
    for m in 0..2u8 {
        b.put(true, m);
        b.put(true, 0.5f32);
    }
    let points = [
        [0.1, 0.2, 0.3],
        [1.5, -0.25, 1e-3],
        [-7.0, 8.0, 9.0],
        [1e6, 2.0, 3.0],
    ];
    for (i, p) in points.iter().enumerate() {
        b.put(true, p[0]);
        b.put(true, -(i as i16));
        b.put(true, p[1]);
        b.put(true, i as u16);
        for _ in 0..i {
            b.put(true, 42.0f64);
        }
        b.put(true, p[2]);
    }
    b.put(true, 4u16);
    for v in [0u32, 1, 2, 3] {
        b.put(true, v);
    }
    b.put(true, 6u8);
    for _ in 0..6 {
        b.put(true, 0.25f32);
    }
    b.put(true, -1i32);
    b.put(true, 3u16);
    for v in [3u32, 2, 1] {
        b.put(true, v);
    }
    b.put(true, 0u8);
    b.put(true, 7i32);
    b.put(true, 0i32);
    b.put(true, 1i32);
    let mesh = load_as(&b, Format::Ply).expect("valid PLY");
    let expect: Vec<[f32; 3]> = points
        .iter()
        .map(|p| [p[0] as f32, p[1] as f32, p[2] as f32])
        .collect();
    assert_eq!(mesh.positions, expect);
    assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3], [3, 2, 1]]);
}

#[test]
fn little_endian_ply_with_every_list_type_and_integer_coordinates() {
    // One face element per list length type, each in a file of its own.
    let lists = [
        "uchar int",
        "uint8 uint32",
        "char int",
        "int8 uint",
        "ushort int",
        "short uint16",
        "int16 int16",
        "uint int8",
        "int uint8",
        "uint32 short",
        "int32 ushort",
    ];
    for (n, list) in lists.iter().enumerate() {
        let header = format!(
            "ply\nformat binary_little_endian 1.0\nelement face 2\nproperty list {list} vertex_indices\n\
             element vertex 4\nproperty int x\nproperty short y\nproperty uchar z\nend_header\n"
        );
        let [count_ty, item_ty] = [0, 1].map(|k| list.split(' ').nth(k).unwrap_or_default());
        let mut b = header.into_bytes();
        let put_typed = |b: &mut Vec<u8>, ty: &str, v: i64| match ty {
            "uchar" | "uint8" => b.put(false, v as u8),
            "char" | "int8" => b.put(false, v as i8),
            "ushort" | "uint16" => b.put(false, v as u16),
            "short" | "int16" => b.put(false, v as i16),
            "uint" | "uint32" => b.put(false, v as u32),
            _ => b.put(false, v as i32),
        };
        for face in [&[0i64, 1, 2][..], &[0, 2, 3]] {
            put_typed(&mut b, count_ty, face.len() as i64);
            for &v in face {
                put_typed(&mut b, item_ty, v);
            }
        }
        for p in [[0i32, 0, 0], [1, 0, 0], [1, 1, 0], [-3, 2, 200]] {
            b.put(false, p[0]);
            b.put(false, p[1] as i16);
            b.put(false, p[2] as u8);
        }
        let mesh = load_as(&b, Format::Ply).unwrap_or_else(|e| panic!("list {n} '{list}': {e}"));
        assert_eq!(
            mesh.positions,
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [-3.0, 2.0, 200.0]
            ],
            "{list}"
        );
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3]], "{list}");
    }
}

#[test]
fn little_endian_ply_fast_path_handles_polygons_and_unreferenced_vertices() {
    let header = "ply\nformat binary_little_endian 1.0\nelement vertex 6\nproperty float x\n\
        property float y\nproperty float z\nelement face 3\nproperty list uchar int vertex_indices\nend_header\n";
    let mut b = header.as_bytes().to_vec();
    let points = [
        [0.0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.5, 0.5, 1.0],
        [-1.0, -1.0, -1.0],
    ];
    for c in points.iter().flatten() {
        b.put(false, *c);
    }
    for face in [&[0i32, 1, 4][..], &[0, 3, 2, 1], &[2, 3, 4]] {
        b.put(false, face.len() as u8);
        for &v in face {
            b.put(false, v);
        }
    }
    let mesh = load_as(&b, Format::Ply).expect("valid PLY");
    assert_eq!(mesh.positions, points.to_vec());
    assert_eq!(
        mesh.triangles,
        vec![[0, 1, 4], [0, 3, 2], [0, 2, 1], [2, 3, 4]]
    );
    let r = report(&mesh);
    assert_eq!(r.unreferenced_vertices, 1);
}

#[test]
fn formats_are_chosen_by_extension() {
    let stl = ascii_stl("x", "\n");
    assert_eq!(load(&stl, "dir.v2/Part.Stl"), Ok(square_mesh()));
    assert!(load(&stl, "part.obj").is_err());
    assert!(matches!(
        load(&stl, "part.xyz"),
        Err(meshsmooth::io::LoadError::UnknownFormat { .. })
    ));
}
