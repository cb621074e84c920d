//! Broken inputs, per format: each must give the right `LoadError` naming where, quickly and
//! without allocating from untrusted counts; mutated real files must never panic.

use meshsmooth::io::{load_as, Format, LoadError, Location};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::time::{Duration, Instant};
use Location::{Byte, Line};

#[path = "io_broken/compressed_gltf.rs"]
mod compressed_gltf;
#[path = "io_broken/mutations.rs"]
mod mutations;
use mutations::XorShift;

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data/");

/// Records the largest allocation each thread asks for, so tests can prove that a header's
/// claimed count never turns into an allocation.
struct Recording;

thread_local! {
    static LARGEST: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Recording {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = LARGEST.try_with(|l| l.set(l.get().max(layout.size())));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = LARGEST.try_with(|l| l.set(l.get().max(new_size)));
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Recording = Recording;

/// Loads and returns the error, failing if it succeeds, takes long or allocates much.
fn error_of(bytes: &[u8], format: Format) -> LoadError {
    LARGEST.with(|l| l.set(0));
    let start = Instant::now();
    let result = load_as(bytes, format);
    let elapsed = start.elapsed();
    let largest = LARGEST.with(Cell::get);
    assert!(
        elapsed < Duration::from_secs(2),
        "{format}: took {elapsed:?}"
    );
    // Parsing may use a few times the input size, never more.
    assert!(
        largest <= 16 * bytes.len() + 4096,
        "{format}: allocated {largest} bytes for a {}-byte input",
        bytes.len()
    );
    match result {
        Ok(m) => panic!(
            "{format}: broken input loaded ({} triangles)",
            m.triangles.len()
        ),
        Err(e) => e,
    }
}

/// The variant's name and, where it has one, the location.
fn shape(e: &LoadError) -> (&'static str, Option<Location>) {
    match e {
        LoadError::Empty { .. } => ("Empty", None),
        LoadError::UnknownFormat { .. } => ("UnknownFormat", None),
        LoadError::UnknownImageFormat { .. } => ("UnknownImageFormat", None),
        LoadError::BadMagic { .. } => ("BadMagic", None),
        LoadError::Truncated { .. } => ("Truncated", None),
        LoadError::CountTooLarge { .. } => ("CountTooLarge", None),
        LoadError::Syntax { location, .. } => ("Syntax", Some(*location)),
        LoadError::IndexOutOfRange { location, .. } => ("IndexOutOfRange", Some(*location)),
        LoadError::NonFinite { location, .. } => ("NonFinite", Some(*location)),
        LoadError::NoTriangles { .. } => ("NoTriangles", None),
        LoadError::Unsupported { .. } => ("Unsupported", None),
    }
}

/// Expects an error of the `kind` variant at `at`, named in its message.
fn error_at(bytes: &[u8], format: Format, kind: &str, at: Location) -> LoadError {
    let e = error_of(bytes, format);
    assert_eq!(shape(&e), (kind, Some(at)), "{e}");
    says(&e, &at.to_string());
    e
}

/// Expects an error of the `kind` variant.
fn error_kind(bytes: &[u8], format: Format, kind: &str) -> LoadError {
    let e = error_of(bytes, format);
    assert_eq!(shape(&e).0, kind, "{e}");
    e
}

fn says(e: &LoadError, what: &str) {
    assert!(e.to_string().contains(what), "'{e}' does not say '{what}'");
}

fn read_data(name: &str) -> Vec<u8> {
    let path = format!("{DATA}{name}");
    std::fs::read(&path).unwrap_or_else(|e| panic!("cannot read {path}: {e}"))
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

fn too_large(format: Format, what: &'static str, claimed: u64, possible: u64) -> LoadError {
    LoadError::CountTooLarge {
        format,
        what,
        claimed,
        possible,
    }
}

#[test]
fn the_allocation_recorder_sees_allocations() {
    LARGEST.with(|l| l.set(0));
    let v = std::hint::black_box(vec![1u8; 3 << 20]);
    assert!(LARGEST.with(Cell::get) >= v.len());
}

// ---------------------------------------------------------------- every format

#[test]
fn empty_files_are_refused_by_every_parser() {
    for f in [Format::Stl, Format::Obj, Format::Ply] {
        assert_eq!(error_of(b"", f), LoadError::Empty { format: f });
    }
}

#[test]
fn garbage_bytes_are_refused_by_every_parser() {
    let mut rng = XorShift(0x9E37_79B9_7F4A_7C15);
    for len in [1usize, 7, 83, 84, 85, 134, 1000, 65_536] {
        let bytes: Vec<u8> = (0..len).map(|_| rng.next() as u8).collect();
        for f in [Format::Stl, Format::Obj, Format::Ply] {
            error_of(&bytes, f);
        }
    }
}

// ---------------------------------------------------------------- STL

fn binary_stl(count: u32, records: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut b = vec![b' '; 80];
    b.extend_from_slice(&count.to_le_bytes());
    for r in records {
        b.extend_from_slice(&[0u8; 12]);
        for c in r.iter().flatten() {
            b.extend_from_slice(&c.to_le_bytes());
        }
        b.extend_from_slice(&[0, 0]);
    }
    b
}

const TRI: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

#[test]
fn stl_wrong_magic_is_bad_magic() {
    error_kind(b"facet normal 0 0 1\n", Format::Stl, "BadMagic");
    error_kind(b"hello, this is not a mesh\n", Format::Stl, "BadMagic");
    error_kind(
        "newmtl bone\n".repeat(20).as_bytes(),
        Format::Stl,
        "BadMagic",
    );
}

#[test]
fn stl_claiming_four_billion_triangles_fails_fast() {
    let e = error_of(&binary_stl(u32::MAX, &[TRI]), Format::Stl);
    assert_eq!(
        e,
        too_large(Format::Stl, "triangles", u64::from(u32::MAX), 1)
    );
}

#[test]
fn stl_binary_truncated_at_several_points() {
    let real = read_data("real/fsaverage_head_scalp_mne.stl");
    // Inside the count field: too short to be binary STL.
    let e = error_kind(&real[..82], Format::Stl, "Truncated");
    says(&e, "byte 82");
    for keep in [0usize, 1, 100, 4061] {
        for extra in [0usize, 1, 49] {
            let cut = 84 + keep * 50 + extra;
            let e = error_of(&real[..cut], Format::Stl);
            assert_eq!(e, too_large(Format::Stl, "triangles", 4062, keep as u64));
        }
    }
}

#[test]
fn stl_ascii_truncated_at_several_points() {
    let text = "solid part\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n\
        vertex 0 1 0\nendloop\nendfacet\nendsolid part\n";
    let lines: Vec<&str> = text.lines().collect();
    for keep in 1..lines.len() {
        let cut = lines[..keep].join("\n") + "\n";
        let e = error_kind(cut.as_bytes(), Format::Stl, "Truncated");
        let between_facets = keep == 1 || keep == 8;
        says(
            &e,
            if between_facets {
                "endsolid"
            } else {
                "facet begun on line 2"
            },
        );
    }
    let cut = b"solid part\nfacet normal 0 0 1\nouter loop\nvertex 0 0";
    error_at(cut, Format::Stl, "Syntax", Line(4));
}

#[test]
fn stl_nan_and_infinity_are_refused_with_their_location() {
    let text = b"solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 NaN 0\n";
    error_at(text, Format::Stl, "NonFinite", Line(5));
    for (bits, shown) in [
        (0x7FC0_0000u32, "NaN"),
        (0xFF80_0000, "-inf"),
        (0x7F80_0001, "NaN"),
    ] {
        let mut tri = [TRI, TRI];
        tri[1][2][1] = f32::from_bits(bits);
        // Record 1 starts at 84 + 50; corner 2's y is 12 + 24 + 4 bytes in.
        let offset = 84 + 50 + 12 + 24 + 4;
        let e = error_at(&binary_stl(2, &tri), Format::Stl, "NonFinite", Byte(offset));
        says(&e, shown);
    }
}

#[test]
fn stl_without_triangles() {
    let none = LoadError::NoTriangles {
        format: Format::Stl,
    };
    assert_eq!(error_of(&binary_stl(0, &[]), Format::Stl), none);
    assert_eq!(
        error_of(b"solid empty\nendsolid empty\n", Format::Stl),
        none
    );
}

#[test]
fn stl_ascii_structure_errors_name_the_line() {
    let cases: &[(&str, usize)] = &[
        ("solid s\nvertex 0 0 0\n", 2),
        ("solid s\nendsolid\nfacet normal 0 0 1\n", 3),
        (
            "solid s\nfacet\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\n",
            7,
        ),
        (
            "solid s\nfacet\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nvertex 1 1 1\n",
            6,
        ),
        ("solid s\nfacet\nvertex 0 0 zero\n", 3),
        ("solid s\nfacet\nfacet\n", 3),
    ];
    for (text, line) in cases {
        error_at(text.as_bytes(), Format::Stl, "Syntax", Line(*line));
    }
}

// ---------------------------------------------------------------- OBJ

#[test]
fn obj_indices_zero_out_of_range_and_too_negative() {
    let base = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let cases: &[(&str, i64)] = &[
        ("f 1 2 0\n", 0),
        ("f 1 2 4\n", 4),
        ("f -4 1 2\n", -4),
        ("f 1/1 2/2 99999999999/3\n", 99_999_999_999),
    ];
    for (face, index) in cases {
        let text = format!("{base}{face}");
        let e = error_at(text.as_bytes(), Format::Obj, "IndexOutOfRange", Line(4));
        assert!(matches!(e, LoadError::IndexOutOfRange { index: i, count: 3, .. } if i == *index));
    }
    // A forward reference that the rest of the file never satisfies names its own line.
    let text = b"v 0 0 0\nf 1 2 3\nv 1 0 0\nf 1 2 5\nv 0 1 0\n";
    let e = error_at(text, Format::Obj, "IndexOutOfRange", Line(4));
    assert!(matches!(
        e,
        LoadError::IndexOutOfRange {
            index: 5,
            count: 3,
            ..
        }
    ));
}

#[test]
fn obj_nan_infinity_and_overflow_are_non_finite() {
    for bad in ["nan", "-inf", "Infinity", "1e39"] {
        let text = format!("v 0 0 0\nv 1 {bad} 0\nv 0 1 0\nf 1 2 3\n");
        let e = error_at(text.as_bytes(), Format::Obj, "NonFinite", Line(2));
        says(&e, bad);
    }
}

#[test]
fn obj_syntax_errors_and_no_triangles() {
    let cases: &[(&str, usize)] = &[
        ("v 0 0\n", 1),
        ("v 0 0 0\nv 1 zero 0\n", 2),
        ("v 0 0 0\nv 1 0 0\nf 1 2\n", 3),
        ("v 0 0 0\nf 1 a 1\n", 2),
        ("v 0 0 0\nf 1 //1 1\n", 2),
        ("v 0 0 0\n\x01\x02garbage\n", 2),
    ];
    for (text, line) in cases {
        error_at(text.as_bytes(), Format::Obj, "Syntax", Line(*line));
    }
    let text = b"# only vertices\nv 0 0 0\nv 1 1 1\nvn 0 0 1\n";
    assert_eq!(
        error_of(text, Format::Obj),
        LoadError::NoTriangles {
            format: Format::Obj
        }
    );
}

#[test]
fn obj_truncated_real_file_never_loads_wrong_data() {
    let real = read_data("real/fsaverage_head_scalp_mne.obj");
    let first_face = find(&real, b"\nf ").expect("the OBJ has faces") + 1;
    // Cut among the vertices (at line ends): nothing refers to them yet.
    let middle = real[..first_face / 2]
        .iter()
        .rposition(|&b| b == b'\n')
        .expect("lines")
        + 1;
    for cut in [10, middle, first_face - 1] {
        let e = error_of(&real[..cut], Format::Obj);
        assert_eq!(
            e,
            LoadError::NoTriangles {
                format: Format::Obj
            },
            "cut at {cut}"
        );
    }
    // Cut just after "f 1": an incomplete face record names its line.
    let line = real[..first_face].iter().filter(|&&b| b == b'\n').count() + 1;
    error_at(&real[..first_face + 3], Format::Obj, "Syntax", Line(line));
}

// ---------------------------------------------------------------- PLY

#[test]
fn ply_wrong_magic_and_missing_header_end() {
    for bad in [
        &b"plx\nformat ascii 1.0\n"[..],
        b"solid x\n",
        b"\x00\x01\x02",
    ] {
        error_kind(bad, Format::Ply, "BadMagic");
    }
    let e = error_kind(
        b"ply\nformat ascii 1.0\nelement vertex 3\n",
        Format::Ply,
        "Truncated",
    );
    says(&e, "end_header");
}

#[test]
fn ply_claiming_2_pow_40_vertices_fails_fast() {
    for format in ["binary_little_endian", "binary_big_endian", "ascii"] {
        let text = format!(
            "ply\nformat {format} 1.0\nelement vertex 1099511627776\nproperty float x\n\
             property float y\nproperty float z\nelement face 1\n\
             property list uchar int vertex_indices\nend_header\n0 0 0 0 0 0 0 0 0 0 0 0 0 0"
        );
        let e = error_kind(text.as_bytes(), Format::Ply, "CountTooLarge");
        assert!(
            matches!(
                e,
                LoadError::CountTooLarge {
                    claimed: 1_099_511_627_776,
                    what: "vertices",
                    ..
                }
            ),
            "{e}"
        );
    }
    // The same for faces and for a skipped element holding lists.
    let text = "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n\
        property float y\nproperty float z\nelement face 4000000000\n\
        property list uchar int vertex_indices\nend_header\n000000000000000";
    let e = error_of(text.as_bytes(), Format::Ply);
    assert_eq!(e, too_large(Format::Ply, "faces", 4_000_000_000, 3));
    let text = "ply\nformat ascii 1.0\nelement edges 99999999999\nproperty list int int i\n\
        end_header\n1 2\n";
    error_kind(text.as_bytes(), Format::Ply, "CountTooLarge");
}

#[test]
fn ply_binary_truncated_at_several_points() {
    let real = read_data("real/fsaverage_head_scalp_mne.ply");
    let body = find(&real, b"end_header\n").expect("header end") + 11;
    let faces_start = body + 2033 * 12;
    assert_eq!(real.len(), faces_start + 4062 * 13);
    // In the header.
    error_kind(&real[..body - 3], Format::Ply, "Truncated");
    // In the vertices: the vertex count cannot fit.
    for cut in [body, body + 1, body + 5000, faces_start - 1] {
        let possible = (cut - body) as u64 / 12;
        assert_eq!(
            error_of(&real[..cut], Format::Ply),
            too_large(Format::Ply, "vertices", 2033, possible)
        );
    }
    // Early in the faces: fewer bytes than one per face.
    let e = error_of(&real[..faces_start + 100], Format::Ply);
    assert_eq!(e, too_large(Format::Ply, "faces", 4062, 100));
    // Late in the faces: the reader runs out mid-list and says where.
    for cut in [faces_start + 30_000, real.len() - 1] {
        let e = error_kind(&real[..cut], Format::Ply, "Truncated");
        assert!(
            matches!(e, LoadError::Truncated { offset, .. } if offset == cut),
            "{e}"
        );
        says(&e, "runs past the end");
    }
}

#[test]
fn ply_ascii_truncated_and_bad_tokens() {
    let head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
        property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    let body = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    // Too few tokens for the vertices at all, then cuts inside the records.
    for (cut, kind) in [
        (0, "CountTooLarge"),
        (3, "CountTooLarge"),
        (12, "CountTooLarge"),
        (19, "Truncated"),
        (body.len() - 3, "Truncated"),
    ] {
        error_kind(
            format!("{head}{}", &body[..cut]).as_bytes(),
            Format::Ply,
            kind,
        );
    }
    let cases: &[(&str, usize)] = &[
        ("0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n", 11),
        ("0 0 0\n1 0 0\n0 1 0\n2 0 1\n", 13),
        ("0 0 0\n1 0 0\n0 1 0\n-3 0 1 2\n", 13),
        ("0 0 0\n1 0 0\n0 1 0\n3 0 1 2.5\n", 13),
    ];
    for (body, line) in cases {
        error_at(
            format!("{head}{body}").as_bytes(),
            Format::Ply,
            "Syntax",
            Line(*line),
        );
    }
    let text = format!("{head}0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 3 2\r\n");
    let e = error_at(text.as_bytes(), Format::Ply, "IndexOutOfRange", Line(13));
    assert!(matches!(
        e,
        LoadError::IndexOutOfRange {
            index: 3,
            count: 3,
            ..
        }
    ));
    let text = format!("{head}0 0 0\r1 nan 0\r0 1 0\r3 0 1 2\r");
    let e = error_at(text.as_bytes(), Format::Ply, "NonFinite", Line(11));
    says(&e, "nan");
}

/// A little-endian PLY of 3 float vertices and one uchar/int triangle, and its body offset.
fn small_binary_ply(points: [[f32; 3]; 3], face: [i32; 3]) -> (Vec<u8>, usize) {
    let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
        property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\n\
        end_header\n"
        .to_vec();
    let body = b.len();
    for c in points.iter().flatten() {
        b.extend_from_slice(&c.to_le_bytes());
    }
    b.push(3);
    for v in face {
        b.extend_from_slice(&v.to_le_bytes());
    }
    (b, body)
}

#[test]
fn ply_binary_bad_indices_and_non_finite_name_the_byte() {
    for (bad, at) in [(3, 2usize), (-1, 0), (i32::MAX, 1)] {
        let mut face = [0, 1, 2];
        face[at] = bad;
        let (b, body) = small_binary_ply(TRI, face);
        let offset = body + 36 + 1 + 4 * at;
        let e = error_at(&b, Format::Ply, "IndexOutOfRange", Byte(offset));
        assert!(
            matches!(e, LoadError::IndexOutOfRange { index, count: 3, .. } if index == i64::from(bad))
        );
    }
    for bits in [0x7FC0_0000u32, 0x7F80_0000, 0xFFFF_FFFF] {
        let mut points = TRI;
        points[1][2] = f32::from_bits(bits);
        let (b, body) = small_binary_ply(points, [0, 1, 2]);
        error_at(&b, Format::Ply, "NonFinite", Byte(body + 20));
    }
    // Doubles beyond f32 range cannot be represented: refused as non-finite.
    let mut b = b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\n\
        property double y\nproperty double z\nelement face 1\nproperty list uchar int vertex_indices\n\
        end_header\n"
        .to_vec();
    let body = b.len();
    for v in [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1e300, 0.0f64] {
        b.extend_from_slice(&v.to_be_bytes());
    }
    b.push(3);
    for v in [0i32, 1, 2] {
        b.extend_from_slice(&v.to_be_bytes());
    }
    let e = error_at(&b, Format::Ply, "NonFinite", Byte(body + 56));
    says(&e, "1e300");
}

#[test]
fn ply_without_triangles_or_with_broken_header() {
    let none = LoadError::NoTriangles {
        format: Format::Ply,
    };
    let (mut b, _) = small_binary_ply(TRI, [0, 1, 2]);
    let at = find(&b, b"element face 1").expect("face line");
    b[at + 13] = b'0';
    assert_eq!(error_of(&b, Format::Ply), none);
    let points_only = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n\
        property float y\nproperty float z\nend_header\n1 2 3\n";
    assert_eq!(error_of(points_only.as_bytes(), Format::Ply), none);
    let headers: &[(&str, usize)] = &[
        ("element vertex -3\n", 3),
        ("element vertex 1\nproperty quad x\n", 4),
        (
            "element face 1\nproperty list uchar int vertex_indices\nproperty int x y\n",
            5,
        ),
        ("element face 1\nproperty int vertex_indices\n", 3),
        (
            "element face 1\nproperty list float int vertex_indices\n",
            4,
        ),
        ("element vertex 1\nproperty float x\nproperty float y\n", 3),
    ];
    for (lines, line) in headers {
        let text = format!("ply\nformat ascii 1.0\n{lines}end_header\n");
        error_at(text.as_bytes(), Format::Ply, "Syntax", Line(*line));
    }
    let text = b"ply\nformat binary_middle_endian 1.0\nend_header\n";
    error_at(text, Format::Ply, "Syntax", Line(2));
    let text = b"ply\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    error_at(text, Format::Ply, "Syntax", Line(4));
    error_at(
        b"ply\nformat ascii 1.0\nend_header extra\n",
        Format::Ply,
        "Syntax",
        Line(3),
    );
}

// --- compressed glTF (EXT_meshopt_compression, KHR_mesh_quantization) ---
