//! The shared label maps in integration tests: their bytes, their structures, and the
//! phantom's analytic shapes.
#![allow(dead_code)]

use meshsmooth::case::{self, relations::RelationChanges, Case};
use meshsmooth::segmentation::{self, NamedBytes, OpenOptions, Structure};
use meshsmooth::session::Session;
use serde_json::Value;

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data/");

/// A file below ../shared/data.
pub fn read(path: &str) -> Vec<u8> {
    std::fs::read(format!("{DATA}{path}")).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// Opens `name` in the page's `session` (its workers run on this thread) and checks it opened.
pub fn open_in_session(session: &mut Session, name: &str, bytes: Vec<u8>) {
    session.begin_open(name, bytes);
    session.poll_opening().expect("done").expect("opens");
}

/// The label map's structures, named by its colour table when it has one.
pub fn open(path: &str, table: Option<&str>) -> Vec<Structure> {
    let bytes = read(path);
    let table_bytes = table.map(read);
    let table = table
        .zip(table_bytes.as_deref())
        .map(|(name, bytes)| NamedBytes { name, bytes });
    segmentation::open(
        &[NamedBytes {
            name: path,
            bytes: &bytes,
        }],
        table,
        &OpenOptions::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"))
}

/// The shared phantom opened as a case, named by its colour table.
pub fn phantom_case() -> Case {
    const TABLE: &str = "labelmaps/case_phantom_shared_labels.txt";
    let (bytes, table) = (read("labelmaps/case_phantom_shared.nii.gz"), read(TABLE));
    let files = [NamedBytes {
        name: "data/case_phantom_shared.nii.gz",
        bytes: &bytes,
    }];
    let table = NamedBytes {
        name: TABLE,
        bytes: &table,
    };
    case::open(&files, Some(table), &OpenOptions::default()).expect("the phantom opens")
}

/// No structure left one it lay inside, and no surfaces cross that did not.
pub fn assert_relations_kept(changes: &RelationChanges) {
    assert!(changes.left_inside.is_empty(), "{:?}", changes.left_inside);
    assert!(
        changes.new_crossings.is_empty(),
        "{:?}",
        changes.new_crossings
    );
}

/// Inside test of one phantom shape (ellipsoids, spheres, capsules) in its own frame (mm).
pub fn inside_shape(shape: &Value, p: [f64; 3]) -> bool {
    let v = |x: &Value| -> [f64; 3] { std::array::from_fn(|k| x[k].as_f64().expect("number")) };
    let list = |key: &str| shape[key].as_array().cloned().unwrap_or_default();
    let ellipsoid = list("ellipsoids").iter().any(|e| {
        let (c, r) = (v(&e[0]), v(&e[1]));
        (0..3).map(|k| ((p[k] - c[k]) / r[k]).powi(2)).sum::<f64>() <= 1.0
    });
    let sphere = list("spheres").iter().any(|s| {
        let (c, r) = (v(&s[0]), s[1].as_f64().expect("radius"));
        (0..3).map(|k| (p[k] - c[k]).powi(2)).sum::<f64>() <= r * r
    });
    let capsule = list("capsules").iter().any(|s| {
        let (a, b, r) = (v(&s[0]), v(&s[1]), s[2].as_f64().expect("radius"));
        let ab: [f64; 3] = std::array::from_fn(|k| b[k] - a[k]);
        let ap: [f64; 3] = std::array::from_fn(|k| p[k] - a[k]);
        let t =
            (0..3).map(|k| ab[k] * ap[k]).sum::<f64>() / (0..3).map(|k| ab[k] * ab[k]).sum::<f64>();
        let t = t.clamp(0.0, 1.0);
        (0..3).map(|k| (ap[k] - t * ab[k]).powi(2)).sum::<f64>() <= r * r
    });
    ellipsoid || sphere || capsule
}
